//! A NanoVDB float grid: decoding the grid buffer (`GridData`, `TreeData`, root tiles, upper,
//! lower and leaf nodes) into flat arrays, and the value lookups and trilinear sampling of
//! pbrt-v4's `NanoVDBMedium`.
//!
//! Node layout of a float tree (NanoVDB 32.x, every node 32-byte aligned, child offsets in
//! bytes relative to the parent node):
//! - root (`RootData`, 64 bytes): index bbox (2 × 3 i32), tile count, background, min, max,
//!   average, std. deviation; then the tiles, 32 bytes each: key (u64, the origin's three
//!   coordinates shifted right by 12, 21 bits each, x highest), child offset (i64, 0 for a
//!   value tile), active state (u32), value (f32);
//! - upper internal node (32³ entries, each child covers 128³ voxels, 270 400 bytes): bbox,
//!   flags, value mask (4096 bytes at 32), child mask (at 4128), min/max/avg/std (at 8224),
//!   table of 32 768 eight-byte entries at 8256 (child offset, or the tile value in the
//!   first four bytes);
//! - lower internal node (16³ entries, each child covers 8³ voxels, 33 856 bytes): masks of
//!   512 bytes at 32 and 544, table of 4096 entries at 1088;
//! - leaf (8³ voxels, 2144 bytes): origin, bbox size and flags (16 bytes), value mask (at 16),
//!   min/max/avg/std (at 80), 512 f32 values at 96, x-major (`x << 6 | y << 3 | z`).

use super::file::{
    c_string, is_supported_version, le_u32, le_u64, version_error, GRID_DATA_BYTES, MAGIC_GRID,
    MAGIC_NUMB,
};
use super::NanoVdbError;

/// `GridType::Float`.
pub(super) const GRID_TYPE_FLOAT: u32 = 1;

/// NanoVDB's name of a `GridType` number (as its `toStr` gives them).
pub(super) fn grid_type_name(t: u32) -> String {
    const NAMES: [&str; 27] = [
        "unknown",
        "float",
        "double",
        "int16",
        "int32",
        "int64",
        "Vec3f",
        "Vec3d",
        "Mask",
        "Half",
        "uint32",
        "bool",
        "RGBA8",
        "Float4",
        "Float8",
        "Float16",
        "FloatN",
        "Vec4f",
        "Vec4d",
        "Index",
        "OnIndex",
        "IndexMask",
        "OnIndexMask",
        "PointIndex",
        "Vec3u8",
        "Vec3u16",
        "uint8",
    ];
    match usize::try_from(t).ok().and_then(|i| NAMES.get(i)) {
        Some(n) => (*n).to_string(),
        None => format!("unknown type {t}"),
    }
}

/// `GridFlags::HasMinMax`: the nodes' min/max fields are filled in.
const FLAG_HAS_MIN_MAX: u32 = 1 << 2;

const TREE_BYTES: usize = 64;
const ROOT_BYTES: usize = 64;
const ROOT_TILE_BYTES: usize = 32;
const LEAF_BYTES: usize = 2144;
const LEAF_VALUE_MASK: usize = 16;
const LEAF_VALUES: usize = 96;

/// Where the parts of an internal node are, and what its children are.
struct InternalLayout {
    /// Entries in the table (32³ or 16³).
    entries: usize,
    value_mask: usize,
    child_mask: usize,
    table: usize,
    bytes: usize,
    child_bytes: usize,
    child_what: &'static str,
}

const UPPER: InternalLayout = InternalLayout {
    entries: 1 << 15,
    value_mask: 32,
    child_mask: 32 + 4096,
    table: 8256,
    bytes: 270_400,
    child_bytes: LOWER.bytes,
    child_what: "lower node",
};

const LOWER: InternalLayout = InternalLayout {
    entries: 1 << 12,
    value_mask: 32,
    child_mask: 32 + 512,
    table: 1088,
    bytes: 33_856,
    child_bytes: LEAF_BYTES,
    child_what: "leaf",
};

const UPPER_WORDS: usize = UPPER.entries / 64;
const LOWER_WORDS: usize = LOWER.entries / 64;

/// The grid's class (`GridClass`): how its values are meant.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GridClass {
    /// No class given.
    Unknown,
    /// A narrow-band signed distance field.
    LevelSet,
    /// A fog volume (density).
    FogVolume,
    /// Another class, by NanoVDB's number.
    Other(u32),
}

