//! The files a scene reads (images, meshes, volumes, spectra, lens
//! descriptions, measured BSDFs), checked all at once before any is
//! opened, so that one run reports every missing file, not the first.

use rpbrt_parser::{Diagnostic, ParsedParameter};

use super::entities::{SceneDescription, SceneEntity};
use crate::params::resolve_path;
use crate::spectrum::named_spectrum;

/// Parameters whose string values name input files, wherever they appear
/// (the film's `filename` names its output and is left out).
const FILE_PARAMS: [&str; 6] = [
    "filename",
    "lensfile",
    "normalmap",
    "bsdffile",
    "mapname",
    "emissionfilename",
];

/// `aperture` names a file unless it is one of the built-in shapes.
const BUILTIN_APERTURES: [&str; 4] = ["gaussian", "square", "pentagon", "star"];

fn is_spectrum_type(ty: &str) -> bool {
    ty == "spectrum"
}

/// The file names `p` holds, if it names files.
fn file_values(p: &ParsedParameter) -> Vec<&str> {
    let strings = p.strings.iter().map(String::as_str);
    if FILE_PARAMS.contains(&p.name.as_str()) && p.ty == "string" {
        return strings.filter(|s| !s.is_empty()).collect();
    }
    if p.name == "aperture" && p.ty == "string" {
        return strings
            .filter(|s| !s.is_empty() && !BUILTIN_APERTURES.contains(s))
            .collect();
    }
    if is_spectrum_type(&p.ty) {
        // A spectrum given by name is built in; any other string is a file.
        return strings.filter(|s| named_spectrum(s).is_none()).collect();
    }
    Vec::new()
}

fn check(entity: &SceneEntity, out: &mut Vec<Diagnostic>) {
    for p in entity.params.params() {
        for f in file_values(p) {
            let path = resolve_path(&p.loc.file, f);
            if !path.is_file() {
                let why = if path.exists() {
                    "not a file"
                } else {
                    "no such file"
                };
                out.push(Diagnostic::error(
                    p.loc.clone(),
                    format!("{} \"{}\": {why}: \"{f}\"", entity.name, p.name),
                ));
            }
        }
    }
}

/// An error for every input file the scene names that does not exist, in
/// the order the directives came.
pub fn missing_files(desc: &SceneDescription) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    let c = &mut out;
    // The film's and the integrator's (`function`) file names are outputs.
    for e in [&desc.sampler, &desc.filter, &desc.accelerator] {
        check(e, c);
    }
    check(&desc.camera.base, c);
    for s in &desc.shapes {
        check(&s.base, c);
    }
    for s in &desc.animated_shapes {
        check(&s.base, c);
    }
    for d in &desc.instance_definitions {
        for s in &d.shapes {
            check(&s.base, c);
        }
        for s in &d.animated_shapes {
            check(&s.base, c);
        }
    }
    for l in &desc.lights {
        check(&l.base, c);
    }
    for e in desc.area_lights.iter().chain(&desc.materials) {
        check(e, c);
    }
    for (_, m) in &desc.named_materials {
        check(m, c);
    }
    for t in desc.float_textures.iter().chain(&desc.spectrum_textures) {
        check(&t.base, c);
    }
    for m in &desc.media {
        check(&m.base, c);
    }
    out.sort_by_key(|d| {
        d.loc
            .as_ref()
            .map(|l| (l.file.to_string(), l.line, l.column))
    });
    out
}

#[cfg(test)]
mod tests {
    use crate::scene::{build_scene_from_str, BuildOptions};

    #[test]
    fn every_missing_file_is_reported_at_once() {
        let text = r#"WorldBegin
Texture "a" "spectrum" "imagemap" "string filename" "nope1.png"
Texture "b" "float" "imagemap" "string filename" "nope2.exr"
Material "conductor" "spectrum eta" "metal-Au-eta" "spectrum k" "nope.spd"
Shape "plymesh" "string filename" "nomesh.ply"
LightSource "infinite" "string filename" "noenv.exr"
Shape "sphere"
"#;
        let d = build_scene_from_str(text, &BuildOptions::default()).expect_err("missing files");
        let errors: Vec<String> = d.items.iter().map(|e| e.to_string()).collect();
        let all = errors.join("\n");
        for (line, name) in [
            (2, "nope1.png"),
            (3, "nope2.exr"),
            (4, "nope.spd"),
            (5, "nomesh.ply"),
            (6, "noenv.exr"),
        ] {
            assert!(
                all.contains(&format!("<string>:{line}:")) && all.contains(name),
                "{name} not reported:\n{all}"
            );
        }
        assert!(!all.contains("metal-Au-eta"), "{all}");
        assert_eq!(errors.len(), 5, "{all}");
    }

    #[test]
    fn missing_includes_and_files_come_together() {
        let text = "WorldBegin\nInclude \"noinc.pbrt\"\nShape \"plymesh\" \"string filename\" \"nomesh.ply\"\n";
        let d = build_scene_from_str(text, &BuildOptions::default()).expect_err("missing");
        let all: String = d.items.iter().map(|e| e.to_string() + "\n").collect();
        assert!(
            all.contains("noinc.pbrt") && all.contains("nomesh.ply"),
            "{all}"
        );
    }
}
