//! Accelerator parameters, read from pbrt-style `Accelerator` directive
//! values (pbrt-v4 `BVHAggregate::Create`, `KdTreeAggregate::Create`).

use rpbrt_geometry::Float;

/// One parameter value as the scene code hands it over.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamValue<'a> {
    /// An `integer` parameter.
    Int(i32),
    /// A `float` parameter.
    Float(Float),
    /// A `string` parameter.
    Str(&'a str),
}

/// Which structure to build.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum AccelKind {
    /// `"bvh"` (the default): 8-, 4-wide or binary, see [`BvhParams::width`].
    #[default]
    Bvh,
    /// `"kdtree"`.
    KdTree,
    /// `"grid"` (pbrt-v1/v2's uniform grid).
    Grid,
    /// `"embree"`: Embree 3's BVH (cargo feature `embree`; without it the
    /// scene warns and uses the BVH). It takes no parameters.
    #[cfg(feature = "embree")]
    Embree,
}

/// How the BVH chooses its splits (pbrt-v4 `SplitMethod`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SplitMethod {
    /// Binned surface area heuristic, 12 buckets (`"sah"`, the default).
    Sah,
    /// Linear BVH on Morton codes with SAH over the treelets (`"hlbvh"`).
    Hlbvh,
    /// Split at the centroid bounds' midpoint (`"middle"`).
    Middle,
    /// Split into halves by centroid order (`"equal"`).
    EqualCounts,
}

/// BVH parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhParams {
    /// Split method.
    pub split_method: SplitMethod,
    /// Most primitives in a leaf the SAH may choose (`"maxnodeprims"`,
    /// default 4, at most 255 as in pbrt-v4). Middle and equal-count splits
    /// also stop at this many primitives (pbrt splits them down to one).
    pub max_prims_in_node: u32,
    /// Children per node (`"width"`, an rpbrt extension): 8 collapses the
    /// SAH tree into 8-wide nodes tested together ([`Bvh8`](super::Bvh8):
    /// one AVX2 instruction per step, or two SSE ones), 4 into 4-wide ones
    /// ([`Bvh4`](super::Bvh4)), 2 keeps pbrt-v4's binary layout
    /// ([`Bvh`](super::Bvh)). All give identical hits (but for exact ties
    /// in distance). 0 (the default) chooses by size
    /// ([`BvhParams::width_for`]).
    pub width: u32,
}

impl Default for BvhParams {
    fn default() -> Self {
        BvhParams {
            split_method: SplitMethod::Sah,
            max_prims_in_node: 4,
            width: 0,
        }
    }
}

/// Above this many entries the default BVH is 4-wide
/// ([`BvhParams::width_for`]).
pub const LARGE_BVH_ENTRIES: usize = 1 << 22;

impl BvhParams {
    /// The width to build over `n` entries: the one the file gave, else 8
    /// (the fastest in the accel bench on every mesh, at AVX2 and at
    /// SSE4.1; the README gives the figures), or 4 above
    /// [`LARGE_BVH_ENTRIES`]: the 8-wide tree's nodes are less full, and
    /// over the 10-million-triangle scale bench it took 662 MB against the
    /// 4-wide tree's 516 MB (peak 942 against 859 MiB), where memory counts
    /// more than its 5–15% more rays per second.
    pub fn width_for(&self, n: usize) -> u32 {
        match self.width {
            0 if n > LARGE_BVH_ENTRIES => 4,
            0 => 8,
            w => w,
        }
    }
}

/// kd-tree parameters (pbrt-v3 `KdTreeAccel`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KdTreeParams {
    /// Cost of one primitive intersection test (`"intersectcost"`, 5).
    pub isect_cost: Float,
    /// Cost of one interior-node traversal step (`"traversalcost"`, 1).
    pub traversal_cost: Float,
    /// Cost discount for a split with an empty side, in [0, 1]
    /// (`"emptybonus"`, 0.5).
    pub empty_bonus: Float,
    /// Primitives below which a node is always a leaf (`"maxprims"`, 1).
    pub max_prims: u32,
    /// Maximum depth (`"maxdepth"`); `None` (-1) means
    /// `round(8 + 1.3 log2 N)`. Capped at 64, the traversal stack size.
    pub max_depth: Option<u32>,
}

impl Default for KdTreeParams {
    fn default() -> Self {
        KdTreeParams {
            isect_cost: 5.0,
            traversal_cost: 1.0,
            empty_bonus: 0.5,
            max_prims: 1,
            max_depth: None,
        }
    }
}

/// Uniform grid parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridParams {
    /// Most voxels along one axis (`"maxvoxels"`, 64 as in pbrt-v2; at most
    /// 256, which keeps the voxel table under 64 MiB).
    pub max_voxels_per_axis: u32,
}

