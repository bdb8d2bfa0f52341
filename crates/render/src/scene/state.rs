//! The builder's graphics state and push stack (pbrt-v4 `scene.h`:
//! `BasicSceneBuilder::GraphicsState`, `TransformSet` and the push stack of
//! `AttributeBegin`/`ObjectBegin`).

use std::sync::Arc;

use rpbrt_geometry::{Float, Transform};
use rpbrt_parser::{FileLoc, ParsedParameter};

use super::entities::{MaterialRef, SceneEntity};

/// Bit of [`GraphicsState::active`] for the start-time transformation.
pub(super) const START_BIT: u8 = 1;
/// Bit of [`GraphicsState::active`] for the end-time transformation.
pub(super) const END_BIT: u8 = 2;
/// Both transformations.
pub(super) const ALL_BITS: u8 = START_BIT | END_BIT;

/// The current transformation at the start and at the end of the
/// transformation times (pbrt-v4 `TransformSet`).
pub(super) type TransformSet = [Transform; 2];

/// What `AttributeBegin` saves and `AttributeEnd` restores (pbrt-v4
/// `BasicSceneBuilder::GraphicsState`).
#[derive(Clone, Debug)]
pub(super) struct GraphicsState {
    pub(super) inside_medium: String,
    pub(super) outside_medium: String,
    pub(super) material: MaterialRef,
    /// The active `AreaLightSource`, shared between saved states.
    pub(super) area_light: Option<Arc<SceneEntity>>,
    pub(super) shape_attributes: Arc<Vec<ParsedParameter>>,
    pub(super) light_attributes: Arc<Vec<ParsedParameter>>,
    pub(super) material_attributes: Arc<Vec<ParsedParameter>>,
    pub(super) medium_attributes: Arc<Vec<ParsedParameter>>,
    pub(super) texture_attributes: Arc<Vec<ParsedParameter>>,
    pub(super) reverse_orientation: bool,
    pub(super) color_space: &'static str,
    pub(super) ctm: TransformSet,
    pub(super) active: u8,
    pub(super) start_time: Float,
    pub(super) end_time: Float,
}

impl Default for GraphicsState {
    fn default() -> Self {
        GraphicsState {
            inside_medium: String::new(),
            outside_medium: String::new(),
            material: MaterialRef::Index(0),
            area_light: None,
            shape_attributes: Arc::default(),
            light_attributes: Arc::default(),
            material_attributes: Arc::default(),
            medium_attributes: Arc::default(),
            texture_attributes: Arc::default(),
            reverse_orientation: false,
            color_space: "srgb",
            ctm: [Transform::identity(); 2],
            active: ALL_BITS,
            start_time: 0.0,
            end_time: 1.0,
        }
    }
}

impl GraphicsState {
    /// Applies `f` to each active transformation.
    pub(super) fn for_active(&mut self, f: impl Fn(&Transform) -> Transform) {
        // Both, and the same (no motion): computed once.
        if self.active == ALL_BITS && self.ctm[0].same_bits(&self.ctm[1]) {
            let t = f(&self.ctm[0]);
            self.ctm = [t, t];
            return;
        }
        for (i, t) in self.ctm.iter_mut().enumerate() {
            if self.active & (1 << i) != 0 {
                *t = f(t);
            }
        }
    }
}

/// One entry of the push stack.
#[derive(Debug)]
pub(super) enum Pushed {
    /// `AttributeBegin`: the whole state.
    Attribute(Box<GraphicsState>, FileLoc),
    /// `ObjectBegin`: the whole state; `opened` is false when the
    /// `ObjectBegin` was in error and started no definition.
    Object {
        state: Box<GraphicsState>,
        loc: FileLoc,
        opened: bool,
    },
    /// `TransformBegin` (pbrt-v3): only the transformation.
    Transform(Box<TransformSet>, u8, FileLoc),
}

impl Pushed {
    pub(super) fn describe(&self) -> &'static str {
        match self {
            Pushed::Attribute(..) => "AttributeBegin",
            Pushed::Object { .. } => "ObjectBegin",
            Pushed::Transform(..) => "TransformBegin",
        }
    }

    pub(super) fn loc(&self) -> &FileLoc {
        match self {
            Pushed::Attribute(_, l) | Pushed::Transform(_, _, l) => l,
            Pushed::Object { loc, .. } => loc,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Block {
    Options,
    World,
}

/// A cheap summary of a parameter list: enough to tell whether an upgrade
/// mapping changed anything (it renames, retypes, adds and removes
/// parameters or changes their value counts; it never edits a value in place).
pub(super) fn fingerprint(params: &[ParsedParameter]) -> u64 {
    // A hash rather than a copy of the names: this runs twice for every
    // directive, and copying would allocate for each parameter. It eats
    // 64-bit words, FNV-1a's step on each (xor, then a multiplication by
    // an odd number: a bijection of the state for a given word), so two
    // lists of the same number of words that differ in one word always
    // hash apart; other pairs collide about once in 2^64, and then an
    // upgrade's warnings go unreported (the upgrade itself is applied
    // either way).
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |w: u64| h = (h ^ w).wrapping_mul(0x0000_0100_0000_01b3);
    for p in params {
        for text in [p.name.as_str(), &*p.ty] {
            // The length first, so that ("ab", "c") and ("a", "bc") differ.
            eat(text.len() as u64);
            for chunk in text.as_bytes().chunks(8) {
                let mut word = [0u8; 8];
                word[..chunk.len()].copy_from_slice(chunk);
                eat(u64::from_le_bytes(word));
            }
        }
        for n in [p.floats.len(), p.ints.len(), p.strings.len(), p.bools.len()] {
            eat(n as u64);
        }
    }
    eat(params.len() as u64);
    h
}
