//! Materials (pbrt-v4 book section 10.5 and chapter 9; pbrt-v4
//! `base/material.h`, `materials.h/.cpp`, `interaction.cpp`'s
//! `SurfaceInteraction::GetBSDF`).
//!
//! A [`Material`] turns the textures it holds into a BxDF at a surface
//! point. [`MaterialSet`] keeps every material of a scene, indexed by the
//! `u32` the primitives carry, and does what pbrt-v4's `GetBSDF` does after
//! the ray differentials are known: it resolves `mix` materials, skips
//! `interface` ones, applies normal or bump mapping to the shading geometry
//! and builds the [`BSDF`].
//!
//! [`Material`] is a closed enum; each method is a one-line delegation.

use std::sync::Arc;

use rpbrt_geometry::float::*;
use rpbrt_geometry::interaction::SurfaceInteraction;
use rpbrt_geometry::tuple::*;
use rpbrt_parser::FileLoc;

use crate::bssrdf::Bssrdf;
use crate::bxdf::{BxDF, DiffuseBxDF, TrowbridgeReitzDistribution, BSDF};
use crate::image::Image;
use crate::spectrum::{SampledWavelengths, Spectrum};
use crate::texture::{FloatTextureRef, SpectrumTextureRef, TextureEvalContext};

mod bump;
mod coated;
mod conductor;
mod create;
mod dielectric;
mod diffuse;
mod disney;
mod fourier;
mod hair;
mod lafortune;
mod measured;
mod merl;
mod mix;
mod shinymetal;
mod subsurface;
#[cfg(test)]
mod tests;

pub use crate::medium::measured::get_medium_scattering_properties;
pub use bump::{bump_map, normal_map, read_normal_map};
pub use coated::{CoatedConductorMaterial, CoatedDiffuseMaterial};
pub use conductor::{ConductorMaterial, ConductorSpectra};
pub use create::{create_material, NormalMapCache, MATERIAL_NAMES};
pub use dielectric::{DielectricMaterial, ThinDielectricMaterial};
pub use diffuse::{DiffuseMaterial, DiffuseTransmissionMaterial};
pub use disney::DisneyMaterial;
pub use fourier::FourierMaterial;
pub use hair::{HairAbsorption, HairMaterial};
pub use lafortune::LafortuneMaterial;
pub use measured::MeasuredMaterial;
pub use merl::{IrregularMaterial, MerlMaterial};
pub use mix::MixMaterial;
pub use shinymetal::ShinyMetalMaterial;
pub use subsurface::{SubsurfaceCoefficients, SubsurfaceMaterial};

/// The longest chain of `mix` materials [`MaterialSet::resolve`] follows.
pub const MIX_MAX_DEPTH: usize = 64;

/// What a material sees of the point being shaded (pbrt-v4
/// `MaterialEvalContext`): the texture context plus the outgoing direction
/// and the geometric and shading frames.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MaterialEvalContext {
    /// What textures see.
    pub tex: TextureEvalContext,
    /// Outgoing direction ωo.
    pub wo: Vector3f,
    /// Geometric normal.
    pub n: Normal3f,
    /// Shading normal.
    pub ns: Normal3f,
    /// Shading ∂p/∂u.
    pub dpdus: Vector3f,
}

impl MaterialEvalContext {
    /// The context of a surface interaction (after differentials and any
    /// normal or bump mapping).
    pub fn from_si(si: &SurfaceInteraction) -> Self {
        MaterialEvalContext {
            tex: TextureEvalContext::from_si(si),
            wo: si.wo,
            n: si.n,
            ns: si.shading.n,
            dpdus: si.shading.dpdu,
        }
    }
}

/// Microfacet roughness given as two float textures (pbrt-v4's
/// `uroughness`/`vroughness`, both defaulting to `roughness`).
#[derive(Clone, Debug)]
pub struct Roughness {
    /// Roughness along ∂p/∂u.
    pub u: FloatTextureRef,
    /// Roughness along ∂p/∂v.
    pub v: FloatTextureRef,
    /// Map user roughness in [0, 1] to the distribution's α.
    pub remap: bool,
}

