//! Texture coordinate generation (book section 10.2; pbrt-v4 `textures.h`:
//! `UVMapping`, `SphericalMapping`, `CylindricalMapping`, `PlanarMapping`,
//! `PointTransformMapping`, `TextureMapping2D::Create`).
//!
//! Each mapping also returns the screen-space derivatives of its
//! coordinates, which the texture filters use as the footprint.

use super::TextureEvalContext;
use crate::params::ParamReader;
use rpbrt_geometry::float::{Float, INV_2PI, INV_PI, PI};
use rpbrt_geometry::spherical::{spherical_phi, spherical_theta};
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::*;
use rpbrt_parser::Diagnostic;

/// 2-D texture coordinates and their derivatives per pixel (pbrt-v4
/// `TexCoord2D`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TexCoord2D {
    /// The (s, t) coordinates.
    pub st: Point2f,
    /// ∂s/∂x.
    pub dsdx: Float,
    /// ∂s/∂y.
    pub dsdy: Float,
    /// ∂t/∂x.
    pub dtdx: Float,
    /// ∂t/∂y.
    pub dtdy: Float,
}

/// 3-D texture coordinates and their derivatives per pixel (pbrt-v4
/// `TexCoord3D`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TexCoord3D {
    /// The point in texture space.
    pub p: Point3f,
    /// ∂p/∂x.
    pub dpdx: Vector3f,
    /// ∂p/∂y.
    pub dpdy: Vector3f,
}

/// How a surface point gets (s, t) coordinates.
#[derive(Clone, Debug, PartialEq)]
pub enum TextureMapping2D {
    /// Scaled and offset surface (u, v).
    UV {
        /// Scale of u.
        su: Float,
        /// Scale of v.
        sv: Float,
        /// Offset added to s.
        du: Float,
        /// Offset added to t.
        dv: Float,
    },
    /// (θ/π, φ/2π) of the point about the texture-space origin.
    Spherical {
        /// From render space to texture space.
        texture_from_render: Transform,
    },
    /// ((π + atan2(y, x))/2π, z) in texture space.
    Cylindrical {
        /// From render space to texture space.
        texture_from_render: Transform,
    },
    /// Projections of the texture-space point on two vectors, plus offsets.
    Planar {
        /// From render space to texture space.
        texture_from_render: Transform,
        /// Direction giving s.
        vs: Vector3f,
        /// Direction giving t.
        vt: Vector3f,
        /// Offset added to s.
        ds: Float,
        /// Offset added to t.
        dt: Float,
    },
}

impl Default for TextureMapping2D {
    fn default() -> Self {
        TextureMapping2D::UV {
            su: 1.0,
            sv: 1.0,
            du: 0.0,
            dv: 0.0,
        }
    }
}

/// The mapping names `TextureMapping2D::create` knows.
pub const MAPPING_NAMES: &[&str] = &["uv", "spherical", "cylindrical", "planar"];

