//! Tests of scene creation from scene text: what the creation loops of
//! [`super::assemble`] and [`super::materials`] do with whole directives
//! (orders, references between entities, located errors, warnings).

mod accel;
mod budget;
mod camera;
mod materials;
mod media;
mod taking;
mod textures;

use std::collections::HashMap;

use rpbrt_parser::Diagnostic;

use super::assemble::Problems;
use super::entities::{SceneDescription, SceneEntity};
use super::{build_scene_from_str, BuildOptions};
use crate::image::MIPMapCache;
use crate::material::MaterialSet;
use crate::texture::{NamedTextures, TextureOptions};

/// The description of `text`, placed after `WorldBegin` (line numbers in
/// the tests count from the line after it).
fn build(text: &str) -> SceneDescription {
    let full = format!("WorldBegin\n{text}");
    // Creation's own errors for missing files are tested here.
    let opts = BuildOptions {
        skip_file_check: true,
        ..Default::default()
    };
    match build_scene_from_str(&full, &opts) {
        Ok((s, _)) => s,
        Err(d) => panic!("{}", d.render()),
    }
}

/// Errors then warnings, when creation failed.
fn failed(p: Problems) -> Vec<Diagnostic> {
    let mut all = p.errors;
    all.extend(p.warnings);
    all
}

/// The named textures of `desc` and the warnings, or every problem.
fn create_textures_of(
    desc: &SceneDescription,
) -> Result<(NamedTextures, Vec<Diagnostic>), Vec<Diagnostic>> {
    let mut p = Problems::default();
    match super::materials::create_textures(
        &desc.float_textures,
        &desc.spectrum_textures,
        &MIPMapCache::new(),
        &TextureOptions::default(),
        &desc.budget,
        &mut p,
    ) {
        Some(t) if p.errors.is_empty() => Ok((t, p.warnings)),
        _ => Err(failed(p)),
    }
}

/// The materials, named-material indices and warnings, or every problem.
#[allow(clippy::type_complexity)]
fn create_materials(
    materials: &[SceneEntity],
    named: &[(String, SceneEntity)],
    textures: &NamedTextures,
) -> Result<(MaterialSet, HashMap<String, u32>, Vec<Diagnostic>), Vec<Diagnostic>> {
    let mut p = Problems::default();
    match super::materials::create_materials(
        materials,
        named,
        textures,
        &Default::default(),
        &mut p,
    ) {
        Some((set, ids)) if p.errors.is_empty() => Ok((set, ids, p.warnings)),
        _ => Err(failed(p)),
    }
}