impl Roughness {
    /// The Trowbridge–Reitz distribution at a point.
    #[inline]
    pub fn distribution(&self, ctx: &TextureEvalContext) -> TrowbridgeReitzDistribution {
        let (mut u, mut v) = (self.u.evaluate(ctx), self.v.evaluate(ctx));
        if self.remap {
            u = TrowbridgeReitzDistribution::roughness_to_alpha(u);
            v = TrowbridgeReitzDistribution::roughness_to_alpha(v);
        }
        TrowbridgeReitzDistribution::new(u, v)
    }
}

/// Normal or bump mapping a material applies before building its BxDF
/// (pbrt-v4 `GetNormalMap`, `GetDisplacement`).
#[derive(Clone, Debug, Default)]
pub struct ShadingPerturbation {
    /// A displacement texture for bump mapping.
    pub displacement: Option<FloatTextureRef>,
    /// A tangent-space normal map (three channels, R G B, linear). It takes
    /// precedence over `displacement`, as in pbrt-v4.
    pub normal_map: Option<Arc<Image>>,
}

impl ShadingPerturbation {
    /// True when there is something to apply.
    #[inline]
    pub fn is_some(&self) -> bool {
        self.displacement.is_some() || self.normal_map.is_some()
    }

    /// Updates `si`'s shading geometry as pbrt-v4's `GetBSDF` does: the
    /// perturbed ∂p/∂u and ∂p/∂v give the shading normal, which is flipped
    /// to the side of the geometric normal. Degenerate results (parallel
    /// derivatives) leave the shading geometry unchanged.
    pub fn apply(&self, si: &mut SurfaceInteraction) {
        let (dpdu, dpdv) = if let Some(nm) = &self.normal_map {
            normal_map(nm, si)
        } else if let Some(d) = &self.displacement {
            bump_map(d, si)
        } else {
            return;
        };
        let Some(ns) = cross(dpdu, dpdv).try_normalize() else {
            return;
        };
        if !(ns.x.is_finite() && ns.y.is_finite() && ns.z.is_finite()) {
            return;
        }
        let (dndu, dndv) = (si.shading.dndu, si.shading.dndv);
        si.set_shading_geometry(Normal3f::from(ns), dpdu, dpdv, dndu, dndv, false);
    }
}

/// The index of refraction a spectrum gives at the first wavelength; a
/// spectrum that varies with wavelength (dispersion) terminates the
/// secondary wavelengths. A zero index is taken as 1 (pbrt-v4).
#[inline]
pub fn sample_eta(eta: &Spectrum, lambda: &mut SampledWavelengths) -> Float {
    let e = eta.evaluate(lambda[0]);
    if !matches!(eta, Spectrum::Constant(_)) {
        lambda.terminate_secondary();
    }
    if e == 0.0 {
        1.0
    } else {
        e
    }
}

