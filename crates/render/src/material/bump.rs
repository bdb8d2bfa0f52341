//! Normal and bump mapping (pbrt-v4 book section 10.5.2 and 10.5.3; pbrt-v4
//! `materials.h`: `NormalMap`, `BumpMap`): perturbed shading derivatives
//! ∂p/∂u and ∂p/∂v from a tangent-space normal map or a displacement
//! texture.

use std::path::Path;

use rpbrt_parser::MemoryBudget;

use rpbrt_geometry::float::*;
use rpbrt_geometry::interaction::SurfaceInteraction;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::Frame;

use crate::image::{ColorEncoding, Image, WrapMode, WrapMode2D};
use crate::texture::{FloatTexture, TextureEvalContext};

/// The u (or v) step of the finite differences when the differentials are
/// zero (pbrt-v4's constant).
const FALLBACK_DELTA: Float = 0.0005;

/// Bump mapping: ∂p/∂u and ∂p/∂v of the surface displaced along the shading
/// normal by `displacement`, by forward differences over half the pixel
/// footprint in u and v.
pub fn bump_map(displacement: &FloatTexture, si: &SurfaceInteraction) -> (Vector3f, Vector3f) {
    let ctx = TextureEvalContext::from_si(si);
    let p = si.p();
    let sh = &si.shading;

    let mut du = 0.5 * (si.dudx.abs() + si.dudy.abs());
    if du == 0.0 {
        du = FALLBACK_DELTA;
    }
    let mut shifted = ctx;
    shifted.p = p + sh.dpdu * du;
    shifted.uv = Point2f::new(si.uv.x + du, si.uv.y);
    let u_displace = displacement.evaluate(&shifted);

    let mut dv = 0.5 * (si.dvdx.abs() + si.dvdy.abs());
    if dv == 0.0 {
        dv = FALLBACK_DELTA;
    }
    shifted.p = p + sh.dpdv * dv;
    shifted.uv = Point2f::new(si.uv.x, si.uv.y + dv);
    let v_displace = displacement.evaluate(&shifted);

    let displace = displacement.evaluate(&ctx);
    let n = Vector3f::from(sh.n);
    let dpdu = sh.dpdu + n * ((u_displace - displace) / du) + Vector3f::from(sh.dndu) * displace;
    let dpdv = sh.dpdv + n * ((v_displace - displace) / dv) + Vector3f::from(sh.dndv) * displace;
    (dpdu, dpdv)
}

/// Normal mapping: the tangent-space normal stored in `map` (RGB in [0, 1]
/// for components in [−1, 1], looked up bilinearly at (u, 1 − v) with
/// repeat wrapping) placed in the shading frame; ∂p/∂u is made
/// perpendicular to it and ∂p/∂v completes the frame, both keeping their
/// lengths.
pub fn normal_map(map: &Image, si: &SurfaceInteraction) -> (Vector3f, Vector3f) {
    let wrap = WrapMode2D::from(WrapMode::Repeat);
    let uv = Point2f::new(si.uv.x, 1.0 - si.uv.y);
    let c = |i| 2.0 * map.bilerp_channel(uv, i, wrap) - 1.0;
    let sh = &si.shading;
    let local = Vector3f::new(c(0), c(1), c(2));
    let Some(local) = local.try_normalize() else {
        return (sh.dpdu, sh.dpdv);
    };
    let Some(x) = sh.dpdu.try_normalize() else {
        return (sh.dpdu, sh.dpdv);
    };
    let ns = Frame::from_xz(x, Vector3f::from(sh.n)).from_local(local);
    let (ulen, vlen) = (sh.dpdu.length(), sh.dpdv.length());
    let dpdu = sh.dpdu.gram_schmidt(ns).try_normalize().unwrap_or(x) * ulen;
    let dpdv = cross(ns, dpdu).try_normalize().unwrap_or_default() * vlen;
    (dpdu, dpdv)
}

/// Reads a normal map as pbrt-v4 does: linear encoding, keeping the R, G
/// and B channels; the image is charged to `budget`.
pub fn read_normal_map(path: &Path, budget: &MemoryBudget) -> Result<Image, String> {
    let im =
        Image::read_within(path, Some(ColorEncoding::Linear), budget).map_err(|e| e.to_string())?;
    let Some(desc) = im.image.get_channel_desc(&["R", "G", "B"]) else {
        return Err(format!(
            "{}: normal map image must contain R, G and B channels (it has {})",
            path.display(),
            im.image.channel_names().join(", ")
        ));
    };
    Ok(im.image.select_channels(&desc))
}