impl TextureMapping2D {
    /// Coordinates and their derivatives at a point.
    pub fn map(&self, ctx: &TextureEvalContext) -> TexCoord2D {
        match self {
            TextureMapping2D::UV { su, sv, du, dv } => TexCoord2D {
                st: Point2f::new(su * ctx.uv.x + du, sv * ctx.uv.y + dv),
                dsdx: su * ctx.dudx,
                dsdy: su * ctx.dudy,
                dtdx: sv * ctx.dvdx,
                dtdy: sv * ctx.dvdy,
            },
            TextureMapping2D::Spherical {
                texture_from_render,
            } => {
                let pt = texture_from_render.apply_point(ctx.p);
                let x2y2 = pt.x * pt.x + pt.y * pt.y;
                let r = x2y2.sqrt();
                // Gradients of θ/π (which is s) and φ/2π (which is t). pbrt-v4
                // pairs them the other way round (its "dsdp" is the φ
                // gradient), which makes the footprint disagree with the
                // coordinates; here each derivative belongs to its coordinate.
                let dsdp = Vector3f::new(pt.x * pt.z / r, pt.y * pt.z / r, -r)
                    * (1.0 / (PI * (x2y2 + pt.z * pt.z)));
                let dtdp = Vector3f::new(-pt.y, pt.x, 0.0) * (1.0 / (2.0 * PI * x2y2));
                let dpdx = texture_from_render.apply_vector(ctx.dpdx);
                let dpdy = texture_from_render.apply_vector(ctx.dpdy);
                let vec = Vector3f::from(pt).normalize();
                TexCoord2D {
                    st: Point2f::new(spherical_theta(vec) * INV_PI, spherical_phi(vec) * INV_2PI),
                    dsdx: dot(dsdp, dpdx),
                    dsdy: dot(dsdp, dpdy),
                    dtdx: dot(dtdp, dpdx),
                    dtdy: dot(dtdp, dpdy),
                }
            }
            TextureMapping2D::Cylindrical {
                texture_from_render,
            } => {
                let pt = texture_from_render.apply_point(ctx.p);
                let x2y2 = pt.x * pt.x + pt.y * pt.y;
                let dsdp = Vector3f::new(-pt.y, pt.x, 0.0) * (1.0 / (2.0 * PI * x2y2));
                let dtdp = Vector3f::new(0.0, 0.0, 1.0);
                let dpdx = texture_from_render.apply_vector(ctx.dpdx);
                let dpdy = texture_from_render.apply_vector(ctx.dpdy);
                TexCoord2D {
                    st: Point2f::new((PI + pt.y.atan2(pt.x)) * INV_2PI, pt.z),
                    dsdx: dot(dsdp, dpdx),
                    dsdy: dot(dsdp, dpdy),
                    dtdx: dot(dtdp, dpdx),
                    dtdy: dot(dtdp, dpdy),
                }
            }
            TextureMapping2D::Planar {
                texture_from_render,
                vs,
                vt,
                ds,
                dt,
            } => {
                let vec = Vector3f::from(texture_from_render.apply_point(ctx.p));
                let dpdx = texture_from_render.apply_vector(ctx.dpdx);
                let dpdy = texture_from_render.apply_vector(ctx.dpdy);
                TexCoord2D {
                    st: Point2f::new(ds + dot(vec, *vs), dt + dot(vec, *vt)),
                    dsdx: dot(*vs, dpdx),
                    dsdy: dot(*vs, dpdy),
                    dtdx: dot(*vt, dpdx),
                    dtdy: dot(*vt, dpdy),
                }
            }
        }
    }

    /// The mapping a texture's parameters describe: `mapping` ("uv",
    /// "spherical", "cylindrical", "planar"), `uscale`, `vscale`, `udelta`,
    /// `vdelta`, `v1`, `v2`, as pbrt-v4's `TextureMapping2D::Create`.
    pub fn create(
        params: &ParamReader,
        render_from_texture: &Transform,
    ) -> Result<TextureMapping2D, Diagnostic> {
        let kind = params.string("mapping", "uv")?;
        let texture_from_render = render_from_texture.inverse();
        Ok(match kind.as_str() {
            "uv" => TextureMapping2D::UV {
                su: params.float("uscale", 1.0)?,
                sv: params.float("vscale", 1.0)?,
                du: params.float("udelta", 0.0)?,
                dv: params.float("vdelta", 0.0)?,
            },
            "spherical" => TextureMapping2D::Spherical {
                texture_from_render,
            },
            "cylindrical" => TextureMapping2D::Cylindrical {
                texture_from_render,
            },
            "planar" => {
                let v1 = params.vector3("v1", [1.0, 0.0, 0.0])?;
                let v2 = params.vector3("v2", [0.0, 1.0, 0.0])?;
                TextureMapping2D::Planar {
                    texture_from_render,
                    vs: Vector3f::new(v1[0], v1[1], v1[2]),
                    vt: Vector3f::new(v2[0], v2[1], v2[2]),
                    ds: params.float("udelta", 0.0)?,
                    dt: params.float("vdelta", 0.0)?,
                }
            }
            other => {
                return Err(params.error_at(
                    "mapping",
                    format!(
                        "2D texture mapping \"{other}\" unknown (known: {})",
                        MAPPING_NAMES.join(", ")
                    ),
                ));
            }
        })
    }
}

/// How a surface point gets 3-D texture coordinates: the render-space point
/// carried into texture space (pbrt-v4 `PointTransformMapping`).
#[derive(Clone, Debug, PartialEq)]
pub struct TextureMapping3D {
    /// From render space to texture space.
    pub texture_from_render: Transform,
}

impl TextureMapping3D {
    /// The mapping of a texture placed by `render_from_texture`.
    pub fn new(render_from_texture: &Transform) -> Self {
        TextureMapping3D {
            texture_from_render: render_from_texture.inverse(),
        }
    }

    /// The texture-space point and its derivatives.
    #[inline]
    pub fn map(&self, ctx: &TextureEvalContext) -> TexCoord3D {
        TexCoord3D {
            p: self.texture_from_render.apply_point(ctx.p),
            dpdx: self.texture_from_render.apply_vector(ctx.dpdx),
            dpdy: self.texture_from_render.apply_vector(ctx.dpdy),
        }
    }
}
