//! Issue 34, finding 6: input that asks for more memory than the budget
//! has ends in one located error (`file:line:col: this film needs 20.0
//! GiB; the memory limit is 1.0 GiB`), never in an allocation that aborts
//! the process. Each test is one of the finding's cases, against a small
//! budget so that nothing large is allocated.

use std::io::Write;
use std::path::PathBuf;

use rpbrt_parser::{Diagnostic, Diagnostics, MemoryBudget, ParseOptions};

use super::super::assemble::{create_scene, CreateOptions};
use super::super::{build_scene_from_str, BuildOptions};

const MIB: u64 = 1 << 20;

fn options(limit: u64) -> BuildOptions {
    BuildOptions {
        parse: ParseOptions {
            budget: MemoryBudget::labelled(limit, "--max-memory"),
            ..ParseOptions::default()
        },
        ..BuildOptions::default()
    }
}

/// A film small enough for any budget here (the default one's sums take
/// 70 MiB), on line 1.
const FILM: &str = "Film \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 16\n";

/// The errors of building and then creating `text` with a budget of
/// `limit` bytes (none when both succeed).
fn errors(text: &str, limit: u64) -> Vec<Diagnostic> {
    match build_scene_from_str(text, &options(limit)) {
        Err(Diagnostics { items, .. }) => items,
        Ok((desc, _)) => match create_scene(&desc, &CreateOptions::default()) {
            Ok(_) => Vec::new(),
            Err(e) => e,
        },
    }
}

/// The one error, its line and its message.
fn one_error(text: &str, limit: u64) -> (u32, String) {
    let e = errors(text, limit);
    assert_eq!(e.len(), 1, "{e:#?}");
    let line = e[0].loc.as_ref().map_or(0, |l| l.line);
    (line, e[0].message.clone())
}

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rpbrt-budget-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn oom_film_16384_squared_is_a_located_error() {
    let (line, msg) = one_error(
        "Film \"rgb\" \"integer xresolution\" 16384 \"integer yresolution\" 16384\n\
         WorldBegin\nShape \"sphere\"\n",
        1 << 30,
    );
    assert_eq!(line, 1);
    assert_eq!(msg, "this film needs 20.0 GiB; --max-memory is 1.0 GiB");
    // The same film fits a budget that has room for it (nothing is
    // allocated here: the check is against the claim).
    let e = errors(
        "Film \"rgb\" \"integer xresolution\" 64 \"integer yresolution\" 64\nWorldBegin\n",
        MIB,
    );
    assert!(e.is_empty(), "{e:#?}");
}

#[test]
fn oom_many_sphere_directives_end_at_the_first_that_does_not_fit() {
    let mut text = format!("{FILM}WorldBegin\n");
    text.push_str(&"Shape \"sphere\"\n".repeat(20_000));
    let (line, msg) = one_error(&text, 4 * MIB);
    // Each sphere is charged about a kilobyte, so a 4 MiB budget runs out
    // after some thousands of them; the parse stops at the first.
    assert!((1000..15_000).contains(&line), "{line}: {msg}");
    assert!(
        msg.starts_with("this Shape needs ") && msg.ends_with("; --max-memory is 4.0 MiB"),
        "{msg}"
    );
}

#[test]
fn oom_unbalanced_attribute_blocks_are_charged_and_balanced_ones_released() {
    let open = format!("{FILM}WorldBegin\n{}", "AttributeBegin\n".repeat(50_000));
    let (_, msg) = one_error(&open, MIB);
    assert!(msg.starts_with("this AttributeBegin needs "), "{msg}");
    let balanced = format!(
        "{FILM}WorldBegin\n{}",
        "AttributeBegin\nAttributeEnd\n".repeat(50_000)
    );
    let e = errors(&balanced, MIB);
    assert!(e.is_empty(), "{e:#?}");
}

#[test]
fn oom_ply_gz_inflating_past_the_budget_is_a_located_error() {
    // A valid mesh of 2^20 vertices (12 MiB of zeros) in 12 KiB of gzip.
    let n = 1u32 << 20;
    let path = temp("inflating.ply.gz");
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    write!(
        gz,
        "ply\nformat binary_little_endian 1.0\nelement vertex {n}\n\
         property float x\nproperty float y\nproperty float z\n\
         element face 1\nproperty list uchar int vertex_indices\nend_header\n"
    )
    .unwrap();
    gz.write_all(&vec![0u8; 12 * n as usize]).unwrap();
    gz.write_all(&[3, 0, 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0])
        .unwrap();
    std::fs::write(&path, gz.finish().unwrap()).unwrap();
    let scene = format!(
        "{FILM}WorldBegin\nShape \"plymesh\" \"string filename\" \"{}\"\n",
        path.display()
    );
    let (line, msg) = one_error(&scene, 4 * MIB);
    assert_eq!(line, 3);
    assert!(
        msg.contains("this mesh (1048576 vertices, 1 faces) needs 12.0 MiB")
            && msg.ends_with("--max-memory is 4.0 MiB"),
        "{msg}"
    );
    // With room for it, the mesh is read.
    assert!(errors(&scene, 64 * MIB).is_empty());
    let _ = std::fs::remove_file(&path);
}

