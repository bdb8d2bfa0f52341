//! Connecting a light subpath to a camera subpath (pbrt-v4 `ConnectBDPT`,
//! `MISWeight` and `G` in `cpu/integrators.cpp`): the contribution of one
//! (s, t) strategy and its multiple-importance weight against every other
//! strategy that could have made the same path.

use super::vertex::{Vertex, VertexKind};
use crate::bxdf::TransportMode;
use crate::integrator::volume::{shadow_transmittance, ShadowTransmittance};
use crate::integrator::Scene;
use crate::light::LightSampleContext;
use crate::sampler::SampleSource;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::tuple::*;

/// The transmittance between two vertices: zero when a surface blocks
/// the segment, attenuated by media and passing `interface` surfaces
/// (pbrt-v4 `Integrator::Tr`, ratio tracking).
pub(crate) fn transmittance(
    scene: &Scene,
    from: &Vertex,
    to: &Vertex,
    lambda: &SampledWavelengths,
) -> SampledSpectrum {
    let ray = from.spawn_ray_to(to);
    if ray.d == Vector3f::default() {
        return SampledSpectrum::new(1.0);
    }
    match shadow_transmittance(scene, ray, to.pi, to.n, lambda) {
        Some(ShadowTransmittance { t_ray, r_l, .. }) => {
            let w = r_l.average();
            if w > 0.0 {
                t_ray / w
            } else {
                SampledSpectrum::new(0.0)
            }
        }
        None => SampledSpectrum::new(0.0),
    }
}

/// The geometric term between two vertices, times their transmittance
/// (pbrt-v4 `G`).
fn g(scene: &Scene, v0: &Vertex, v1: &Vertex, lambda: &SampledWavelengths) -> SampledSpectrum {
    let d = v0.p() - v1.p();
    let mut g = 1.0 / d.length_squared();
    let d = d * g.sqrt();
    if v0.is_on_surface() {
        g *= abs_dot(Vector3f::from(v0.ns), d);
    }
    if v1.is_on_surface() {
        g *= abs_dot(Vector3f::from(v1.ns), d);
    }
    if g == 0.0 || !g.is_finite() {
        return SampledSpectrum::new(0.0);
    }
    transmittance(scene, v0, v1, lambda) * g
}

/// A strategy's contribution, its MIS weight and, for t = 1, where it
/// lands on the film.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Connection {
    /// The weighted contribution.
    pub l: SampledSpectrum,
    /// The MIS weight already applied to `l`.
    pub mis_weight: Float,
    /// The raster position of a t = 1 connection.
    pub p_raster: Option<Point2f>,
}