/// The closed set of materials.
#[derive(Clone, Debug)]
pub enum Material {
    /// Lambertian reflection.
    Diffuse(DiffuseMaterial),
    /// Lambertian reflection and transmission.
    DiffuseTransmission(DiffuseTransmissionMaterial),
    /// Metal.
    Conductor(ConductorMaterial),
    /// Glass-like interface.
    Dielectric(DielectricMaterial),
    /// Thin dielectric slab.
    ThinDielectric(ThinDielectricMaterial),
    /// Dielectric coating over a diffuse base.
    CoatedDiffuse(Box<CoatedDiffuseMaterial>),
    /// Dielectric coating over a conductor.
    CoatedConductor(Box<CoatedConductorMaterial>),
    /// Hair fibers.
    Hair(HairMaterial),
    /// A stochastic choice between two materials.
    Mix(MixMaterial),
    /// No surface: only marks a boundary between media (pbrt-v4
    /// `"interface"`, `""`, `"none"`).
    Interface,
    /// A dielectric boundary over a scattering volume.
    Subsurface(Box<SubsurfaceMaterial>),
    /// Tabulated measured reflectance.
    Measured(Box<MeasuredMaterial>),
    /// pbrt-v3's Disney BSDF.
    Disney(Box<DisneyMaterial>),
    /// pbrt-v3's tabulated Fourier BSDF.
    Fourier(Box<FourierMaterial>),
    /// pbrt-v1/v2's `shinymetal`.
    ShinyMetal(Box<ShinyMetalMaterial>),
    /// pbrt-v1's measured Lafortune fits.
    Lafortune(Box<LafortuneMaterial>),
    /// pbrt-v2's `measured` with a MERL table.
    Merl(Box<MerlMaterial>),
    /// pbrt-v2's `measured` with irregular `.brdf` measurements.
    Irregular(Box<IrregularMaterial>),
}

impl Material {
    /// The material's BxDF at a point; `None` for `Interface` and `Mix`
    /// (mixes are resolved first with [`MaterialSet::resolve`]). `seed` is
    /// pbrt-v4's `--seed`, which layered BxDFs mix into their random walks.
    #[inline]
    pub fn get_bxdf(
        &self,
        ctx: &MaterialEvalContext,
        lambda: &mut SampledWavelengths,
        seed: i32,
    ) -> Option<BxDF> {
        match self {
            Material::Diffuse(m) => Some(m.get_bxdf(ctx, lambda)),
            Material::DiffuseTransmission(m) => Some(m.get_bxdf(ctx, lambda)),
            Material::Conductor(m) => Some(m.get_bxdf(ctx, lambda)),
            Material::Dielectric(m) => Some(m.get_bxdf(ctx, lambda)),
            Material::ThinDielectric(m) => Some(m.get_bxdf(ctx, lambda)),
            Material::CoatedDiffuse(m) => Some(m.get_bxdf(ctx, lambda, seed)),
            Material::CoatedConductor(m) => Some(m.get_bxdf(ctx, lambda, seed)),
            Material::Hair(m) => Some(m.get_bxdf(ctx, lambda)),
            Material::Mix(_) | Material::Interface => None,
            Material::Subsurface(m) => Some(m.get_bxdf(ctx, lambda)),
            Material::Measured(m) => Some(m.get_bxdf(ctx, lambda)),
            Material::Disney(m) => Some(m.get_bxdf(ctx, lambda)),
            Material::Fourier(m) => Some(m.get_bxdf(ctx, lambda)),
            Material::ShinyMetal(m) => Some(m.get_bxdf(ctx, lambda)),
            Material::Lafortune(m) => Some(m.get_bxdf(ctx, lambda)),
            Material::Merl(m) => Some(m.get_bxdf(ctx, lambda)),
            Material::Irregular(m) => Some(m.get_bxdf(ctx, lambda)),
        }
    }

    /// The normal map and displacement applied before the BxDF is built.
    #[inline]
    pub fn perturbation(&self) -> Option<&ShadingPerturbation> {
        match self {
            Material::Diffuse(m) => Some(&m.perturbation),
            Material::DiffuseTransmission(m) => Some(&m.perturbation),
            Material::Conductor(m) => Some(&m.perturbation),
            Material::Dielectric(m) => Some(&m.perturbation),
            Material::ThinDielectric(m) => Some(&m.perturbation),
            Material::CoatedDiffuse(m) => Some(&m.perturbation),
            Material::CoatedConductor(m) => Some(&m.perturbation),
            Material::Subsurface(m) => Some(&m.perturbation),
            Material::Measured(m) => Some(&m.perturbation),
            Material::Disney(m) => Some(&m.perturbation),
            Material::Fourier(m) => Some(&m.perturbation),
            Material::ShinyMetal(m) => Some(&m.perturbation),
            Material::Lafortune(m) => Some(&m.perturbation),
            Material::Merl(m) => Some(&m.perturbation),
            Material::Irregular(m) => Some(&m.perturbation),
            Material::Hair(_) | Material::Mix(_) | Material::Interface => None,
        }
    }