impl Default for GridParams {
    fn default() -> Self {
        GridParams {
            max_voxels_per_axis: 64,
        }
    }
}

/// Everything needed to build an [`Accelerator`](super::Accelerator).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct AccelParams {
    /// The structure to build.
    pub kind: AccelKind,
    /// Used when `kind` is a BVH.
    pub bvh: BvhParams,
    /// Used when `kind` is kd-tree.
    pub kdtree: KdTreeParams,
    /// Used when `kind` is grid.
    pub grid: GridParams,
}

fn int_of(key: &str, v: ParamValue) -> Result<i32, String> {
    match v {
        ParamValue::Int(i) => Ok(i),
        _ => Err(format!("\"{key}\": expected an integer value, got {v:?}")),
    }
}

fn float_of(key: &str, v: ParamValue) -> Result<Float, String> {
    let f = match v {
        ParamValue::Float(f) => f,
        ParamValue::Int(i) => i as Float,
        ParamValue::Str(_) => return Err(format!("\"{key}\": expected a number, got {v:?}")),
    };
    if f.is_finite() {
        Ok(f)
    } else {
        Err(format!("\"{key}\": value {f} is not a finite number"))
    }
}

/// Why [`AccelParams::new`] refuses `"embree"` in a build without the cargo
/// feature `embree`.
#[cfg(not(feature = "embree"))]
pub const NO_EMBREE: &str = "this build has no Embree";