impl GridClass {
    fn from_raw(c: u32) -> Self {
        match c {
            0 => GridClass::Unknown,
            1 => GridClass::LevelSet,
            2 => GridClass::FogVolume,
            c => GridClass::Other(c),
        }
    }
}

/// The index-to-world map (`nanovdb::Map`), in the single-precision form the `...F` methods use.
#[derive(Clone, Copy, Debug)]
struct Map {
    /// Row-major 3×3 matrix, index to world.
    mat: [f32; 9],
    /// Its inverse, world to index.
    inv: [f32; 9],
    /// Translation.
    vec: [f32; 3],
}

/// A root tile: a child upper node or a value covering a 4096³ block.
#[derive(Clone, Copy, Debug)]
struct RootTile {
    /// The block's origin (coordinates with the low 12 bits clear).
    origin: [i32; 3],
    /// Index of the upper node, or [`NO_CHILD`].
    child: u32,
    /// The tile's value when there is no child.
    value: f32,
}

const NO_CHILD: u32 = u32::MAX;

/// A NanoVDB float grid read from a file (pbrt-v4 `nanovdb::FloatGrid` as used by
/// `NanoVDBMedium`), decoded into flat arrays for fast lookups.
#[derive(Clone, Debug)]
pub struct FloatGrid {
    name: String,
    class: GridClass,
    background: f32,
    min_max: (f32, f32),
    index_bbox: ([i32; 3], [i32; 3]),
    world_bbox: ([f64; 3], [f64; 3]),
    voxel_size: [f64; 3],
    map: Map,
    /// Sorted by origin.
    root: Vec<RootTile>,
    /// Child masks, [`UPPER_WORDS`] words per upper node.
    upper_masks: Vec<u64>,
    /// Per upper node 32³ entries: a lower-node index where the mask bit is set, else the
    /// tile value's bits.
    upper_table: Vec<u32>,
    /// Child masks, [`LOWER_WORDS`] words per lower node.
    lower_masks: Vec<u64>,
    /// Per lower node 16³ entries: a leaf index where the mask bit is set, else the tile
    /// value's bits.
    lower_table: Vec<u32>,
    /// 512 values per leaf.
    leaves: Vec<f32>,
}

/// Where a voxel's value lives: in a leaf (index of its first value) or in a tile.
enum Slot {
    Leaf(usize),
    Tile(f32),
}

#[inline]
fn upper_index(ijk: [i32; 3]) -> usize {
    ((((ijk[0] & 4095) >> 7) << 10) | (((ijk[1] & 4095) >> 7) << 5) | ((ijk[2] & 4095) >> 7))
        as usize
}

#[inline]
fn lower_index(ijk: [i32; 3]) -> usize {
    ((((ijk[0] & 127) >> 3) << 8) | (((ijk[1] & 127) >> 3) << 4) | ((ijk[2] & 127) >> 3)) as usize
}

#[inline]
fn leaf_index(ijk: [i32; 3]) -> usize {
    (((ijk[0] & 7) << 6) | ((ijk[1] & 7) << 3) | (ijk[2] & 7)) as usize
}

#[inline]
fn lerp(a: f32, b: f32, w: f32) -> f32 {
    a + w * (b - a)
}

impl FloatGrid {
    /// The grid's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The grid's class (fog volume, level set, ...).
    pub fn grid_class(&self) -> GridClass {
        self.class
    }

    /// The value of voxels outside all nodes and tiles.
    pub fn background(&self) -> f32 {
        self.background
    }

    /// The size of a voxel in world units (`GridData::mVoxelSize`).
    pub fn voxel_size(&self) -> [f64; 3] {
        self.voxel_size
    }

    /// The number of upper internal, lower internal and leaf nodes.
    pub fn node_counts(&self) -> [usize; 3] {
        [
            self.upper_masks.len() / UPPER_WORDS,
            self.lower_masks.len() / LOWER_WORDS,
            self.leaves.len() / 512,
        ]
    }

    #[inline]
    fn root_tile(&self, ijk: [i32; 3]) -> Option<&RootTile> {
        let key = [ijk[0] & !4095, ijk[1] & !4095, ijk[2] & !4095];
        if self.root.len() <= 8 {
            self.root.iter().find(|t| t.origin == key)
        } else {
            self.root
                .binary_search_by(|t| t.origin.cmp(&key))
                .ok()
                .map(|i| &self.root[i])
        }
    }