    /// True for materials that can have a BSSRDF (`subsurface`, and a solid
    /// `disney` with a `scatterdistance`).
    #[inline]
    pub fn has_subsurface_scattering(&self) -> bool {
        match self {
            Material::Subsurface(_) => true,
            Material::Disney(m) => m.has_subsurface_scattering(),
            _ => false,
        }
    }

    /// True for `interface` materials, which have no BSDF.
    #[inline]
    pub fn is_interface(&self) -> bool {
        matches!(self, Material::Interface)
    }

    /// The scene-file name of the material's type.
    pub fn type_name(&self) -> &'static str {
        match self {
            Material::Diffuse(_) => "diffuse",
            Material::DiffuseTransmission(_) => "diffusetransmission",
            Material::Conductor(_) => "conductor",
            Material::Dielectric(_) => "dielectric",
            Material::ThinDielectric(_) => "thindielectric",
            Material::CoatedDiffuse(_) => "coateddiffuse",
            Material::CoatedConductor(_) => "coatedconductor",
            Material::Hair(_) => "hair",
            Material::Mix(_) => "mix",
            Material::Interface => "interface",
            Material::Subsurface(_) => "subsurface",
            Material::Measured(_) => "measured",
            Material::Disney(_) => "disney",
            Material::Fourier(_) => "fourier",
            Material::ShinyMetal(_) => "shinymetal",
            Material::Lafortune(m) => m.fit.name,
            Material::Merl(_) | Material::Irregular(_) => "measured",
        }
    }
}

/// Every material of a scene, indexed by the `u32` primitives carry.
#[derive(Clone, Debug, Default)]
pub struct MaterialSet {
    materials: Vec<Material>,
    /// Where each material was defined (empty for sets built in code).
    locs: Vec<FileLoc>,
    seed: i32,
}

impl MaterialSet {
    /// A set holding `materials`; mix materials must refer to indices
    /// inside it.
    pub fn new(materials: Vec<Material>) -> Self {
        debug_assert!(materials.iter().all(|m| match m {
            Material::Mix(x) => x.materials.iter().all(|&i| (i as usize) < materials.len()),
            _ => true,
        }));
        MaterialSet {
            materials,
            locs: Vec::new(),
            seed: 0,
        }
    }

    /// Records where each material was defined, for messages such as the
    /// integrator's refusal of subsurface materials.
    pub fn with_locs(mut self, locs: Vec<FileLoc>) -> Self {
        debug_assert_eq!(locs.len(), self.materials.len());
        self.locs = locs;
        self
    }

    /// Where material `index` was defined, when known.
    pub fn loc(&self, index: u32) -> Option<&FileLoc> {
        self.locs.get(index as usize)
    }

    /// The first material with subsurface scattering, with its location
    /// when known.
    pub fn first_subsurface(&self) -> Option<(u32, Option<&FileLoc>)> {
        let i = self
            .materials
            .iter()
            .position(Material::has_subsurface_scattering)?;
        Some((i as u32, self.loc(i as u32)))
    }

    /// The location of the first material whose surfaces scatter light
    /// (anything but `interface` and a constant black `diffuse`), for
    /// integrators that handle media alone, among those `used` accepts;
    /// `Some(None)` when it has no recorded location.
    pub fn first_scattering(&self, used: impl Fn(u32) -> bool) -> Option<Option<&FileLoc>> {
        use crate::texture::SpectrumTexture;
        let i = self.materials.iter().enumerate().position(|(i, m)| {
            used(i as u32)
                && match m {
                    Material::Interface => false,
                    Material::Diffuse(d) => !matches!(&*d.reflectance,
                SpectrumTexture::Constant(s) if s.max_value() == 0.0),
                    _ => true,
                }
        })?;
        Some(self.loc(i as u32))
    }

