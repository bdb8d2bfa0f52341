//! Command-line options, spelled as pbrt-v4 spells them. Flag names ignore
//! case, '-' and '_' (`--outfile`, `--out-file` and `--OUTFILE` are one
//! flag), and a value may follow as the next argument or after '='.

use std::fmt;

/// What the user asked for.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Options {
    /// Scene files, in order.
    pub files: Vec<String>,
    /// `--outfile`: overrides the film's filename.
    pub outfile: Option<String>,
    /// `--spp`: overrides the sampler's pixel sample count.
    pub spp: Option<i32>,
    /// `--seed`.
    pub seed: Option<i32>,
    /// `--nthreads` (0: all cores).
    pub nthreads: Option<usize>,
    /// `--cropwindow x0 x1 y0 y1` (NDC).
    pub crop_window: Option<[f32; 4]>,
    /// `--pixelbounds x0 x1 y0 y1`.
    pub pixel_bounds: Option<[i32; 4]>,
    /// `--tile K/N`: render tile K of N (0-based).
    pub tile: Option<(u32, u32)>,
    /// `--spp-range A..B`: render samples A..B-1 of every pixel.
    pub spp_range: Option<(i32, i32)>,
    /// `--serve-parts`: build the scene once, render parts asked on stdin.
    pub serve_parts: bool,
    /// `--quick`: a fast, reduced-quality render.
    pub quick: bool,
    /// `--quiet`: no progress bar or statistics.
    pub quiet: bool,
    /// `--stats`: print statistics after rendering.
    pub stats: bool,
    /// `--write-partial-images`.
    pub write_partial_images: bool,
    /// `--wavefront` (`Some(true)`) or `--no-wavefront` (`Some(false)`):
    /// the design, where the command line chooses it.
    pub wavefront: Option<bool>,
    /// `--disable-pixel-jitter`.
    pub disable_pixel_jitter: bool,
    /// `--denoise`: an `rgb` film also records albedo and normal, and the
    /// image is denoised with Open Image Denoise after the render.
    pub denoise: bool,
    /// `--gbuffer`: an `rgb` film renders as a `gbuffer` film (what
    /// `--denoise` does before denoising; for parts denoised once joined).
    pub gbuffer: bool,
    /// `--disable-wavelength-jitter`.
    pub disable_wavelength_jitter: bool,
    /// `--disable-texture-filtering`.
    pub disable_texture_filtering: bool,
    /// `--force-diffuse`.
    pub force_diffuse: bool,
    /// `--texture-cache-mb <n>`: image textures tiled on disk, read
    /// through a cache of this many megabytes (10^6 bytes).
    pub texture_cache_mb: Option<f64>,
    /// `--texture-cache-dir <dir>`: where the tiled pyramids go.
    pub texture_cache_dir: Option<String>,
    /// `--render-coord-sys camera|cameraworld|world`.
    pub render_coord_sys: Option<String>,
    /// `--mse-reference-image`.
    pub mse_reference_image: Option<String>,
    /// `--mse-reference-out`.
    pub mse_reference_out: Option<String>,
    /// `--preview [ADDR]`: serve a live view of the render over HTTP
    /// (`127.0.0.1:0`, a free loopback port, when no address is given).
    pub preview: Option<std::net::SocketAddr>,
    /// `--interactive`: move the camera from the preview page; implies
    /// `--preview` (on a free loopback port unless given an address).
    pub interactive: bool,
    /// `--display-server host:port`: stream the image to tev.
    pub display_server: Option<String>,
    /// `--max-memory <size>`: the memory budget, in bytes (default: from
    /// the machine's memory).
    pub max_memory: Option<u64>,
    /// `--format`: print the scene back as canonical pbrt-v4 text.
    pub format: bool,
    /// `--upgrade`: print a pbrt-v3 scene as pbrt-v4 text.
    pub upgrade: bool,
    /// `--toply`: with --format/--upgrade, write large meshes to PLY files.
    pub toply: bool,
    /// `--help`.
    pub help: bool,
    /// `--version`.
    pub version: bool,
}