#[test]
fn oom_png_imagemap_is_refused_after_its_header() {
    // A valid 3000 x 3000 RGB PNG of zeros, some kilobytes of zlib.
    let path = temp("big.png");
    let n = 3000u32;
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
    let row = vec![0u8; 3 * n as usize + 1];
    for _ in 0..n {
        z.write_all(&row).unwrap();
    }
    let idat = z.finish().unwrap();
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut chunk = |ty: &[u8; 4], data: &[u8]| {
        let mut crc = flate2::Crc::new();
        crc.update(ty);
        crc.update(data);
        png.extend((data.len() as u32).to_be_bytes());
        png.extend(ty);
        png.extend(data);
        png.extend(crc.sum().to_be_bytes());
    };
    let mut ihdr = n.to_be_bytes().to_vec();
    ihdr.extend(n.to_be_bytes());
    ihdr.extend([8, 2, 0, 0, 0]);
    chunk(b"IHDR", &ihdr);
    chunk(b"IDAT", &idat);
    chunk(b"IEND", &[]);
    std::fs::write(&path, png).unwrap();
    let scene = format!(
        "{FILM}WorldBegin\nTexture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"{}\"\n\
         Material \"diffuse\" \"texture reflectance\" \"t\"\nShape \"sphere\"\n",
        path.display()
    );
    // The image (26 MiB with the decoder's rows) does not fit 16 MiB.
    let (line, msg) = one_error(&scene, 16 * MIB);
    assert_eq!(line, 3);
    assert!(msg.contains("this image needs 51.5 MiB"), "{msg}");
    // It fits 64 MiB, but its MIP map (4096² texels, in floats while the
    // levels are made) does not.
    let (line, msg) = one_error(&scene, 64 * MIB);
    assert_eq!(line, 3);
    assert!(msg.contains("this texture's MIP map needs"), "{msg}");
    let _ = std::fs::remove_file(&path);
}

#[test]
fn oom_loopsubdiv_is_checked_before_it_refines() {
    let scene = &format!("{FILM}WorldBegin\nShape \"loopsubdiv\" \"integer levels\" 9 \
                 \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 1] \"integer indices\" [0 1 2 2 1 3 0 2 3 0 3 1]\n");
    let (line, msg) = one_error(scene, 64 * MIB);
    assert_eq!(line, 3);
    assert!(
        msg.starts_with("this subdivision (1048576 triangles after 9 levels) needs 96.0 MiB"),
        "{msg}"
    );
}

#[test]
fn oom_loopsubdiv_level_clamp_is_a_warning() {
    let text = "Film \"rgb\" \"integer xresolution\" 4 \"integer yresolution\" 4\nWorldBegin\n\
                Shape \"loopsubdiv\" \"integer levels\" 40 \
                \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2]\n";
    // Refused before it refines, with the clamp said.
    let (desc, _) = build_scene_from_str(text, &options(MIB)).unwrap();
    let Err(e) = create_scene(&desc, &CreateOptions::default()) else {
        panic!("a million triangles fit a megabyte");
    };
    assert!(e[0].message.contains("after 10 levels"), "{e:#?}");
    let (desc, _) = build_scene_from_str(text, &options(1 << 30)).unwrap();
    let Ok(created) = create_scene(&desc, &CreateOptions::default()) else {
        panic!("the subdivision fits a gigabyte");
    };
    let w: Vec<&str> = created
        .warnings
        .iter()
        .map(|d| d.message.as_str())
        .collect();
    assert!(
        w.iter()
            .any(|m| m.contains("\"levels\" 40 is more than the 10 rpbrt applies")),
        "{w:?}"
    );
}

#[test]
fn oom_integrator_buffers_are_charged_with_the_film() {
    let (line, msg) = one_error(
        "Film \"rgb\" \"integer xresolution\" 1000 \"integer yresolution\" 1000\n\
         Integrator \"mlt\" \"integer bootstrapsamples\" 2000000000\nWorldBegin\n",
        1 << 30,
    );
    assert_eq!(line, 2);
    assert!(msg.starts_with("the \"mlt\" integrator needs"), "{msg}");
}

#[test]
fn oom_scene_text_is_read_no_further_than_the_budget() {
    let path = temp("long.pbrt");
    std::fs::write(
        &path,
        format!("WorldBegin\n{}", "# padding\n".repeat(300_000)),
    )
    .unwrap();
    let parsed = rpbrt_parser::Parser::new(ParseOptions {
        budget: MemoryBudget::labelled(MIB, "--max-memory"),
        ..ParseOptions::default()
    })
    .parse_files(&[&path], &mut rpbrt_parser::FormattingTarget::new(false));
    let e = parsed.unwrap_err();
    let msg = &e.items[0].message;
    assert!(
        msg.contains("long.pbrt: this scene file needs more than 1.0 MiB"),
        "{msg}"
    );
    let _ = std::fs::remove_file(&path);
}