    /// Sets pbrt-v4's `--seed`, mixed into layered BxDFs' random walks.
    pub fn with_seed(mut self, seed: i32) -> Self {
        self.seed = seed;
        self
    }

    /// The number of materials.
    pub fn len(&self) -> usize {
        self.materials.len()
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.materials.is_empty()
    }

    /// The material at `index`.
    pub fn get(&self, index: u32) -> Option<&Material> {
        self.materials.get(index as usize)
    }

    /// All materials in index order.
    pub fn materials(&self) -> &[Material] {
        &self.materials
    }

    /// Follows mix materials from `material` to the one used at this
    /// point (pbrt-v4 `MixMaterial::ChooseMaterial`, deterministic in the
    /// point and ωo). Chains longer than [`MIX_MAX_DEPTH`] (impossible for
    /// sets built by [`create_materials`]) and unknown indices give `None`.
    pub fn resolve(&self, material: u32, si: &SurfaceInteraction) -> Option<(u32, &Material)> {
        let mut index = material;
        for _ in 0..=MIX_MAX_DEPTH {
            let m = self.materials.get(index as usize)?;
            match m {
                Material::Mix(mix) => {
                    let ctx = TextureEvalContext::from_si(si);
                    index = mix.choose_material(&ctx, si.wo);
                }
                _ => return Some((index, m)),
            }
        }
        debug_assert!(false, "mix material chain longer than {MIX_MAX_DEPTH}");
        None
    }

    /// True when the material at `material` (after resolving mixes at this
    /// point) has a BSSRDF.
    pub fn has_subsurface(&self, material: u32, si: &SurfaceInteraction) -> bool {
        self.resolve(material, si)
            .is_some_and(|(_, m)| m.has_subsurface_scattering())
    }

    /// The reflectance of material `material` when it is a plain
    /// `diffuse` material (no mix, no bump or normal map) of constant
    /// reflectance: its BSDF at any point is a [`DiffuseBxDF`] of that
    /// spectrum clamped to [0, 1], in the hit's shading frame (the
    /// wavefront's lane-parallel diffuse vertex).
    #[inline]
    pub(crate) fn constant_diffuse(&self, material: u32) -> Option<&Spectrum> {
        match self.materials.get(material as usize) {
            Some(Material::Diffuse(m)) if !m.perturbation.is_some() => match &*m.reflectance {
                crate::texture::SpectrumTexture::Constant(s) => Some(s),
                _ => None,
            },
            _ => None,
        }
    }

    /// The plain `diffuse` material `material` (no mix, no normal or
    /// bump map) when its reflectance is a texture other than a constant:
    /// its reflectance varies over the surface but depends on nothing
    /// else of the hit than the texture lookup's context (the wavefront's
    /// lane-parallel diffuse vertex, textured).
    #[inline]
    pub(crate) fn textured_diffuse(&self, material: u32) -> Option<&DiffuseMaterial> {
        match self.materials.get(material as usize) {
            Some(Material::Diffuse(m))
                if !m.perturbation.is_some()
                    && !matches!(*m.reflectance, crate::texture::SpectrumTexture::Constant(_)) =>
            {
                Some(m)
            }
            _ => None,
        }
    }

