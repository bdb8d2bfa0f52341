//! Stochastic mixing of two materials (pbrt-v4 book section 10.5; pbrt-v4
//! `MixMaterial`).

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;

use crate::sampler::lowdiscrepancy::murmur_hash64a;
use crate::texture::{FloatTextureRef, TextureEvalContext};

/// `mix`: at each point one of two materials is used, the second with
/// probability `amount`. The choice is a deterministic hash of the point and
/// ωo, so a point seen along the same direction always gets the same
/// material.
#[derive(Clone, Debug)]
pub struct MixMaterial {
    /// Indices (in the [`MaterialSet`](super::MaterialSet)) of the two
    /// materials.
    pub materials: [u32; 2],
    /// Probability of choosing the second material.
    pub amount: FloatTextureRef,
}

impl MixMaterial {
    /// The index of the material used at this point (pbrt-v4
    /// `ChooseMaterial`).
    pub fn choose_material(&self, ctx: &TextureEvalContext, wo: Vector3f) -> u32 {
        let amt = self.amount.evaluate(ctx);
        if amt <= 0.0 {
            return self.materials[0];
        }
        if amt >= 1.0 {
            return self.materials[1];
        }
        let u = mix_hash_u(ctx.p, wo);
        if amt < u {
            self.materials[0]
        } else {
            self.materials[1]
        }
    }
}

/// A uniform value in [0, 1) from the point and direction: pbrt-v4's
/// `Hash(p, wo)` (MurmurHash64A of the six packed floats), low 32 bits.
pub(crate) fn mix_hash_u(p: Point3f, wo: Vector3f) -> Float {
    let mut buf = [0u8; 24];
    for (i, v) in [p.x, p.y, p.z, wo.x, wo.y, wo.z].iter().enumerate() {
        buf[4 * i..4 * i + 4].copy_from_slice(&v.to_le_bytes());
    }
    let h = murmur_hash64a(&buf, 0) as u32;
    (h as f64 * (1.0 / 4_294_967_296.0)) as Float
}