/// A command-line mistake.
#[derive(Clone, Debug, PartialEq)]
pub struct ArgError(pub String);

impl fmt::Display for ArgError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

/// The usage text printed by `--help`.
pub const USAGE: &str = "\
usage: rpbrt [<options>] <filename.pbrt...>

Renders pbrt-v4 (and pbrt-v3) scene files. Flag names ignore case, '-' and '_'.

Rendering options:
  --cropwindow <x0,x1,y0,y1>   Render only this part of the image (NDC, [0,1]).
  --denoise                    Denoise the image with Intel Open Image Denoise (CPU)
                               after the render, from its colour, albedo and normal
                               (an rgb film renders as a gbuffer film to record them).
                               The denoised R, G, B go to the output name; the raw
                               render, with its albedo and normal, beside it as
                               <name>-noisy.exr. Needs `pip install pyoidn`.
  --gbuffer                    Render an rgb film as a gbuffer film with the same
                               parameters (the same R, G, B, plus albedo, normals and
                               more): for tiles that are denoised once joined
                               (rpbrt-farm --denoise).
  --disable-pixel-jitter       Always sample pixels at their centres.
  --disable-texture-filtering  Point-sample all textures.
  --disable-wavelength-jitter  Always sample the same four wavelengths of light.
  --display-server <host:port> Stream the image as it renders to the tev viewer.
  --force-diffuse              Replace every material with a diffuse one.
  --interactive                Move the camera from the browser (implies --preview):
                               W/S A/D Q/E move, arrows turn, drag orbits, the wheel
                               dollies; the render restarts on each change and the
                               page shows the camera as LookAt/Camera text.
  --max-memory <size>          The most memory the input may claim (e.g. 6G): scene
                               text, meshes, images and textures, the film and the
                               integrator's buffers. Past it, an error names the
                               directive. Default: 3/4 of the machine's memory.
  --mse-reference-image <file> Compute the MSE against this image while rendering.
  --mse-reference-out <file>   Write the MSE per sample count to this file.
  --no-wavefront               Render path and volpath scenes with the scalar loop (one
                               path per thread at a time; same image).
  --nthreads <n>               Use n threads (default: all cores).
  --outfile <file>             Write the image here (overrides the Film's filename).
  --preview [<addr>]           Watch the render in a browser: serves a live view on
                               127.0.0.1 (a free port, the URL printed) or on <addr>
                               (e.g. 0.0.0.0:8000; reachable from the network then).
  --pixelbounds <x0,x1,y0,y1>  Render only these pixels.
  --quick                      Reduced quality for a fast preview.
  --quiet                      No progress bar or informational messages.
  --render-coord-sys <name>    Rendering space: camera, cameraworld (default), world.
  --texture-cache-mb <n>       Keep image textures on disk, converted once into tiled
                               MIP maps, and read their tiles through a cache of n MB
                               (the same image as without; for texture sets larger
                               than memory). Default: textures held in memory.
  --texture-cache-dir <dir>    Where the tiled MIP maps go (default:
                               $XDG_CACHE_HOME/rpbrt/textures or ~/.cache/...).
  --seed <n>                   Seed for the random number generators.
  --spp <n>                    Samples per pixel (overrides the Sampler).
  --spp-range <a..b>           Render samples a..b-1 of every pixel, as a full render
                               takes them; the EXR carries the sums that
                               `imgtool merge` adds into the full render's image.
  --serve-parts                Build the scene once, then render the parts that stdin
                               asks for ('--tile k/n --spp-range a..b --outfile f' a
                               line), answering 'ok' or 'error: ...' on stdout.
  --stats                      Print statistics after rendering.
  --tile <k/n>                 Render tile k (0-based) of n tiles of the image;
                               `imgtool assemble` joins them.
  --wavefront                  Render path and volpath scenes with the wavefront path
                               tracer (many paths per thread at once; same image).
                               The default for path, and for volpath without media.
  --write-partial-images       Write the image periodically while rendering.

Scene file tools:
  --format                     Print the scene back as canonical pbrt-v4 text.
  --toply                      With --format/--upgrade: write large meshes to PLY files.
  --upgrade                    Print a pbrt-v3 scene as pbrt-v4 text.

  --help                       Print this help.
  --version                    Print the version.

  rpbrt imgtool <command> ...  Image utilities (see: rpbrt imgtool help).
";

/// Lower-case and drop '-' and '_' so flag spellings compare equal.
fn normalize(flag: &str) -> String {
    flag.chars()
        .filter(|c| *c != '-' && *c != '_')
        .flat_map(char::to_lowercase)
        .collect()
}

fn parse_num<T: std::str::FromStr>(flag: &str, v: &str) -> Result<T, ArgError> {
    v.trim()
        .parse::<T>()
        .map_err(|_| ArgError(format!("--{flag}: \"{v}\" is not a valid number")))
}

fn parse_four<T: std::str::FromStr + Copy + Default>(
    flag: &str,
    vals: &[String],
) -> Result<[T; 4], ArgError> {
    let joined = vals.join(",");
    let parts: Vec<&str> = joined
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|s| !s.is_empty())
        .collect();
    if parts.len() != 4 {
        return Err(ArgError(format!(
            "--{flag} expects four values, got {}",
            parts.len()
        )));
    }
    let mut out = [T::default(); 4];
    for (o, p) in out.iter_mut().zip(parts) {
        *o = parse_num(flag, p)?;
    }
    Ok(out)
}