    /// The BxDF of `material` when it is a plain `dielectric` (no mix, no
    /// normal or bump map) of constant index of refraction and constant
    /// roughness, and that BxDF is specular: the same at every point and
    /// wavelength, so it is built without the hit (the wavefront's
    /// lane-parallel specular vertex).
    pub(crate) fn constant_specular_dielectric(
        &self,
        material: u32,
        lambda: &SampledWavelengths,
    ) -> Option<crate::bxdf::DielectricBxDF> {
        use crate::texture::FloatTexture;
        let Some(Material::Dielectric(m)) = self.materials.get(material as usize) else {
            return None;
        };
        let constant = |t: &FloatTextureRef| matches!(**t, FloatTexture::Constant(_));
        if m.perturbation.is_some()
            || !matches!(m.eta, Spectrum::Constant(_))
            || !constant(&m.roughness.u)
            || !constant(&m.roughness.v)
        {
            return None;
        }
        // Nothing `get_bxdf` reads varies over the surface, and a constant
        // index of refraction leaves the wavelengths as they are.
        let mut lambda = *lambda;
        match m.get_bxdf(&MaterialEvalContext::default(), &mut lambda) {
            BxDF::Dielectric(d) if !crate::bxdf::BxDFMethods::flags(&d).is_non_specular() => {
                Some(d)
            }
            _ => None,
        }
    }

    /// True when `material` is a plain `conductor`, `dielectric`,
    /// `coateddiffuse` or `coatedconductor` (no mix, no bump or normal
    /// map) whose textures are all constants: its BxDF is the same at
    /// every point ([`MaterialSet::constant_bxdf`]), and the wavefront's
    /// BSDF stage answers its queries (the wavefront's staged vertex).
    #[inline]
    pub(crate) fn is_constant_staged(&self, material: u32) -> bool {
        matches!(
            self.materials.get(material as usize),
            Some(
                Material::Conductor(_)
                    | Material::Dielectric(_)
                    | Material::CoatedDiffuse(_)
                    | Material::CoatedConductor(_)
            )
        ) && !self.needs_differentials(material)
    }

    /// The BxDF of a material that [`MaterialSet::is_constant_staged`]
    /// accepts, as [`MaterialSet::get_bsdf`] builds it at any hit
    /// (nothing it reads varies over the surface); it may terminate the
    /// secondary wavelengths of `lambda`, as there.
    pub(crate) fn constant_bxdf(
        &self,
        material: u32,
        lambda: &mut SampledWavelengths,
    ) -> Option<BxDF> {
        debug_assert!(self.is_constant_staged(material));
        self.materials.get(material as usize)?.get_bxdf(
            &MaterialEvalContext::default(),
            lambda,
            self.seed,
        )
    }

    /// True when shading material `material` may read the hit's
    /// screen-space differentials: a texture that filters over its
    /// footprint, or bump or normal mapping. Only materials proven to read
    /// constant textures alone answer false (the rest conservatively
    /// true), so skipping the differentials for them cannot change a BSDF.
    pub fn needs_differentials(&self, material: u32) -> bool {
        use crate::texture::{FloatTexture, SpectrumTexture};
        let fc = |t: &FloatTextureRef| matches!(**t, FloatTexture::Constant(_));
        let sc = |t: &SpectrumTextureRef| matches!(**t, SpectrumTexture::Constant(_));
        let rough = |r: &Roughness| fc(&r.u) && fc(&r.v);
        let layer = |l: &coated::LayerSettings| fc(&l.thickness) && sc(&l.albedo) && fc(&l.g);
        let conductor = |c: &conductor::ConductorSpectra| match c {
            conductor::ConductorSpectra::EtaK { eta, k } => sc(eta) && sc(k),
            conductor::ConductorSpectra::Reflectance(r) => sc(r),
        };
        // Materials whose textures are all constants and that perturb no
        // normals read no differentials: their BSDFs are the same without.
        let constant = match self.materials.get(material as usize) {
            Some(Material::Diffuse(m)) => sc(&m.reflectance) && !m.perturbation.is_some(),
            Some(Material::DiffuseTransmission(m)) => {
                sc(&m.reflectance) && sc(&m.transmittance) && !m.perturbation.is_some()
            }
            Some(Material::Conductor(m)) => {
                conductor(&m.spectra) && rough(&m.roughness) && !m.perturbation.is_some()
            }
            Some(Material::Dielectric(m)) => rough(&m.roughness) && !m.perturbation.is_some(),
            Some(Material::ThinDielectric(m)) => !m.perturbation.is_some(),
            Some(Material::CoatedDiffuse(m)) => {
                sc(&m.reflectance)
                    && rough(&m.roughness)
                    && layer(&m.layer)
                    && !m.perturbation.is_some()
            }
            Some(Material::CoatedConductor(m)) => {
                rough(&m.interface_roughness)
                    && conductor(&m.conductor)
                    && rough(&m.conductor_roughness)
                    && layer(&m.layer)
                    && !m.perturbation.is_some()
            }
            Some(Material::Interface) => true,
            _ => false,
        };
        !constant
    }