/// The (s, t) strategy: `s` vertices of the light subpath `light` and `t`
/// of the camera subpath `camera`, joined (pbrt-v4 `ConnectBDPT`).
pub(crate) fn connect_bdpt<S: SampleSource>(
    scene: &Scene,
    lambda: &SampledWavelengths,
    light: &[Vertex],
    camera: &[Vertex],
    s: usize,
    t: usize,
    sampler: &mut S,
) -> Connection {
    let zero = SampledSpectrum::new(0.0);
    let mut out = Connection {
        l: zero,
        mis_weight: 0.0,
        p_raster: None,
    };
    // Paths that escaped to infinity cannot be connected further.
    if t > 1 && s != 0 && camera[t - 1].kind == VertexKind::Light {
        return out;
    }
    let mut l = zero;
    let mut sampled: Option<Vertex> = None;
    if s == 0 {
        // The camera subpath alone, ending on an emitter.
        let pt = &camera[t - 1];
        if pt.is_light() {
            l = pt.le(scene, &camera[t - 2], lambda) * pt.beta;
        }
    } else if t == 1 {
        // A point on the lens, connected to the light subpath.
        let qs = &light[s - 1];
        if qs.is_connectible(scene) {
            let u = sampler.get_2d();
            if let Some(cs) = scene.camera.sample_wi(qs.p(), qs.time, u, lambda) {
                out.p_raster = Some(cs.p_raster);
                let mut v = Vertex::new(
                    VertexKind::Camera,
                    Point3fi::from(cs.p_lens),
                    qs.time,
                    cs.wi_importance / cs.pdf,
                );
                v.n = cs.n_lens;
                v.ns = cs.n_lens;
                v.medium = scene.camera.base().medium;
                l = qs.beta * qs.f(&v, TransportMode::Importance) * v.beta;
                if qs.is_on_surface() {
                    l *= abs_dot(cs.wi, Vector3f::from(qs.ns));
                }
                if !l.is_black() {
                    l *= transmittance(scene, qs, &v, lambda);
                }
                sampled = Some(v);
            }
        }
    } else if s == 1 {
        // A point on a light, connected to the camera subpath.
        let pt = &camera[t - 1];
        if pt.is_connectible(scene) {
            if let Some(chosen) = scene.light_sampler.sample_no_ctx(sampler.get_1d()) {
                let light_pdf = chosen.p;
                let mut ctx = LightSampleContext {
                    pi: pt.pi,
                    n: pt.n,
                    ns: pt.ns,
                };
                if let (VertexKind::Surface, Some(bsdf)) = (pt.kind, &pt.bsdf) {
                    // Nudge the point to the side light can arrive from.
                    let flags = bsdf.flags();
                    if flags.is_reflective() && !flags.is_transmissive() {
                        ctx.pi = Point3fi::from(pt.spawn_ray(pt.wo).o);
                    } else if flags.is_transmissive() && !flags.is_reflective() {
                        ctx.pi = Point3fi::from(pt.spawn_ray(-pt.wo).o);
                    }
                }
                let lt = &scene.lights[chosen.light as usize];
                let u = sampler.get_2d();
                if let Some(ls) = lt.sample_li(&ctx, u, lambda, false) {
                    if !ls.l.is_black() && ls.pdf > 0.0 {
                        let mut v = Vertex::new(
                            VertexKind::Light,
                            ls.p_light,
                            pt.time,
                            ls.l / (ls.pdf * light_pdf),
                        );
                        v.n = ls.n_light;
                        v.ns = ls.n_light;
                        v.light = Some(chosen.light);
                        v.medium = lt.medium();
                        v.pdf_fwd = v.pdf_light_origin(scene, pt);
                        l = pt.beta * pt.f(&v, TransportMode::Radiance) * v.beta;
                        if pt.is_on_surface() {
                            l *= abs_dot(ls.wi, Vector3f::from(pt.ns));
                        }
                        if !l.is_black() {
                            l *= transmittance(scene, pt, &v, lambda);
                        }
                        sampled = Some(v);
                    }
                }
            }
        }
    } else {
        // Both subpaths, joined by a deterministic edge.
        let qs = &light[s - 1];
        let pt = &camera[t - 1];
        if qs.is_connectible(scene) && pt.is_connectible(scene) {
            // The second BSDF only when the first passes light (layered
            // BSDFs are costly; each is seeded by its own directions, so
            // skipping one changes nothing else).
            let fq = qs.beta * qs.f(pt, TransportMode::Importance);
            if !fq.is_black() {
                l = fq * pt.f(qs, TransportMode::Radiance) * pt.beta;
            }
            if !l.is_black() {
                l *= g(scene, qs, pt, lambda);
            }
        }
    }
    if l.is_black() {
        return out;
    }
    let w = mis_weight(scene, light, camera, sampled.as_ref(), s, t);
    out.l = l * w;
    out.mis_weight = w;
    out
}