    /// Descends to the leaf or tile holding `ijk`.
    #[inline]
    fn slot(&self, ijk: [i32; 3]) -> Slot {
        let Some(tile) = self.root_tile(ijk) else {
            return Slot::Tile(self.background);
        };
        if tile.child == NO_CHILD {
            return Slot::Tile(tile.value);
        }
        let u = tile.child as usize;
        let n = upper_index(ijk);
        let entry = self.upper_table[u * UPPER.entries + n];
        if (self.upper_masks[u * UPPER_WORDS + (n >> 6)] >> (n & 63)) & 1 == 0 {
            return Slot::Tile(f32::from_bits(entry));
        }
        let l = entry as usize;
        let n = lower_index(ijk);
        let entry = self.lower_table[l * LOWER.entries + n];
        if (self.lower_masks[l * LOWER_WORDS + (n >> 6)] >> (n & 63)) & 1 == 0 {
            return Slot::Tile(f32::from_bits(entry));
        }
        Slot::Leaf(entry as usize * 512)
    }

    /// The value at integer index coordinates: a leaf's stored value (active or not), else the
    /// value of the tile covering the voxel, else the background (`tree().getValue(ijk)`).
    #[inline]
    pub fn value(&self, ijk: [i32; 3]) -> f32 {
        match self.slot(ijk) {
            Slot::Leaf(base) => self.leaves[base + leaf_index(ijk)],
            Slot::Tile(v) => v,
        }
    }

    /// The 2×2×2 voxel values from `ijk` to `ijk + 1`, in the order `[i][j][k]` flattened.
    #[inline]
    fn stencil(&self, ijk: [i32; 3]) -> [f32; 8] {
        if ijk[0] & 7 != 7 && ijk[1] & 7 != 7 && ijk[2] & 7 != 7 {
            // All eight lie in the same 8³ block: one descent.
            return match self.slot(ijk) {
                Slot::Tile(v) => [v; 8],
                Slot::Leaf(base) => {
                    let n = base + leaf_index(ijk);
                    let l = &self.leaves[n..n + 74];
                    [l[0], l[1], l[8], l[9], l[64], l[65], l[72], l[73]]
                }
            };
        }
        let mut v = [0.0; 8];
        for (c, out) in v.iter_mut().enumerate() {
            let d = [(c >> 2) as i32, ((c >> 1) & 1) as i32, (c & 1) as i32];
            *out = self.value([
                ijk[0].wrapping_add(d[0]),
                ijk[1].wrapping_add(d[1]),
                ijk[2].wrapping_add(d[2]),
            ]);
        }
        v
    }

    /// Trilinear interpolation at a floating-point index-space point, as
    /// `nanovdb::SampleFromVoxels<TreeT, 1, false>`: voxel values sit at integer coordinates;
    /// the point's floor picks the 2×2×2 neighbours and its fractional part the weights
    /// (interpolated along z, then y, then x, as NanoVDB does).
    #[inline]
    pub fn sample_trilinear(&self, p_index: [f32; 3]) -> f32 {
        // ⌊x⌋ by truncation and a correction (`floor` is a libm call on
        // baseline x86-64); coordinates are first kept where i32 and f32
        // agree, far outside any grid (NaN stays NaN in the weights).
        let floor = |x: f32| {
            let x = x.clamp(-1e9, 1e9);
            let i = x as i32;
            if (i as f32) > x {
                i - 1
            } else {
                i
            }
        };
        let i = [floor(p_index[0]), floor(p_index[1]), floor(p_index[2])];
        let w = [
            p_index[0].clamp(-1e9, 1e9) - i[0] as f32,
            p_index[1].clamp(-1e9, 1e9) - i[1] as f32,
            p_index[2].clamp(-1e9, 1e9) - i[2] as f32,
        ];
        let v = self.stencil(i);
        let x0 = lerp(lerp(v[0], v[1], w[2]), lerp(v[2], v[3], w[2]), w[1]);
        let x1 = lerp(lerp(v[4], v[5], w[2]), lerp(v[6], v[7], w[2]), w[1]);
        lerp(x0, x1, w[0])
    }

    /// World (the grid's own world, i.e. pbrt's medium space) to index space, as
    /// `worldToIndexF`: the single-precision inverse matrix applied to `p` minus the
    /// translation. (NanoVDB uses fused multiply-adds here; plain ones can differ in the last
    /// bit.)
    #[inline]
    pub fn world_to_index(&self, p: [f32; 3]) -> [f32; 3] {
        let m = &self.map.inv;
        let q = [
            p[0] - self.map.vec[0],
            p[1] - self.map.vec[1],
            p[2] - self.map.vec[2],
        ];
        [
            q[0] * m[0] + (q[1] * m[1] + q[2] * m[2]),
            q[0] * m[3] + (q[1] * m[4] + q[2] * m[5]),
            q[0] * m[6] + (q[1] * m[7] + q[2] * m[8]),
        ]
    }