/// Whether an argument after `--preview` is its address rather than a
/// scene file: a port number, or anything ending in `:<port>`.
fn looks_like_address(arg: &str) -> bool {
    let port = arg.rsplit_once(':').map_or(arg, |(_, p)| p);
    !arg.starts_with('-') && !port.is_empty() && port.bytes().all(|b| b.is_ascii_digit())
}

/// `--preview`'s address: `ip:port`, `[ipv6]:port`, `localhost:port` or a
/// bare port (on 127.0.0.1).
pub fn parse_preview_address(v: &str) -> Result<std::net::SocketAddr, ArgError> {
    use std::net::{IpAddr, Ipv4Addr, SocketAddr};
    let bad = |why: &str| ArgError(format!("--preview: \"{v}\" {why}"));
    if let Ok(port) = v.parse::<u16>() {
        return Ok(SocketAddr::from((Ipv4Addr::LOCALHOST, port)));
    }
    if let Ok(a) = v.parse::<SocketAddr>() {
        return Ok(a);
    }
    match v.rsplit_once(':') {
        Some((host, port)) => {
            let port: u16 = port
                .parse()
                .map_err(|_| bad("has no valid port (0 to 65535)"))?;
            let ip = match host {
                "localhost" => IpAddr::V4(Ipv4Addr::LOCALHOST),
                _ => host.parse::<IpAddr>().map_err(|_| {
                    bad("is not an address: expected ip:port (e.g. 127.0.0.1:8000) or a port")
                })?,
            };
            Ok(SocketAddr::new(ip, port))
        }
        None => Err(bad(
            "is not an address: expected ip:port (e.g. 127.0.0.1:8000) or a port",
        )),
    }
}

/// `--display-server`'s `host:port` (the host is looked up when
/// connecting, as pbrt-v4 does).
fn parse_display_server(v: &str) -> Result<(), ArgError> {
    match v.rsplit_once(':') {
        Some((host, port)) if !host.is_empty() && port.parse::<u16>().is_ok_and(|p| p > 0) => {
            Ok(())
        }
        _ => Err(ArgError(format!(
            "--display-server: expected \"host:port\" (e.g. localhost:14158), got \"{v}\""
        ))),
    }
}

