//! pbrt-v1 and pbrt-v2 → pbrt-v4: the light-transport directives those
//! editions had and pbrt-v3 replaced by `Integrator` (pbrt-v2
//! `core/api.cpp`'s `MakeRenderer`; pbrt-v1 had no `Renderer`).
//!
//! A pbrt-v2 image was made by a *renderer* (`sampler`, the default, which
//! asks a *surface integrator* and a *volume integrator* for each camera
//! ray's radiance, or `metropolis`, which needs neither); pbrt-v4 has one
//! integrator doing all of it. [`LegacyTransport`] collects the three
//! directives as given and makes the one `Integrator` that renders what
//! they rendered: the same integrator where one exists, the one that
//! converges to the same light transport otherwise (with a warning naming
//! the substitution).

use super::{Edit, Upgraded};
use crate::loc::FileLoc;
use crate::params::ParsedParameter;

/// One directive as the file gave it.
#[derive(Clone, Debug, PartialEq)]
pub struct Given {
    /// Its type name.
    pub name: String,
    /// Its parameters.
    pub params: Vec<ParsedParameter>,
    /// Where it was.
    pub loc: FileLoc,
}

impl Given {
    /// The directive `name params` at `loc`.
    pub fn new(name: &str, params: Vec<ParsedParameter>, loc: FileLoc) -> Self {
        Given {
            name: name.to_string(),
            params,
            loc,
        }
    }
}

/// The `Renderer`, `SurfaceIntegrator` and `VolumeIntegrator` of a pbrt-v1
/// or pbrt-v2 file (the last of each).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LegacyTransport {
    /// `Renderer` (pbrt-v2's default: `sampler`).
    pub renderer: Option<Given>,
    /// `SurfaceIntegrator` (default: `directlighting`).
    pub surface: Option<Given>,
    /// `VolumeIntegrator` (default: `emission`).
    pub volume: Option<Given>,
}

/// Which of the three directives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Transport {
    /// `Renderer`.
    Renderer,
    /// `SurfaceIntegrator`.
    Surface,
    /// `VolumeIntegrator`.
    Volume,
}

impl Transport {
    /// The directive's name.
    pub fn directive(self) -> &'static str {
        match self {
            Transport::Renderer => "Renderer",
            Transport::Surface => "SurfaceIntegrator",
            Transport::Volume => "VolumeIntegrator",
        }
    }
}

/// For whom the integrator is made.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// rpbrt's renderer, which also has pbrt-v3's `whitted`.
    Render,
    /// pbrt-v4 text (`--upgrade`).
    PbrtV4,
}

/// pbrt-v2's surface integrators that pbrt-v4 has no counterpart for, and
/// what they computed (for the substitution warning).
const APPROXIMATE: &[(&str, &str)] = &[
    ("photonmap", "photon mapping with final gathering"),
    ("exphotonmap", "photon mapping with final gathering"),
    ("irradiancecache", "irradiance caching"),
    ("igi", "instant global illumination (virtual point lights)"),
    (
        "useprobes",
        "precomputed radiance probes (made by the \"createprobes\" renderer)",
    ),
    ("diffuseprt", "diffuse precomputed radiance transfer"),
    ("glossyprt", "glossy precomputed radiance transfer"),
];

/// The pbrt-v2 renderers that make no image, and what they were for.
const TOOLS: &[(&str, &str)] = &[
    (
        "createprobes",
        "it precomputes the radiance probes of the \"useprobes\" surface integrator and writes them to a file",
    ),
    (
        "surfacepoints",
        "it writes the surface points the \"dipolesubsurface\" integrator samples to a file",
    ),
    (
        "aggregatetest",
        "it checks the accelerator's intersections against every primitive's",
    ),
];

impl LegacyTransport {
    /// Records directive `which` (a later one replaces an earlier one).
    pub fn set(&mut self, which: Transport, given: Given) {
        let slot = match which {
            Transport::Renderer => &mut self.renderer,
            Transport::Surface => &mut self.surface,
            Transport::Volume => &mut self.volume,
        };
        *slot = Some(given);
    }

    /// Whether the file gave none of the three directives.
    pub fn is_empty(&self) -> bool {
        self.renderer.is_none() && self.surface.is_none() && self.volume.is_none()
    }

