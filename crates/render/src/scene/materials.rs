//! The scene's named textures and its materials (pbrt-v4
//! `BasicScene::CreateTextures` and `BasicScene::CreateMaterials`): the
//! order they are created in, which names each may refer to, and one
//! parameter reader per directive.
//!
//! Float textures are created first, then spectrum textures, each in
//! definition order, so a texture may use any float texture and any
//! earlier texture of its kind; every spectrum texture is made once per
//! [`SpectrumType`]. Anonymous materials keep their indices `0..n` (the
//! description's `MaterialRef::Index`); named ones follow in definition
//! order. As in pbrt-v4, a named `mix` may only use named materials
//! defined before it; anonymous ones may use any. Image textures' files
//! are read first, in parallel.

use std::collections::{HashMap, HashSet};
use std::sync::atomic::{AtomicUsize, Ordering};

use rpbrt_parser::{Diagnostic, MemoryBudget};

use super::assemble::{reader, Problems};
use super::entities::{SceneEntity, TextureKind, TextureSceneEntity};
use crate::image::MIPMapCache;
use crate::material::{create_material, Material, MaterialSet, NormalMapCache};
use crate::spectrum::SpectrumType;
use crate::texture::{
    create_float_texture, create_spectrum_texture, ImageRequest, NamedTextures, TextureDef,
    TextureOptions, TextureParams,
};

fn texture_def(e: &TextureSceneEntity) -> TextureDef<'_> {
    TextureDef {
        name: &e.name,
        class: &e.base.name,
        render_from_texture: e.render_from_object.start_transform(),
    }
}

/// Reads the image textures' files into `cache` in parallel (pbrt-v4
/// reads them while parsing, asynchronously), so that creating the
/// textures in order then finds them there. Only the requests are read
/// here: a texture whose parameters or file fail is left to its creation,
/// which reports it (failed reads are not cached).
fn preload_images<'e>(
    entities: impl Iterator<Item = &'e TextureSceneEntity>,
    cache: &MIPMapCache,
    options: &TextureOptions,
    budget: &MemoryBudget,
) {
    let requests: Vec<ImageRequest> = entities
        .filter(|e| e.base.name == "imagemap")
        .filter_map(|e| {
            let r = reader(&e.base, budget).ok()?;
            ImageRequest::read(&texture_def(e), &r, options).ok()
        })
        .collect();
    let threads = crate::accel::default_threads().min(requests.len());
    if threads < 2 {
        return;
    }
    let next = AtomicUsize::new(0);
    std::thread::scope(|s| {
        for _ in 0..threads {
            s.spawn(|| {
                while let Some(r) = requests.get(next.fetch_add(1, Ordering::Relaxed)) {
                    // Errors are reported when the texture is created.
                    let _ = r.load(cache);
                }
            });
        }
    });
}

/// Creates every named texture. A texture that fails is left out (later
/// references to it fail too); `None` when any failed.
pub(super) fn create_textures(
    float_entities: &[TextureSceneEntity],
    spectrum_entities: &[TextureSceneEntity],
    cache: &MIPMapCache,
    options: &TextureOptions,
    budget: &MemoryBudget,
    problems: &mut Problems,
) -> Option<NamedTextures> {
    let mut named = NamedTextures::default();
    let errors_before = problems.errors.len();
    preload_images(
        float_entities.iter().chain(spectrum_entities),
        cache,
        options,
        budget,
    );
    let spectrum_names: HashSet<String> =
        spectrum_entities.iter().map(|e| e.name.clone()).collect();
    for e in float_entities {
        debug_assert_eq!(e.kind, TextureKind::Float);
        let Some(r) = problems.take(reader(&e.base, budget)) else {
            continue;
        };
        let tp = TextureParams::with_later_spectrum(r, &named, &spectrum_names);
        let made = create_float_texture(&texture_def(e), &tp, cache, options);
        if let Some(t) = problems.finish(tp.into_reader(), made) {
            named.float.insert(e.name.clone(), t);
        }
    }
    let types = [
        SpectrumType::Albedo,
        SpectrumType::Unbounded,
        SpectrumType::Illuminant,
    ];
    for e in spectrum_entities {
        debug_assert_eq!(e.kind, TextureKind::Spectrum);
        let Some(r) = problems.take(reader(&e.base, budget)) else {
            continue;
        };
        let tp = TextureParams::new(r, &named);
        let made: Result<Vec<_>, Diagnostic> = types
            .iter()
            .map(|&ty| create_spectrum_texture(&texture_def(e), ty, &tp, cache, options))
            .collect();
        if let Some(made) = problems.finish(tp.into_reader(), made) {
            for (ty, t) in types.into_iter().zip(made) {
                named.spectrum_mut(ty).insert(e.name.clone(), t);
            }
        }
    }
    (problems.errors.len() == errors_before).then_some(named)
}