    /// Index to world space, as `indexToWorldF`: the single-precision matrix, then the
    /// translation.
    #[inline]
    pub fn index_to_world(&self, p: [f32; 3]) -> [f32; 3] {
        let m = &self.map.mat;
        let t = &self.map.vec;
        [
            p[0] * m[0] + (p[1] * m[1] + (p[2] * m[2] + t[0])),
            p[0] * m[3] + (p[1] * m[4] + (p[2] * m[5] + t[1])),
            p[0] * m[6] + (p[1] * m[7] + (p[2] * m[8] + t[2])),
        ]
    }

    /// The grid's world bounding box as stored in the grid data (`GridData::mWorldBBox`),
    /// min and max.
    pub fn world_bbox(&self) -> ([f64; 3], [f64; 3]) {
        self.world_bbox
    }

    /// The index bounding box of the tree (`RootData`'s bbox: min and max, inclusive).
    /// For an empty grid NanoVDB stores an inverted box (min > max).
    pub fn index_bbox(&self) -> ([i32; 3], [i32; 3]) {
        self.index_bbox
    }

    /// Minimum and maximum of the active values: the root's stored extrema
    /// (`tree().extrema()`) when the grid says it has them, else computed from the active
    /// voxels and tiles at load (the background twice if there are none).
    pub fn min_max(&self) -> (f32, f32) {
        self.min_max
    }
}

/// Running min/max of active values.
struct Extrema {
    min: f32,
    max: f32,
    any: bool,
}

impl Extrema {
    fn add(&mut self, v: f32) {
        if !self.any {
            (self.min, self.max, self.any) = (v, v, true);
        } else {
            self.min = self.min.min(v);
            self.max = self.max.max(v);
        }
    }
}

fn corrupt(msg: String) -> NanoVdbError {
    NanoVdbError::Corrupt(msg)
}

fn f32_at(b: &[u8], at: usize) -> f32 {
    f32::from_bits(le_u32(b, at))
}

fn f64_at(b: &[u8], at: usize) -> f64 {
    f64::from_bits(le_u64(b, at))
}

fn i32x3_at(b: &[u8], at: usize) -> [i32; 3] {
    [0, 1, 2].map(|i| le_u32(b, at + 4 * i) as i32)
}

/// The origin encoded in a root tile's key: three 21-bit fields of the coordinates shifted
/// right by 12 (x in the highest bits).
fn key_origin(key: u64) -> [i32; 3] {
    let field = |shift: u32| ((((key >> shift) & 0x1f_ffff) as u32) << 12) as i32;
    [field(42), field(21), field(0)]
}

/// The byte position of a child `rel` bytes from its parent at `parent`, checked to hold a
/// whole node of `size` bytes inside the buffer and to be 32-byte aligned.
fn child_pos(
    parent: usize,
    rel: i64,
    size: usize,
    len: usize,
    what: &str,
) -> Result<usize, NanoVdbError> {
    let pos = parent as i128 + i128::from(rel);
    if pos < 0 || pos % 32 != 0 || pos + size as i128 > len as i128 {
        return Err(corrupt(format!(
            "{what} at offset {rel} from byte {parent} is misaligned or outside the grid's \
             {len} bytes"
        )));
    }
    Ok(pos as usize)
}

/// A child's position stored in a table until the child level is numbered (positions are
/// 32-byte aligned, so a u32 holds them up to 128 GiB).
fn pos_tag(pos: usize) -> Result<u32, NanoVdbError> {
    u32::try_from(pos / 32).map_err(|_| corrupt(format!("node offset {pos} is too large")))
}

/// Sorts and de-duplicates the positions of one level's nodes and checks that no two overlap,
/// so the level's decoded size is bounded by the buffer's.
fn level(mut refs: Vec<usize>, size: usize, what: &str) -> Result<Vec<usize>, NanoVdbError> {
    refs.sort_unstable();
    refs.dedup();
    if let Some(w) = refs.windows(2).find(|w| w[1] - w[0] < size) {
        return Err(corrupt(format!(
            "two {what}s overlap (at bytes {} and {})",
            w[0], w[1]
        )));
    }
    Ok(refs)
}