    /// The one integrator that renders what the three directives did.
    /// `volumes`: the scene has `Volume` regions (without them the volume
    /// integrator has nothing to do); `loc`: where a default directive is
    /// said to be. The result's diagnostics hold the substitution
    /// warnings, and an error where the file asks for a renderer that
    /// makes no image.
    pub fn integrator(&self, volumes: bool, target: Target, loc: &FileLoc) -> Upgraded {
        if let Some(r) = &self.renderer {
            match r.name.as_str() {
                "sampler" => {}
                "metropolis" => return metropolis(r),
                name => {
                    let mut e = Edit::new(name, r.params.clone(), &r.loc);
                    let why = TOOLS.iter().find(|(n, _)| *n == name).map_or_else(
                        || {
                            format!(
                                "\"{name}\": unknown pbrt-v2 renderer (pbrt-v2's renderers: \"sampler\", \"metropolis\", \"createprobes\", \"surfacepoints\", \"aggregatetest\")"
                            )
                        },
                        |(_, what)| {
                            format!(
                                "pbrt-v2's \"{name}\" renderer makes no image: {what}. Remove the Renderer line to render the scene"
                            )
                        },
                    );
                    e.error(None, why);
                    return e.finish();
                }
            }
        }
        let surface = self
            .surface
            .clone()
            .unwrap_or_else(|| Given::new("directlighting", Vec::new(), loc.clone()));
        let mut e = surface_integrator(&surface, target);
        if volumes {
            let volume = self
                .volume
                .clone()
                .unwrap_or_else(|| Given::new("emission", Vec::new(), loc.clone()));
            volume_integrator(&mut e, &volume);
        }
        e.finish()
    }
}

/// The integer parameter `name` of `e`, or `default`.
fn int_or(e: &Edit, name: &str, default: i32) -> i32 {
    e.get(name, &["integer"])
        .and_then(|p| p.ints.first().copied())
        .unwrap_or(default)
}

/// `e` with `maxdepth` set to `depth` (first, as pbrt-v4 prints it).
fn set_max_depth(e: &mut Edit, depth: i32) {
    e.remove_all("maxdepth", &["integer"]);
    let mut p = ParsedParameter::new("integer", "maxdepth", e.loc.clone());
    p.ints = vec![depth];
    e.add_front(p);
}

/// A `SurfaceIntegrator` as a pbrt-v4 integrator (pbrt-v2 defaults:
/// `maxdepth` 5 for `directlighting`, `whitted` and `path`).
pub(super) fn surface_integrator(s: &Given, target: Target) -> Edit {
    let name = s.name.as_str();
    let mut e = Edit::new(name, s.params.clone(), &s.loc);
    match name {
        // Direct lighting at each hit plus perfectly specular reflection
        // and transmission followed to `maxdepth`: what pbrt-v3's whitted
        // computes (with one sample of each light instead of MIS, which
        // changes only the noise). pbrt-v4 has neither, and --upgrade
        // writes what it writes for pbrt-v3's directlighting.
        "directlighting" | "whitted" => {
            let depth = int_or(&e, "maxdepth", 5);
            e.remove_all("strategy", &["string"]);
            match target {
                Target::Render => {
                    e.name = "whitted".into();
                    set_max_depth(&mut e, depth);
                }
                Target::PbrtV4 => {
                    e.name = "path".into();
                    set_max_depth(&mut e, 1);
                    e.warn(
                        None,
                        format!("pbrt-v2's \"{name}\" is approximated by \"path\" with \"maxdepth\" 1 (pbrt-v4 follows no specular chains in it)"),
                    );
                }
            }
        }
        "path" => {
            let depth = int_or(&e, "maxdepth", 5);
            set_max_depth(&mut e, depth);
        }
        // pbrt-v2 counts the unoccluded share of `nsamples` cosine-
        // distributed directions within `maxdist`: pbrt-v4's
        // ambientocclusion (cosine sampling) converges to the same value.
        "ambientocclusion" => {
            e.remove_all("nsamples", &["integer"]);
            if let Some(mut p) = e.remove("maxdist", &["float"]) {
                p.name = "maxdistance".into();
                e.add_front(p);
            }
        }
        "dipolesubsurface" => {
            let depth = int_or(&e, "maxdepth", 5);
            e.params.clear();
            e.name = "volpath".into();
            set_max_depth(&mut e, depth);
            e.warn(
                None,
                "pbrt-v2's \"dipolesubsurface\" (the dipole diffusion approximation over precomputed surface points) is rendered by \"volpath\", which traces the subsurface materials' BSSRDFs; the image converges to pbrt-v4's BSSRDF, not pbrt-v2's dipole".into(),
            );
        }
        _ => {
            let Some((_, what)) = APPROXIMATE.iter().find(|(n, _)| *n == name) else {
                e.error(
                    None,
                    format!("\"{name}\": unknown pbrt-v2 surface integrator (pbrt-v2's: \"directlighting\", \"path\", \"whitted\", \"ambientocclusion\", \"photonmap\", \"exphotonmap\", \"irradiancecache\", \"igi\", \"dipolesubsurface\", \"useprobes\", \"diffuseprt\", \"glossyprt\")"),
                );
                return e;
            };
            // Each approximates global illumination to some depth; `path`
            // converges to the light transport they estimate.
            let depth = ["maxdepth", "maxspeculardepth", "maxindirectdepth"]
                .iter()
                .filter_map(|n| e.get(n, &["integer"]).and_then(|p| p.ints.first().copied()))
                .max()
                .unwrap_or(5);
            e.params.clear();
            e.name = "path".into();
            set_max_depth(&mut e, depth);
            e.warn(
                None,
                format!("pbrt-v2's \"{name}\" surface integrator ({what}) is rendered by \"path\", which converges to the light transport it approximates; its own bias and noise are not reproduced"),
            );
        }
    }
    e
}