/// Creates every material: `materials` (anonymous, indices
/// `0..materials.len()`) and `named_materials` (indices following, in
/// order). Returns the set and the index of each named material; `None`
/// when any failed.
pub(super) fn create_materials(
    materials: &[SceneEntity],
    named_materials: &[(String, SceneEntity)],
    textures: &NamedTextures,
    budget: &MemoryBudget,
    problems: &mut Problems,
) -> Option<(MaterialSet, HashMap<String, u32>)> {
    let n_anon = materials.len();
    let errors_before = problems.errors.len();
    let mut normal_maps = NormalMapCache::new();
    let mut out: Vec<Option<Material>> = vec![None; n_anon + named_materials.len()];
    // Every named material's index, and how many were defined before each.
    let all_named: HashMap<&str, (usize, u32)> = named_materials
        .iter()
        .enumerate()
        .map(|(j, (name, _))| (name.as_str(), (j, (n_anon + j) as u32)))
        .collect();

    let mut create = |e: &SceneEntity,
                      ty: &str,
                      visible: &dyn Fn(&str) -> Result<u32, String>,
                      problems: &mut Problems|
     -> Option<Material> {
        let tp = TextureParams::new(problems.take(reader(e, budget))?, textures);
        let made = create_material(ty, &tp, visible, &mut normal_maps);
        problems.finish(tp.into_reader(), made)
    };

    for (j, (name, e)) in named_materials.iter().enumerate() {
        // `MakeNamedMaterial` gives its type as `"string type"`.
        let ty = match e.params.get_one_string("type", "") {
            Ok(t) if !t.is_empty() => t,
            Ok(_) => e.name.to_string(),
            Err(err) => {
                problems.errors.push(err.into());
                continue;
            }
        };
        let visible = |m: &str| match all_named.get(m) {
            Some(&(k, index)) if k < j => Ok(index),
            Some(_) => Err(format!(
                "named material \"{m}\" is used by \"{name}\" before it is defined"
            )),
            None => Err(format!("\"{m}\": named material not defined")),
        };
        out[n_anon + j] = create(e, &ty, &visible, problems);
    }
    for (i, e) in materials.iter().enumerate() {
        let visible = |m: &str| match all_named.get(m) {
            Some(&(_, index)) => Ok(index),
            None => Err(format!("\"{m}\": named material not defined")),
        };
        out[i] = create(e, &e.name, &visible, problems);
    }
    if problems.errors.len() != errors_before {
        return None;
    }
    let set: Vec<Material> = out.into_iter().flatten().collect();
    debug_assert_eq!(set.len(), n_anon + named_materials.len());
    let named = all_named
        .into_iter()
        .map(|(k, (_, index))| (k.to_string(), index))
        .collect();
    let locs = materials
        .iter()
        .chain(named_materials.iter().map(|(_, e)| e))
        .map(|e| e.loc.clone())
        .collect();
    Some((MaterialSet::new(set).with_locs(locs), named))
}