/// Replaces the position tags in child entries by indices into the numbered level.
fn number_children(masks: &[u64], table: &mut [u32], level: &[usize]) -> Result<(), NanoVdbError> {
    for (w, &word) in masks.iter().enumerate() {
        let mut bits = word;
        while bits != 0 {
            let n = w * 64 + bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let pos = table[n] as usize * 32;
            let i = level
                .binary_search(&pos)
                .map_err(|_| corrupt(format!("child node at byte {pos} not found")))?;
            table[n] = i as u32;
        }
    }
    Ok(())
}

/// Decodes one internal node at `pos`: its child mask, its table (tile values as bits, child
/// positions as tags), its children's positions and its active tile values' extrema.
fn decode_internal(
    g: &[u8],
    pos: usize,
    layout: &InternalLayout,
    masks: &mut Vec<u64>,
    table: &mut Vec<u32>,
    child_refs: &mut Vec<usize>,
    extrema: &mut Extrema,
) -> Result<(), NanoVdbError> {
    let node = &g[pos..pos + layout.bytes];
    for w in 0..layout.entries / 64 {
        let child_word = le_u64(node, layout.child_mask + 8 * w);
        let value_word = le_u64(node, layout.value_mask + 8 * w);
        masks.push(child_word);
        for b in 0..64 {
            let at = layout.table + 8 * (w * 64 + b);
            if (child_word >> b) & 1 == 1 {
                let rel = le_u64(node, at) as i64;
                let child = child_pos(pos, rel, layout.child_bytes, g.len(), layout.child_what)?;
                child_refs.push(child);
                table.push(pos_tag(child)?);
            } else {
                let v = le_u32(node, at);
                if (value_word >> b) & 1 == 1 {
                    extrema.add(f32::from_bits(v));
                }
                table.push(v);
            }
        }
    }
    Ok(())
}