impl AccelParams {
    /// The accelerator names a scene may ask for. `"embree"` is among them
    /// in every build: [`AccelParams::new`] refuses it without the cargo
    /// feature `embree`, and the scene then warns and uses `"bvh"`.
    pub const NAMES: &'static [&'static str] = &["bvh", "embree", "grid", "kdtree"];

    /// Defaults for the accelerator named `name` (`"bvh"`, `"kdtree"` or
    /// `"grid"`).
    pub fn new(name: &str) -> Result<AccelParams, String> {
        let kind = match name {
            "bvh" => AccelKind::Bvh,
            "kdtree" => AccelKind::KdTree,
            "grid" => AccelKind::Grid,
            #[cfg(feature = "embree")]
            "embree" => AccelKind::Embree,
            #[cfg(not(feature = "embree"))]
            "embree" => return Err(NO_EMBREE.to_string()),
            _ => {
                return Err(format!(
                    "\"{name}\": unknown accelerator (expected \"bvh\", \"kdtree\", \"grid\" or \"embree\")"
                ))
            }
        };
        Ok(AccelParams {
            kind,
            ..Default::default()
        })
    }

    /// Parameters for `name` with the given `(key, value)` pairs applied.
    pub fn parse<'a>(
        name: &str,
        values: impl IntoIterator<Item = (&'a str, ParamValue<'a>)>,
    ) -> Result<AccelParams, String> {
        let mut p = AccelParams::new(name)?;
        for (k, v) in values {
            p.set(k, v)?;
        }
        Ok(p)
    }

    /// Sets one parameter of the selected structure. Unknown names and
    /// out-of-range values are errors (the caller may downgrade the former
    /// to an "unused parameter" warning).
    pub fn set(&mut self, key: &str, value: ParamValue) -> Result<(), String> {
        match (self.kind, key) {
            (AccelKind::Bvh, "splitmethod") => {
                let ParamValue::Str(s) = value else {
                    return Err(format!("\"splitmethod\": expected a string, got {value:?}"));
                };
                self.bvh.split_method = match s {
                    "sah" => SplitMethod::Sah,
                    "hlbvh" => SplitMethod::Hlbvh,
                    "middle" => SplitMethod::Middle,
                    "equal" => SplitMethod::EqualCounts,
                    _ => {
                        return Err(format!(
                            "\"{s}\": unknown BVH split method (expected \"sah\", \"hlbvh\", \
                             \"middle\" or \"equal\")"
                        ))
                    }
                };
            }
            (AccelKind::Bvh, "maxnodeprims") => {
                let n = int_of(key, value)?;
                if n < 1 {
                    return Err(format!("\"maxnodeprims\": {n} must be at least 1"));
                }
                // pbrt-v4 clamps to 255 as well.
                self.bvh.max_prims_in_node = (n as u32).min(255);
            }
            (AccelKind::Bvh, "width") => {
                let n = int_of(key, value)?;
                if n != 2 && n != 4 && n != 8 {
                    return Err(format!("\"width\": {n} must be 2, 4 or 8"));
                }
                self.bvh.width = n as u32;
            }
            (AccelKind::KdTree, "intersectcost" | "traversalcost") => {
                let c = float_of(key, value)?;
                if c < 0.0 {
                    return Err(format!("\"{key}\": {c} must not be negative"));
                }
                if key == "intersectcost" {
                    self.kdtree.isect_cost = c;
                } else {
                    self.kdtree.traversal_cost = c;
                }
            }
            (AccelKind::KdTree, "emptybonus") => {
                let b = float_of(key, value)?;
                if !(0.0..=1.0).contains(&b) {
                    return Err(format!("\"emptybonus\": {b} must be in [0, 1]"));
                }
                self.kdtree.empty_bonus = b;
            }
            (AccelKind::KdTree, "maxprims") => {
                let n = int_of(key, value)?;
                if n < 1 {
                    return Err(format!("\"maxprims\": {n} must be at least 1"));
                }
                self.kdtree.max_prims = n as u32;
            }
            (AccelKind::KdTree, "maxdepth") => {
                let n = int_of(key, value)?;
                self.kdtree.max_depth = match n {
                    -1 => None,
                    0..=64 => Some(n as u32),
                    _ => {
                        return Err(format!(
                            "\"maxdepth\": {n} must be -1 (automatic) or in 0..=64"
                        ))
                    }
                };
            }
            (AccelKind::Grid, "maxvoxels") => {
                let n = int_of(key, value)?;
                if !(1..=256).contains(&n) {
                    return Err(format!("\"maxvoxels\": {n} must be in 1..=256"));
                }
                self.grid.max_voxels_per_axis = n as u32;
            }
            _ => {
                return Err(format!(
                    "\"{key}\": not a parameter of the {:?} accelerator",
                    self.kind
                ))
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_defaults_and_values() {
        let p = AccelParams::new("bvh").unwrap();
        assert_eq!(p.bvh.max_prims_in_node, 4);
        assert_eq!(p.bvh.split_method, SplitMethod::Sah);
        assert_eq!(p.bvh.width, 0);
        assert_eq!(p.bvh.width_for(1000), 8);
        assert_eq!(p.bvh.width_for(LARGE_BVH_ENTRIES + 1), 4);
        let p = AccelParams::parse("bvh", [("width", ParamValue::Int(2))]).unwrap();
        assert_eq!(p.bvh.width, 2);
        let p = AccelParams::parse(
            "bvh",
            [
                ("splitmethod", ParamValue::Str("hlbvh")),
                ("maxnodeprims", ParamValue::Int(1000)),
            ],
        )
        .unwrap();
        assert_eq!(p.bvh.split_method, SplitMethod::Hlbvh);
        assert_eq!(p.bvh.max_prims_in_node, 255);
        let p = AccelParams::parse(
            "kdtree",
            [
                ("intersectcost", ParamValue::Int(80)),
                ("emptybonus", ParamValue::Float(0.25)),
                ("maxdepth", ParamValue::Int(20)),
            ],
        )
        .unwrap();
        assert_eq!(p.kind, AccelKind::KdTree);
        assert_eq!(p.kdtree.isect_cost, 80.0);
        assert_eq!(p.kdtree.empty_bonus, 0.25);
        assert_eq!(p.kdtree.max_depth, Some(20));
        assert_eq!(p.kdtree.traversal_cost, 1.0);
        assert_eq!(
            AccelParams::new("grid").unwrap().grid.max_voxels_per_axis,
            64
        );
    }

    #[test]
    fn parse_errors() {
        assert!(AccelParams::new("octree")
            .unwrap_err()
            .contains("unknown accelerator"));
        let bad =
            |name: &str, k: &str, v: ParamValue| AccelParams::parse(name, [(k, v)]).unwrap_err();
        assert!(bad("bvh", "splitmethod", ParamValue::Str("best")).contains("split method"));
        assert!(bad("bvh", "maxnodeprims", ParamValue::Int(-3)).contains("at least 1"));
        assert!(bad("bvh", "maxnodeprims", ParamValue::Float(2.0)).contains("integer"));
        assert!(bad("kdtree", "intersectcost", ParamValue::Float(Float::NAN)).contains("finite"));
        assert!(bad("kdtree", "traversalcost", ParamValue::Float(-1.0)).contains("negative"));
        assert!(bad("kdtree", "emptybonus", ParamValue::Float(1.5)).contains("[0, 1]"));
        assert!(bad("kdtree", "maxdepth", ParamValue::Int(-2)).contains("maxdepth"));
        assert!(bad("kdtree", "maxprims", ParamValue::Int(0)).contains("maxprims"));
        assert!(bad("grid", "maxvoxels", ParamValue::Int(0)).contains("maxvoxels"));
        assert!(bad("bvh", "width", ParamValue::Int(16)).contains("2, 4 or 8"));
        assert!(bad("bvh", "emptybonus", ParamValue::Float(0.5)).contains("not a parameter"));
    }
}