/// Folds the `VolumeIntegrator` into the surface integrator `e`: with
/// `Volume` regions in the scene, `volpath` renders both.
fn volume_integrator(e: &mut Edit, v: &Given) {
    match v.name.as_str() {
        // Absorption and emission only: the regions' scattering is dropped
        // where they are made (`Volume` with an `emission` integrator), so
        // volpath renders exactly that.
        "emission" => {}
        "single" => e.warn(
            Some(&v.loc),
            "pbrt-v2's \"single\" volume integrator (single scattering) is rendered by \"volpath\", which also follows multiple scattering: scattering regions look brighter than in pbrt-v2".into(),
        ),
        name => {
            e.error(
                Some(&v.loc),
                format!("\"{name}\": unknown pbrt-v2 volume integrator (pbrt-v2's: \"emission\", \"single\")"),
            );
            return;
        }
    }
    match e.name.as_str() {
        "path" | "volpath" => e.name = "volpath".into(),
        // Direct lighting through media has no integrator of its own in
        // pbrt-v4, which renders media with volpath.
        "whitted" => {
            e.name = "volpath".into();
            e.warn(
                Some(&v.loc),
                "with \"Volume\" regions, pbrt-v2's direct lighting is rendered by \"volpath\" (up to the same \"maxdepth\"), which also carries indirect light between surfaces: they look brighter than in pbrt-v2".into(),
            );
        }
        other => {
            let other = other.to_string();
            e.warn(
                Some(&v.loc),
                format!("the \"{other}\" integrator does not see the \"Volume\" regions; use the \"path\" surface integrator to render them"),
            );
        }
    }
}

/// `Renderer "metropolis"` → `mlt` (pbrt-v2 `renderers/metropolis.cpp`):
/// `samplesperpixel` mutations per pixel (default 100), `bootstrapsamples`
/// (100000), `maxdepth` (7) and `largestepprobability` (0.25) keep their
/// meaning, written out where pbrt-v4's defaults differ. Its
/// `directsamples`/`dodirectseparately` (direct lighting estimated apart),
/// `bidirectional` and `maxconsecutiverejects` change only the noise.
fn metropolis(r: &Given) -> Upgraded {
    let mut e = Edit::new("mlt", r.params.clone(), &r.loc);
    let depth = int_or(&e, "maxdepth", 7);
    set_max_depth(&mut e, depth);
    if let Some(mut p) = e.remove("samplesperpixel", &["integer"]) {
        p.name = "mutationsperpixel".into();
        e.add_front(p);
    }
    if e.get("largestepprobability", &["float"]).is_none() {
        let p = e.float("largestepprobability", &[0.25]);
        e.add_front(p);
    }
    for (name, ty) in [
        ("directsamples", "integer"),
        ("dodirectseparately", "bool"),
        ("bidirectional", "bool"),
        ("maxconsecutiverejects", "integer"),
    ] {
        e.remove_all(name, &[ty]);
    }
    e.finish()
}