/// The balance-heuristic weight of the (s, t) strategy among all
/// strategies that make a path of the same length (pbrt-v4 `MISWeight`).
/// `sampled` is the vertex a t = 1 or s = 1 strategy sampled in place of
/// the subpath's own endpoint. The subpaths are not modified: the
/// densities the strategy changes are computed aside.
pub(crate) fn mis_weight(
    scene: &Scene,
    light: &[Vertex],
    camera: &[Vertex],
    sampled: Option<&Vertex>,
    s: usize,
    t: usize,
) -> Float {
    if s + t == 2 {
        return 1.0;
    }
    let remap0 = |f: Float| if f != 0.0 { f } else { 1.0 };
    // The connection vertices and their predecessors, with the sampled
    // vertex standing in for the endpoint it replaces.
    let qs: Option<&Vertex> = match s {
        0 => None,
        1 => sampled.or(Some(&light[0])),
        _ => Some(&light[s - 1]),
    };
    let pt: Option<&Vertex> = match t {
        0 => None,
        1 => sampled.filter(|_| s != 1).or(Some(&camera[0])),
        _ => Some(&camera[t - 1]),
    };
    let qs_minus = if s > 1 { Some(&light[s - 2]) } else { None };
    let pt_minus = if t > 1 { Some(&camera[t - 2]) } else { None };
    // The reverse densities of the four vertices around the connection.
    let pt_rev = pt.map(|pt| match qs {
        Some(qs) => qs.pdf(scene, qs_minus, pt),
        None => pt_minus.map_or(0.0, |pm| pt.pdf_light_origin(scene, pm)),
    });
    let pt_minus_rev = match (pt, pt_minus) {
        (Some(pt), Some(pm)) => Some(match qs {
            Some(qs) => pt.pdf(scene, Some(qs), pm),
            None => pt.pdf_light(scene, pm),
        }),
        _ => None,
    };
    let qs_rev = match (qs, pt) {
        (Some(qs), Some(pt)) => Some(pt.pdf(scene, pt_minus, qs)),
        _ => None,
    };
    let qs_minus_rev = match (qs_minus, qs) {
        (Some(qm), Some(qs)) => Some(qs.pdf(scene, pt, qm)),
        _ => None,
    };
    // The camera subpath's vertex i as this strategy sees it.
    let cam = |i: usize| -> (Float, Float, bool) {
        let v = if i == t - 1 {
            pt.unwrap_or(&camera[i])
        } else {
            &camera[i]
        };
        let rev = if i + 1 == t {
            pt_rev.unwrap_or(v.pdf_rev)
        } else if i + 2 == t {
            pt_minus_rev.unwrap_or(v.pdf_rev)
        } else {
            v.pdf_rev
        };
        // Connection vertices count as non-degenerate.
        let delta = if i + 1 == t { false } else { v.delta };
        (rev, v.pdf_fwd, delta)
    };
    let lgt = |i: usize| -> (Float, Float, bool) {
        let v = if i + 1 == s {
            qs.unwrap_or(&light[i])
        } else {
            &light[i]
        };
        let rev = if i + 1 == s {
            qs_rev.unwrap_or(v.pdf_rev)
        } else if i + 2 == s {
            qs_minus_rev.unwrap_or(v.pdf_rev)
        } else {
            v.pdf_rev
        };
        let delta = if i + 1 == s { false } else { v.delta };
        (rev, v.pdf_fwd, delta)
    };
    let mut sum_ri = 0.0;
    let mut ri = 1.0;
    for i in (1..t).rev() {
        let (rev, fwd, delta) = cam(i);
        ri *= remap0(rev) / remap0(fwd);
        if !delta && !cam(i - 1).2 {
            sum_ri += ri;
        }
    }
    ri = 1.0;
    for i in (0..s).rev() {
        let (rev, fwd, delta) = lgt(i);
        ri *= remap0(rev) / remap0(fwd);
        let delta_light_vertex = if i > 0 {
            lgt(i - 1).2
        } else {
            qs.filter(|_| s == 1)
                .unwrap_or(&light[0])
                .is_delta_light(scene)
        };
        if !delta && !delta_light_vertex {
            sum_ri += ri;
        }
    }
    1.0 / (1.0 + sum_ri)
}