    /// True when some material of the set may read hits' screen-space
    /// differentials (see [`MaterialSet::needs_differentials`]).
    pub fn any_needs_differentials(&self) -> bool {
        (0..self.materials.len()).any(|i| self.needs_differentials(i as u32))
    }

    /// True when any material of the set can have a BSSRDF.
    pub fn any_subsurface(&self) -> bool {
        self.materials
            .iter()
            .any(Material::has_subsurface_scattering)
    }

    /// pbrt-v4's `SurfaceInteraction::GetBSDF` after the differentials
    /// (which the caller computes first): resolves mixes, returns `None`
    /// for interfaces (the ray passes through), applies normal or bump
    /// mapping to `si`'s shading geometry and builds the BSDF. Dispersive
    /// materials may terminate the secondary wavelengths of `lambda`.
    ///
    /// For pbrt-v4's `--force-diffuse`, pass the result through
    /// [`MaterialSet::force_diffuse`] with the sampler's next 1-D and 2-D
    /// values, which pbrt-v4 draws only when there is a BSDF.
    pub fn get_bsdf(
        &self,
        material: u32,
        si: &mut SurfaceInteraction,
        lambda: &mut SampledWavelengths,
    ) -> Option<BSDF> {
        let (_, m) = self.resolve(material, si)?;
        if m.is_interface() {
            return None;
        }
        if let Some(p) = m.perturbation() {
            p.apply(si);
        }
        let ctx = MaterialEvalContext::from_si(si);
        let bxdf = m.get_bxdf(&ctx, lambda, self.seed)?;
        Some(BSDF::new(ctx.ns, ctx.dpdus, bxdf))
    }

    /// The BSSRDF of the material at `material` (after resolving mixes at
    /// this point), for a hit whose shading geometry `get_bsdf` has already
    /// perturbed (pbrt-v4 `SurfaceInteraction::GetBSSRDF`); `None` for
    /// materials without subsurface scattering.
    pub fn get_bssrdf(
        &self,
        material: u32,
        si: &SurfaceInteraction,
        lambda: &SampledWavelengths,
    ) -> Option<Bssrdf<'static>> {
        let ctx = MaterialEvalContext::from_si(si);
        match self.resolve(material, si)? {
            (_, Material::Subsurface(m)) => Some(Bssrdf::Tabulated(m.get_bssrdf(&ctx, lambda))),
            (_, Material::Disney(m)) => m.get_bssrdf(&ctx, lambda).map(Bssrdf::Disney),
            _ => None,
        }
    }

    /// True when some material of the set is an `interface`.
    pub fn any_interface(&self) -> bool {
        self.materials.iter().any(Material::is_interface)
    }

    /// pbrt-v4's `--force-diffuse`: a Lambertian BSDF whose reflectance is
    /// a one-sample estimate of `bsdf`'s directional albedo ρ(ωo) (with
    /// sample values `uc`, `u`), in `si`'s shading frame.
    pub fn force_diffuse(bsdf: &BSDF, si: &SurfaceInteraction, uc: Float, u: Point2f) -> BSDF {
        let r = bsdf.rho_hd(si.wo, &[uc], &[u]);
        BSDF::new(
            si.shading.n,
            si.shading.dpdu,
            BxDF::Diffuse(DiffuseBxDF::new(r)),
        )
    }
}