/// Decodes a whole grid buffer (the bytes of one grid, uncompressed). `name` is the name the
/// file's metadata gives it (which, unlike `GridData`'s, is not cut at 255 bytes).
pub(super) fn decode(g: &[u8], name: &str) -> Result<FloatGrid, NanoVdbError> {
    let len = g.len();
    let tree = GRID_DATA_BYTES as usize;
    if len < tree + TREE_BYTES + ROOT_BYTES {
        return Err(corrupt(format!(
            "grid \"{name}\" of {len} bytes is smaller than its headers"
        )));
    }
    let magic = le_u64(g, 0);
    if magic != MAGIC_NUMB && magic != MAGIC_GRID {
        return Err(corrupt(format!("grid \"{name}\" has a bad magic number")));
    }
    let version = le_u32(g, 16);
    if !is_supported_version(version) {
        return Err(version_error(version));
    }
    let flags = le_u32(g, 20);
    let claimed = le_u64(g, 32);
    if claimed != len as u64 {
        return Err(corrupt(format!(
            "grid \"{name}\" says it has {claimed} bytes, the file gives {len}"
        )));
    }
    let name = if name.is_empty() {
        c_string(&g[40..296])
    } else {
        name.to_string()
    };
    let grid_type = le_u32(g, 636);
    if grid_type != GRID_TYPE_FLOAT {
        return Err(NanoVdbError::NotFloatGrid {
            name,
            found_type: grid_type_name(grid_type),
        });
    }
    let class = GridClass::from_raw(le_u32(g, 632));
    let map = Map {
        mat: [0, 1, 2, 3, 4, 5, 6, 7, 8].map(|i| f32_at(g, 296 + 4 * i)),
        inv: [0, 1, 2, 3, 4, 5, 6, 7, 8].map(|i| f32_at(g, 332 + 4 * i)),
        vec: [0, 1, 2].map(|i| f32_at(g, 368 + 4 * i)),
    };
    let world_bbox = (
        [0, 1, 2].map(|i| f64_at(g, 560 + 8 * i)),
        [0, 1, 2].map(|i| f64_at(g, 584 + 8 * i)),
    );
    let voxel_size = [0, 1, 2].map(|i| f64_at(g, 608 + 8 * i));

    // The root, at TreeData::mNodeOffset[3] from the tree.
    let root_rel = le_u64(g, tree + 24);
    let root = (tree as u64)
        .checked_add(root_rel)
        .filter(|&r| r % 32 == 0 && r <= (len - ROOT_BYTES) as u64)
        .ok_or_else(|| corrupt(format!("root node offset {root_rel} is outside the grid")))?
        as usize;
    let index_bbox = (i32x3_at(g, root), i32x3_at(g, root + 12));
    let table_size = le_u32(g, root + 24) as usize;
    let background = f32_at(g, root + 28);
    let stored_min_max = (f32_at(g, root + 32), f32_at(g, root + 36));
    let tiles = root + ROOT_BYTES;
    if (table_size as u64) * (ROOT_TILE_BYTES as u64) > (len - tiles) as u64 {
        return Err(corrupt(format!(
            "the root's {table_size} tiles do not fit in the grid's {len} bytes"
        )));
    }

    let mut extrema = Extrema {
        min: 0.0,
        max: 0.0,
        any: false,
    };
    let mut root_tiles = Vec::with_capacity(table_size);
    let mut upper_refs = Vec::new();
    for t in 0..table_size {
        let b = &g[tiles + ROOT_TILE_BYTES * t..tiles + ROOT_TILE_BYTES * (t + 1)];
        let origin = key_origin(le_u64(b, 0));
        let rel = le_u64(b, 8) as i64;
        let active = le_u32(b, 16) != 0;
        let value = f32_at(b, 20);
        let child = if rel == 0 {
            if active {
                extrema.add(value);
            }
            NO_CHILD
        } else {
            let pos = child_pos(root, rel, UPPER.bytes, len, "upper node")?;
            upper_refs.push(pos);
            pos_tag(pos)?
        };
        root_tiles.push(RootTile {
            origin,
            child,
            value,
        });
    }
    // Sorted for lookups; of tiles with the same key, the first wins (as in NanoVDB's scan).
    root_tiles.sort_by_key(|t| t.origin);
    root_tiles.dedup_by(|later, first| later.origin == first.origin);

    let uppers = level(upper_refs, UPPER.bytes, "upper node")?;
    for t in root_tiles.iter_mut().filter(|t| t.child != NO_CHILD) {
        let pos = t.child as usize * 32;
        let i = uppers
            .binary_search(&pos)
            .map_err(|_| corrupt(format!("upper node at byte {pos} not found")))?;
        t.child = i as u32;
    }

    let mut upper_masks = Vec::with_capacity(uppers.len() * UPPER_WORDS);
    let mut upper_table = Vec::with_capacity(uppers.len() * UPPER.entries);
    let mut lower_refs = Vec::new();
    for &pos in &uppers {
        decode_internal(
            g,
            pos,
            &UPPER,
            &mut upper_masks,
            &mut upper_table,
            &mut lower_refs,
            &mut extrema,
        )?;
    }
    let lowers = level(lower_refs, LOWER.bytes, "lower node")?;
    number_children(&upper_masks, &mut upper_table, &lowers)?;

    let mut lower_masks = Vec::with_capacity(lowers.len() * LOWER_WORDS);
    let mut lower_table = Vec::with_capacity(lowers.len() * LOWER.entries);
    let mut leaf_refs = Vec::new();
    for &pos in &lowers {
        decode_internal(
            g,
            pos,
            &LOWER,
            &mut lower_masks,
            &mut lower_table,
            &mut leaf_refs,
            &mut extrema,
        )?;
    }
    let leaf_pos = level(leaf_refs, LEAF_BYTES, "leaf")?;
    number_children(&lower_masks, &mut lower_table, &leaf_pos)?;

    let mut leaves = Vec::with_capacity(leaf_pos.len() * 512);
    for &pos in &leaf_pos {
        let node = &g[pos..pos + LEAF_BYTES];
        for w in 0..8 {
            let active = le_u64(node, LEAF_VALUE_MASK + 8 * w);
            for b in 0..64 {
                let v = f32_at(node, LEAF_VALUES + 4 * (w * 64 + b));
                if (active >> b) & 1 == 1 {
                    extrema.add(v);
                }
                leaves.push(v);
            }
        }
    }

    let min_max = if flags & FLAG_HAS_MIN_MAX != 0 {
        stored_min_max
    } else if extrema.any {
        (extrema.min, extrema.max)
    } else {
        (background, background)
    };
    Ok(FloatGrid {
        name,
        class,
        background,
        min_max,
        index_bbox,
        world_bbox,
        voxel_size,
        map,
        root: root_tiles,
        upper_masks,
        upper_table,
        lower_masks,
        lower_table,
        leaves,
    })
}