/// Parses the arguments after the program name.
pub fn parse_args(args: &[String]) -> Result<Options, ArgError> {
    let mut o = Options::default();
    let mut i = 0;
    while i < args.len() {
        let arg = &args[i];
        i += 1;
        if !arg.starts_with('-') || arg == "-" {
            o.files.push(arg.clone());
            continue;
        }
        let body = arg.trim_start_matches('-');
        let (name, inline) = match body.split_once('=') {
            Some((n, v)) => (n, Some(v.to_string())),
            None => (body, None),
        };
        let key = normalize(name);
        // Fetches the flag's value: inline after '=' or the next argument.
        let value = |i: &mut usize| -> Result<String, ArgError> {
            if let Some(v) = &inline {
                return Ok(v.clone());
            }
            match args.get(*i) {
                Some(v) => {
                    *i += 1;
                    Ok(v.clone())
                }
                None => Err(ArgError(format!("--{name} needs a value"))),
            }
        };
        match key.as_str() {
            "outfile" => o.outfile = Some(value(&mut i)?),
            "spp" => {
                let n: i32 = parse_num(name, &value(&mut i)?)?;
                if n <= 0 {
                    return Err(ArgError(format!("--spp must be positive, got {n}")));
                }
                o.spp = Some(n);
            }
            "seed" => o.seed = Some(parse_num(name, &value(&mut i)?)?),
            "nthreads" => {
                let n: i64 = parse_num(name, &value(&mut i)?)?;
                if n < 0 {
                    return Err(ArgError(format!(
                        "--nthreads must not be negative, got {n}"
                    )));
                }
                o.nthreads = Some(n as usize);
            }
            "cropwindow" | "pixelbounds" => {
                // Four values: "a,b,c,d" in one argument, or four arguments.
                let first = value(&mut i)?;
                let mut vals = vec![first];
                let count = |v: &Vec<String>| {
                    v.join(",")
                        .split(|c: char| c == ',' || c.is_whitespace())
                        .filter(|s| !s.is_empty())
                        .count()
                };
                while count(&vals) < 4 && i < args.len() && !args[i].starts_with("--") {
                    vals.push(args[i].clone());
                    i += 1;
                }
                if key == "cropwindow" {
                    let c: [f32; 4] = parse_four(name, &vals)?;
                    if c.iter().any(|v| !(0.0..=1.0).contains(v)) || c[0] >= c[1] || c[2] >= c[3] {
                        return Err(ArgError(format!(
                            "--cropwindow {c:?}: values must be in [0,1] with x0 < x1 and y0 < y1"
                        )));
                    }
                    o.crop_window = Some(c);
                } else {
                    let b: [i32; 4] = parse_four(name, &vals)?;
                    if b[0] >= b[1] || b[2] >= b[3] || b.iter().any(|v| *v < 0) {
                        return Err(ArgError(format!(
                            "--pixelbounds {b:?}: need 0 <= x0 < x1 and 0 <= y0 < y1"
                        )));
                    }
                    o.pixel_bounds = Some(b);
                }
            }
            "tile" => {
                let v = value(&mut i)?;
                let parsed = v.split_once('/').and_then(|(k, n)| {
                    Some((k.trim().parse::<u32>().ok()?, n.trim().parse::<u32>().ok()?))
                });
                match parsed {
                    Some((k, n)) if k < n => o.tile = Some((k, n)),
                    _ => {
                        return Err(ArgError(format!(
                            "--tile \"{v}\": expected K/N with 0 <= K < N (e.g. 3/16)"
                        )))
                    }
                }
            }
            "spprange" => {
                let v = value(&mut i)?;
                let parsed = v.split_once("..").and_then(|(a, b)| {
                    Some((a.trim().parse::<i32>().ok()?, b.trim().parse::<i32>().ok()?))
                });
                match parsed {
                    Some((a, b)) if 0 <= a && a < b => o.spp_range = Some((a, b)),
                    _ => {
                        return Err(ArgError(format!(
                            "--spp-range \"{v}\": expected A..B with 0 <= A < B (samples A to B-1)"
                        )))
                    }
                }
            }
            "serveparts" => o.serve_parts = true,
            "quick" => o.quick = true,
            "quiet" => o.quiet = true,
            "interactive" => o.interactive = true,
            "stats" => o.stats = true,
            "writepartialimages" => o.write_partial_images = true,
            "wavefront" => o.wavefront = Some(true),
            "nowavefront" => o.wavefront = Some(false),
            "disablepixeljitter" => o.disable_pixel_jitter = true,
            "denoise" => o.denoise = true,
            "gbuffer" => o.gbuffer = true,
            "disablewavelengthjitter" => o.disable_wavelength_jitter = true,
            "disabletexturefiltering" => o.disable_texture_filtering = true,
            "forcediffuse" => o.force_diffuse = true,
            "texturecachemb" => {
                let v = value(&mut i)?;
                match v.trim().parse::<f64>() {
                    Ok(mb) if (0.0..=1e9).contains(&mb) => o.texture_cache_mb = Some(mb),
                    _ => {
                        return Err(ArgError(format!(
                            "--texture-cache-mb \"{v}\": expected a size in megabytes (e.g. 256)"
                        )))
                    }
                }
            }
            "texturecachedir" => o.texture_cache_dir = Some(value(&mut i)?),
            "rendercoordsys" => {
                let v = value(&mut i)?;
                if !["camera", "cameraworld", "world"].contains(&v.as_str()) {
                    return Err(ArgError(format!(
                        "--render-coord-sys: \"{v}\" is not one of camera, cameraworld, world"
                    )));
                }
                o.render_coord_sys = Some(v);
            }
            "maxmemory" => {
                let v = value(&mut i)?;
                o.max_memory = Some(crate::imgtool::parse_max_memory(&v).map_err(ArgError)?);
            }
            "msereferenceimage" => o.mse_reference_image = Some(value(&mut i)?),
            "msereferenceout" => o.mse_reference_out = Some(value(&mut i)?),
            "preview" => {
                // The address is optional: taken from "=ADDR" or from the
                // next argument when that reads as an address or a port.
                let given = match &inline {
                    Some(v) => Some(v.clone()),
                    None => match args.get(i) {
                        Some(next) if looks_like_address(next) => {
                            i += 1;
                            Some(next.clone())
                        }
                        _ => None,
                    },
                };
                o.preview = Some(match given {
                    Some(v) => parse_preview_address(&v)?,
                    None => std::net::SocketAddr::from(([127, 0, 0, 1], 0)),
                });
            }
            "displayserver" => {
                let v = value(&mut i)?;
                parse_display_server(&v)?;
                o.display_server = Some(v);
            }
            "format" => o.format = true,
            "upgrade" => o.upgrade = true,
            "toply" => o.toply = true,
            "help" | "h" => o.help = true,
            "version" => o.version = true,
            _ => return Err(ArgError(format!("unknown option \"{arg}\" (see --help)"))),
        }
    }
    Ok(o)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(args: &[&str]) -> Result<Options, ArgError> {
        parse_args(&args.iter().map(|s| s.to_string()).collect::<Vec<_>>())
    }

    #[test]
    fn spellings_are_equivalent() {
        for flag in [
            "--outfile",
            "--out-file",
            "--OUTFILE",
            "--out_file",
            "-outfile",
        ] {
            let o = p(&[flag, "x.exr", "scene.pbrt"]).unwrap();
            assert_eq!(o.outfile.as_deref(), Some("x.exr"));
            assert_eq!(o.files, vec!["scene.pbrt"]);
        }
        let o = p(&["--max-memory", "6G", "--MAX_MEMORY=512m"]).unwrap();
        assert_eq!(o.max_memory, Some(512 << 20));
        let o = p(&["--spp=16", "--Disable_Pixel-Jitter", "a.pbrt"]).unwrap();
        assert_eq!(o.spp, Some(16));
        assert!(o.disable_pixel_jitter);
    }

    #[test]
    fn four_value_flags() {
        assert_eq!(
            p(&["--cropwindow", "0,0.5,0.25,1"]).unwrap().crop_window,
            Some([0.0, 0.5, 0.25, 1.0])
        );
        assert_eq!(
            p(&["--cropwindow", "0", "0.5", "0.25", "1", "s.pbrt"])
                .unwrap()
                .crop_window,
            Some([0.0, 0.5, 0.25, 1.0])
        );
        assert_eq!(
            p(&["--pixelbounds", "0,16,8,24"]).unwrap().pixel_bounds,
            Some([0, 16, 8, 24])
        );
        assert!(p(&["--cropwindow", "0,2,0,1"]).is_err());
        assert_eq!(p(&["--tile", "3/16"]).unwrap().tile, Some((3, 16)));
        assert_eq!(p(&["--spp-range=8..16"]).unwrap().spp_range, Some((8, 16)));
        assert!(p(&["--pixelbounds", "5,1,0,1"]).is_err());
    }

    #[test]
    fn preview_address_is_optional() {
        let local = |port| std::net::SocketAddr::from(([127, 0, 0, 1], port));
        let o = p(&["--preview", "scene.pbrt"]).unwrap();
        assert_eq!(o.preview, Some(local(0)));
        assert_eq!(o.files, ["scene.pbrt"]);
        let o = p(&["--preview", "0.0.0.0:8000", "scene.pbrt"]).unwrap();
        assert_eq!(
            o.preview,
            Some(std::net::SocketAddr::from(([0, 0, 0, 0], 8000)))
        );
        assert_eq!(o.files, ["scene.pbrt"]);
        assert_eq!(p(&["--preview=8001"]).unwrap().preview, Some(local(8001)));
        assert_eq!(
            p(&["--preview", "localhost:9"]).unwrap().preview,
            Some(local(9))
        );
        let o = p(&["--preview", "[::1]:8000"]).unwrap();
        assert_eq!(o.preview, Some("[::1]:8000".parse().unwrap()));
        // A flag after it is not its address.
        let o = p(&["--preview", "--quiet", "s.pbrt"]).unwrap();
        assert!(o.preview.is_some() && o.quiet);
        for bad in [
            "--preview=nowhere",
            "--preview=1.2.3:80",
            "--preview=127.0.0.1:99999",
        ] {
            let e = p(&[bad]).unwrap_err();
            assert!(e.0.starts_with("--preview: "), "{e}");
        }
    }

    #[test]
    fn display_server_needs_host_and_port() {
        let o = p(&["--display-server", "localhost:14158", "s.pbrt"]).unwrap();
        assert_eq!(o.display_server.as_deref(), Some("localhost:14158"));
        for bad in ["localhost", ":14158", "host:port", "host:0"] {
            assert!(p(&["--display-server", bad]).is_err(), "{bad}");
        }
        assert!(p(&["--display-server"]).is_err());
    }

    #[test]
    fn bad_values_are_errors() {
        assert!(p(&["--spp", "-4"]).is_err());
        assert!(p(&["--spp", "lots"]).is_err());
        assert!(p(&["--nthreads", "-1"]).is_err());
        assert!(p(&["--spp"]).is_err());
        assert!(p(&["--render-coord-sys", "object"]).is_err());
        assert!(p(&["--no-such-flag"]).is_err());
        for bad in ["3", "4/4", "a/b", "-1/4", "2/0"] {
            assert!(p(&["--tile", bad]).is_err(), "{bad}");
        }
        for bad in ["4", "4..4", "5..2", "-1..3", "a..b"] {
            assert!(p(&["--spp-range", bad]).is_err(), "{bad}");
        }
        for bad in ["0", "lots", "-1G", "6X"] {
            assert!(p(&["--max-memory", bad]).is_err(), "{bad}");
        }
        for bad in ["-1", "lots", "NaN", "inf", "1e10"] {
            assert!(p(&["--texture-cache-mb", bad]).is_err(), "{bad}");
        }
    }

    #[test]
    fn texture_cache_flags() {
        let o = p(&[
            "--texture-cache-mb",
            "256",
            "--texture-cache-dir",
            "/tmp/t",
            "a.pbrt",
        ])
        .unwrap();
        assert_eq!(o.texture_cache_mb, Some(256.0));
        assert_eq!(o.texture_cache_dir.as_deref(), Some("/tmp/t"));
        assert_eq!(
            p(&["--texture-cache-mb=0.5", "a.pbrt"])
                .unwrap()
                .texture_cache_mb,
            Some(0.5)
        );
        assert_eq!(p(&["a.pbrt"]).unwrap().texture_cache_mb, None);
    }
}
