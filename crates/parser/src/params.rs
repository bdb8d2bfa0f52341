//! Parameter lists and typed access to them (pbrt-v4 `paramdict.h/.cpp`,
//! `ParsedParameter` and `ParameterDictionary`; book section C.2).
//!
//! A directive's parameters arrive as `"type name" [ values ]`. The parser
//! stores them untyped ([`ParsedParameter`]); the scene builder wraps them in
//! a [`ParameterDictionary`] and asks for values by name and type. Every
//! lookup marks the parameter used, so that typos can be reported with
//! [`ParameterDictionary::report_unused`].

use std::borrow::Cow;
use std::fmt;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::diag::Diagnostic;
use crate::loc::FileLoc;

/// What kind of values a parameter type holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ValueKind {
    /// Floating-point numbers (`float`, points, vectors, normals, `rgb`, `blackbody`).
    Float,
    /// 32-bit integers (`integer`).
    Int,
    /// Booleans (`bool`), written `true`/`false`, quoted or not.
    Bool,
    /// Strings (`string`, `texture`).
    String,
    /// Either numbers (wavelength/value pairs) or strings (a named spectrum
    /// or a file name): `spectrum`.
    Spectrum,
}

/// The pbrt-v4 name of parameter type `ty`, mapping the pbrt-v3 aliases
/// (`point`→`point3`, `vector`→`vector3`, `color`→`rgb`, `normal3`→`normal`).
/// `None` for an unknown type.
pub fn canonical_type(ty: &str) -> Option<&'static str> {
    Some(match ty {
        "float" => "float",
        "integer" => "integer",
        "bool" => "bool",
        "string" => "string",
        "texture" => "texture",
        "point2" => "point2",
        "vector2" => "vector2",
        "point3" | "point" => "point3",
        "vector3" | "vector" => "vector3",
        "normal" | "normal3" => "normal",
        "rgb" | "color" => "rgb",
        "spectrum" => "spectrum",
        "blackbody" => "blackbody",
        _ => return None,
    })
}

/// `ty` as written, held without a copy when it is a pbrt-v4 type name
/// (pbrt-v3's aliases are copied; their upgrade renames them to the
/// canonical name, which is then held without a copy too).
fn written_type(ty: &str) -> Cow<'static, str> {
    match canonical_type(ty) {
        Some(c) if c == ty => Cow::Borrowed(c),
        _ => Cow::Owned(ty.to_string()),
    }
}

/// The kind of values a (canonical or alias) type name holds.
pub fn value_kind(ty: &str) -> Option<ValueKind> {
    Some(match canonical_type(ty)? {
        "integer" => ValueKind::Int,
        "bool" => ValueKind::Bool,
        "string" | "texture" => ValueKind::String,
        "spectrum" => ValueKind::Spectrum,
        _ => ValueKind::Float,
    })
}

/// Splits a declaration such as `"float radius"` into its type and name.
/// It must hold exactly two words separated by spaces or tabs.
pub fn split_declaration(decl: &str) -> Result<(&str, &str), String> {
    let mut words = decl.split([' ', '\t']).filter(|w| !w.is_empty());
    match (words.next(), words.next(), words.next()) {
        (Some(ty), Some(name), None) => Ok((ty, name)),
        (None, _, _) => Err(format!(
            "parameter declaration \"{decl}\" is empty; expected \"type name\""
        )),
        (Some(_), None, _) => Err(format!(
            "parameter declaration \"{decl}\" has no name; expected \"type name\""
        )),
        (Some(_), Some(_), Some(_)) => Err(format!(
            "parameter declaration \"{decl}\" has more than two words; expected \"type name\""
        )),
    }
}

/// One parameter as written in the file: type, name, location and values.
/// Exactly one of the value vectors is non-empty (or none, for `[ ]`).
#[derive(Debug)]
pub struct ParsedParameter {
    /// Type as written (`float`, `point3`, `rgb`, or a pbrt-v3 alias).
    pub ty: Cow<'static, str>,
    /// Parameter name.
    pub name: String,
    /// Location of the declaration string.
    pub loc: FileLoc,
    /// Numeric values of float-like types (and `spectrum` given as numbers).
    pub floats: Vec<f32>,
    /// Values of `integer` parameters.
    pub ints: Vec<i32>,
    /// Values of `string` and `texture` parameters (and named spectra).
    pub strings: Vec<String>,
    /// Values of `bool` parameters.
    pub bools: Vec<bool>,
    /// Set when a lookup consumed the parameter.
    pub looked_up: AtomicBool,
}

impl Clone for ParsedParameter {
    fn clone(&self) -> Self {
        ParsedParameter {
            ty: self.ty.clone(),
            name: self.name.clone(),
            loc: self.loc.clone(),
            floats: self.floats.clone(),
            ints: self.ints.clone(),
            strings: self.strings.clone(),
            bools: self.bools.clone(),
            looked_up: AtomicBool::new(self.is_looked_up()),
        }
    }
}

impl PartialEq for ParsedParameter {
    /// Compares type, name and values; ignores location and usage.
    fn eq(&self, o: &Self) -> bool {
        self.ty == o.ty
            && self.name == o.name
            && self
                .floats
                .iter()
                .map(|f| f.to_bits())
                .eq(o.floats.iter().map(|f| f.to_bits()))
            && self.ints == o.ints
            && self.strings == o.strings
            && self.bools == o.bools
    }
}

impl ParsedParameter {
    /// The memory the parameter holds, in bytes: itself, its names and its
    /// values (for the memory budget).
    pub fn memory_bytes(&self) -> usize {
        use crate::budget::heap;
        std::mem::size_of::<Self>()
            + match &self.ty {
                Cow::Owned(s) => heap(s.capacity()),
                Cow::Borrowed(_) => 0,
            }
            + heap(self.name.capacity())
            + heap(self.floats.capacity() * std::mem::size_of::<f32>())
            + heap(self.ints.capacity() * std::mem::size_of::<i32>())
            + heap(self.bools.capacity())
            + heap(self.strings.capacity() * std::mem::size_of::<String>())
            + self
                .strings
                .iter()
                .map(|s| heap(s.capacity()))
                .sum::<usize>()
    }

    /// A parameter without values.
    pub fn new(ty: impl AsRef<str>, name: impl Into<String>, loc: FileLoc) -> Self {
        ParsedParameter {
            ty: written_type(ty.as_ref()),
            name: name.into(),
            loc,
            floats: Vec::new(),
            ints: Vec::new(),
            strings: Vec::new(),
            bools: Vec::new(),
            looked_up: AtomicBool::new(false),
        }
    }

    /// A parameter holding `floats`.
    pub fn with_floats(ty: &str, name: &str, loc: FileLoc, floats: Vec<f32>) -> Self {
        let mut p = Self::new(ty, name, loc);
        p.floats = floats;
        p
    }

    /// A parameter holding `strings`.
    pub fn with_strings(ty: &str, name: &str, loc: FileLoc, strings: Vec<String>) -> Self {
        let mut p = Self::new(ty, name, loc);
        p.strings = strings;
        p
    }

    /// The pbrt-v4 type name (aliases resolved); the written type if unknown.
    pub fn canonical_type(&self) -> &str {
        canonical_type(&self.ty).unwrap_or(&self.ty)
    }

    /// Number of values, whatever their kind.
    pub fn value_count(&self) -> usize {
        self.floats.len() + self.ints.len() + self.strings.len() + self.bools.len()
    }

    /// True once a lookup used this parameter.
    pub fn is_looked_up(&self) -> bool {
        self.looked_up.load(Ordering::Relaxed)
    }

    /// Marks the parameter as used.
    pub fn mark_used(&self) {
        self.looked_up.store(true, Ordering::Relaxed);
    }
}

/// A parameter had the wrong type, the wrong number of values, or a bad value.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ParamError {
    /// A parameter of that name exists but with a type the lookup cannot use.
    WrongType {
        /// Where the parameter was declared.
        loc: FileLoc,
        /// Parameter name.
        name: String,
        /// Its declared type.
        found: String,
        /// What the lookup wanted (e.g. `"rgb" or "spectrum"`).
        expected: String,
    },
    /// `[ ]`: no values at all.
    NoValues {
        /// Where the parameter was declared.
        loc: FileLoc,
        /// Parameter name.
        name: String,
    },
    /// The number of values does not suit the type.
    WrongCount {
        /// Where the parameter was declared.
        loc: FileLoc,
        /// Parameter name.
        name: String,
        /// Its declared type.
        ty: String,
        /// How many values were given.
        count: usize,
        /// What was expected, in words (e.g. "exactly 3", "a multiple of 3").
        expected: String,
    },
    /// A value is out of its domain (e.g. a negative RGB component).
    InvalidValue {
        /// Where the parameter was declared.
        loc: FileLoc,
        /// Parameter name.
        name: String,
        /// What is wrong.
        message: String,
    },
}

impl ParamError {
    /// Where the offending parameter was declared.
    pub fn loc(&self) -> &FileLoc {
        match self {
            ParamError::WrongType { loc, .. }
            | ParamError::NoValues { loc, .. }
            | ParamError::WrongCount { loc, .. }
            | ParamError::InvalidValue { loc, .. } => loc,
        }
    }

    fn message(&self) -> String {
        match self {
            ParamError::WrongType {
                name,
                found,
                expected,
                ..
            } => format!("parameter \"{name}\" has type \"{found}\" but {expected} was expected"),
            ParamError::NoValues { name, .. } => {
                format!("no values provided for parameter \"{name}\"")
            }
            ParamError::WrongCount {
                name,
                ty,
                count,
                expected,
                ..
            } => format!(
                "parameter \"{ty} {name}\" has {count} value{}; expected {expected}",
                if *count == 1 { "" } else { "s" }
            ),
            ParamError::InvalidValue { name, message, .. } => {
                format!("parameter \"{name}\": {message}")
            }
        }
    }
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: error: {}", self.loc(), self.message())
    }
}

impl std::error::Error for ParamError {}

impl From<ParamError> for Diagnostic {
    fn from(e: ParamError) -> Self {
        let msg = e.message();
        Diagnostic::error(e.loc().clone(), msg)
    }
}

/// A spectrum as written in the file; the renderer turns it into a spectrum.
#[derive(Clone, Debug, PartialEq)]
pub enum SpectrumValue {
    /// `"rgb name" [ r g b ]` (or pbrt-v3 `color`).
    Rgb([f32; 3]),
    /// `"blackbody name" T`: a temperature in Kelvin.
    Blackbody(f32),
    /// `"spectrum name" [ lambda value ... ]`: piecewise-linear samples.
    Sampled(Vec<(f32, f32)>),
    /// `"spectrum name" "metal-Cu-eta"`: a named spectrum, or else a file name.
    NameOrFile(String),
}

/// Typed, usage-tracking access to a directive's parameters.
#[derive(Clone, Debug, Default)]
pub struct ParameterDictionary {
    params: Vec<ParsedParameter>,
    /// Parameters inherited from `Attribute` directives: looked up after the
    /// directive's own, and not reported when unused.
    inherited: Vec<ParsedParameter>,
}

const FLOAT_TEX: &str = "texture";

impl ParameterDictionary {
    /// The memory the parameters (own and inherited) hold, in bytes.
    pub fn memory_bytes(&self) -> usize {
        self.params
            .iter()
            .chain(&self.inherited)
            .map(ParsedParameter::memory_bytes)
            .sum()
    }

    /// Wraps a directive's parameters.
    pub fn new(params: Vec<ParsedParameter>) -> Self {
        ParameterDictionary {
            params,
            inherited: Vec::new(),
        }
    }

    /// Wraps a directive's parameters plus defaults from `Attribute`.
    pub fn with_inherited(params: Vec<ParsedParameter>, inherited: Vec<ParsedParameter>) -> Self {
        ParameterDictionary { params, inherited }
    }

    /// The directive's own parameters.
    pub fn params(&self) -> &[ParsedParameter] {
        &self.params
    }

    /// Gives the parameters back.
    pub fn into_params(self) -> Vec<ParsedParameter> {
        self.params
    }

    /// Candidates named `name`, latest first (a later duplicate overrides).
    fn named<'s: 'n, 'n>(
        &'s self,
        name: &'n str,
    ) -> impl Iterator<Item = &'s ParsedParameter> + 'n {
        self.params
            .iter()
            .rev()
            .chain(self.inherited.iter().rev())
            .filter(move |p| p.name == name)
    }

    /// Finds `name` with one of the `accept`ed canonical types. A parameter
    /// of that name with another type is an error, except that float-like
    /// and texture lookups tolerate each other (the float-or-texture idiom).
    fn find(
        &self,
        name: &str,
        accept: &[&str],
        expected: &dyn std::fmt::Display,
    ) -> Result<Option<&ParsedParameter>, ParamError> {
        let mut other: Option<&ParsedParameter> = None;
        for p in self.named(name) {
            let ct = p.canonical_type();
            if accept.contains(&ct) {
                return Ok(Some(p));
            }
            if other.is_none() {
                other = Some(p);
            }
        }
        match other {
            Some(p) if p.canonical_type() != FLOAT_TEX && !accept.contains(&FLOAT_TEX) => {
                Err(ParamError::WrongType {
                    loc: p.loc.clone(),
                    name: name.to_string(),
                    found: p.ty.to_string(),
                    expected: expected.to_string(),
                })
            }
            _ => Ok(None),
        }
    }

    fn count_error(p: &ParsedParameter, expected: String) -> ParamError {
        if p.value_count() == 0 {
            ParamError::NoValues {
                loc: p.loc.clone(),
                name: p.name.clone(),
            }
        } else {
            ParamError::WrongCount {
                loc: p.loc.clone(),
                name: p.name.clone(),
                ty: p.ty.to_string(),
                count: p.value_count(),
                expected,
            }
        }
    }

    fn one_floats<const N: usize>(
        &self,
        name: &str,
        ty: &str,
    ) -> Result<Option<[f32; N]>, ParamError> {
        let Some(p) = self.find(name, &[ty], &Quoted(ty))? else {
            return Ok(None);
        };
        if p.floats.len() != N || p.value_count() != N {
            return Err(Self::count_error(p, format!("exactly {N}")));
        }
        p.mark_used();
        let mut out = [0.0; N];
        out.copy_from_slice(&p.floats);
        Ok(Some(out))
    }

    fn float_tuples<const N: usize>(
        &self,
        name: &str,
        ty: &str,
    ) -> Result<Vec<[f32; N]>, ParamError> {
        let Some(p) = self.find(name, &[ty], &Quoted(ty))? else {
            return Ok(Vec::new());
        };
        if p.floats.is_empty() || p.floats.len() % N != 0 || p.value_count() != p.floats.len() {
            let expected = if N == 1 {
                "at least one number".to_string()
            } else {
                format!("a non-zero multiple of {N}")
            };
            return Err(Self::count_error(p, expected));
        }
        p.mark_used();
        Ok(p.floats
            .chunks_exact(N)
            .map(|c| {
                let mut a = [0.0; N];
                a.copy_from_slice(c);
                a
            })
            .collect())
    }

    /// The single `float` named `name`, or `default` if absent.
    pub fn get_one_float(&self, name: &str, default: f32) -> Result<f32, ParamError> {
        Ok(self
            .one_floats::<1>(name, "float")?
            .map_or(default, |a| a[0]))
    }

    /// The single `integer` named `name`, or `default` if absent.
    pub fn get_one_int(&self, name: &str, default: i32) -> Result<i32, ParamError> {
        let Some(p) = self.find(name, &["integer"], &"\"integer\"")? else {
            return Ok(default);
        };
        if p.ints.len() != 1 || p.value_count() != 1 {
            return Err(Self::count_error(p, "exactly 1".into()));
        }
        p.mark_used();
        Ok(p.ints[0])
    }

    /// The single `bool` named `name`, or `default` if absent.
    pub fn get_one_bool(&self, name: &str, default: bool) -> Result<bool, ParamError> {
        let Some(p) = self.find(name, &["bool"], &"\"bool\"")? else {
            return Ok(default);
        };
        if p.bools.len() != 1 || p.value_count() != 1 {
            return Err(Self::count_error(p, "exactly 1".into()));
        }
        p.mark_used();
        Ok(p.bools[0])
    }

    /// The single `string` named `name`, or `default` if absent.
    pub fn get_one_string(&self, name: &str, default: &str) -> Result<String, ParamError> {
        Ok(self
            .get_one_string_opt(name)?
            .unwrap_or_else(|| default.to_string()))
    }

    /// The single `string` named `name`, if present.
    pub fn get_one_string_opt(&self, name: &str) -> Result<Option<String>, ParamError> {
        let Some(p) = self.find(name, &["string"], &"\"string\"")? else {
            return Ok(None);
        };
        if p.strings.len() != 1 || p.value_count() != 1 {
            return Err(Self::count_error(p, "exactly 1".into()));
        }
        p.mark_used();
        Ok(Some(p.strings[0].clone()))
    }

    /// The single `point2` named `name`, or `default`.
    pub fn get_one_point2(&self, name: &str, default: [f32; 2]) -> Result<[f32; 2], ParamError> {
        Ok(self.one_floats::<2>(name, "point2")?.unwrap_or(default))
    }

    /// The single `vector2` named `name`, or `default`.
    pub fn get_one_vector2(&self, name: &str, default: [f32; 2]) -> Result<[f32; 2], ParamError> {
        Ok(self.one_floats::<2>(name, "vector2")?.unwrap_or(default))
    }

    /// The single `point3` (or v3 `point`) named `name`, or `default`.
    pub fn get_one_point3(&self, name: &str, default: [f32; 3]) -> Result<[f32; 3], ParamError> {
        Ok(self.one_floats::<3>(name, "point3")?.unwrap_or(default))
    }

    /// The single `vector3` (or v3 `vector`) named `name`, or `default`.
    pub fn get_one_vector3(&self, name: &str, default: [f32; 3]) -> Result<[f32; 3], ParamError> {
        Ok(self.one_floats::<3>(name, "vector3")?.unwrap_or(default))
    }

    /// The single `normal` (or `normal3`) named `name`, or `default`.
    pub fn get_one_normal3(&self, name: &str, default: [f32; 3]) -> Result<[f32; 3], ParamError> {
        Ok(self.one_floats::<3>(name, "normal")?.unwrap_or(default))
    }

    /// The `rgb` (or v3 `color`) triple named `name`, if present. Negative
    /// components are an error.
    pub fn get_one_rgb(&self, name: &str) -> Result<Option<[f32; 3]>, ParamError> {
        let rgb = self.one_floats::<3>(name, "rgb")?;
        if let Some(c) = rgb {
            check_rgb(self, name, c)?;
        }
        Ok(rgb)
    }

    /// All values of the `float` named `name` (empty if absent).
    pub fn get_float_array(&self, name: &str) -> Result<Vec<f32>, ParamError> {
        Ok(self
            .float_tuples::<1>(name, "float")?
            .into_iter()
            .map(|a| a[0])
            .collect())
    }

    /// All triples of the `rgb` (or v3 `color`) named `name`, in order
    /// (empty if absent). A count that is not a multiple of three, or a
    /// negative component, is an error.
    pub fn get_rgb_array(&self, name: &str) -> Result<Vec<[f32; 3]>, ParamError> {
        let rgbs = self.float_tuples::<3>(name, "rgb")?;
        for c in &rgbs {
            check_rgb(self, name, *c)?;
        }
        Ok(rgbs)
    }

    /// All values of the `integer` named `name` (empty if absent).
    pub fn get_int_array(&self, name: &str) -> Result<Vec<i32>, ParamError> {
        let Some(p) = self.find(name, &["integer"], &"\"integer\"")? else {
            return Ok(Vec::new());
        };
        if p.ints.is_empty() || p.value_count() != p.ints.len() {
            return Err(Self::count_error(p, "at least one integer".into()));
        }
        p.mark_used();
        Ok(p.ints.clone())
    }

    /// All values of the `bool` named `name` (empty if absent).
    pub fn get_bool_array(&self, name: &str) -> Result<Vec<bool>, ParamError> {
        let Some(p) = self.find(name, &["bool"], &"\"bool\"")? else {
            return Ok(Vec::new());
        };
        if p.bools.is_empty() || p.value_count() != p.bools.len() {
            return Err(Self::count_error(p, "at least one bool".into()));
        }
        p.mark_used();
        Ok(p.bools.clone())
    }

    /// All values of the `string` named `name` (empty if absent).
    pub fn get_string_array(&self, name: &str) -> Result<Vec<String>, ParamError> {
        let Some(p) = self.find(name, &["string"], &"\"string\"")? else {
            return Ok(Vec::new());
        };
        if p.strings.is_empty() || p.value_count() != p.strings.len() {
            return Err(Self::count_error(p, "at least one string".into()));
        }
        p.mark_used();
        Ok(p.strings.clone())
    }

    /// All `point2` values named `name`.
    pub fn get_point2_array(&self, name: &str) -> Result<Vec<[f32; 2]>, ParamError> {
        self.float_tuples::<2>(name, "point2")
    }

    /// All `vector2` values named `name`.
    pub fn get_vector2_array(&self, name: &str) -> Result<Vec<[f32; 2]>, ParamError> {
        self.float_tuples::<2>(name, "vector2")
    }

    /// All `point3` values named `name`.
    pub fn get_point3_array(&self, name: &str) -> Result<Vec<[f32; 3]>, ParamError> {
        self.float_tuples::<3>(name, "point3")
    }

    /// All `vector3` values named `name`.
    pub fn get_vector3_array(&self, name: &str) -> Result<Vec<[f32; 3]>, ParamError> {
        self.float_tuples::<3>(name, "vector3")
    }

    /// All `normal` values named `name`.
    pub fn get_normal3_array(&self, name: &str) -> Result<Vec<[f32; 3]>, ParamError> {
        self.float_tuples::<3>(name, "normal")
    }

    /// The name of the texture bound to `name` (`"texture name" "texname"`).
    /// A non-texture parameter of that name is not an error here: callers
    /// try the texture first, then a constant.
    pub fn get_texture(&self, name: &str) -> Result<Option<String>, ParamError> {
        let Some(p) = self.find(name, &[FLOAT_TEX], &"\"texture\"")? else {
            return Ok(None);
        };
        if p.strings.len() != 1 || p.value_count() != 1 {
            return Err(Self::count_error(p, "exactly 1".into()));
        }
        p.mark_used();
        Ok(Some(p.strings[0].clone()))
    }

    /// A spectrum given as `rgb`, `blackbody` or `spectrum` (samples or a
    /// name), if present.
    pub fn get_one_spectrum(&self, name: &str) -> Result<Option<SpectrumValue>, ParamError> {
        let accept = ["rgb", "blackbody", "spectrum"];
        let Some(p) = self.find(name, &accept, &"\"rgb\", \"spectrum\" or \"blackbody\"")? else {
            return Ok(None);
        };
        let v = match p.canonical_type() {
            "rgb" => {
                let Some(c) = self.one_floats::<3>(name, "rgb")? else {
                    return Ok(None);
                };
                check_rgb(self, name, c)?;
                SpectrumValue::Rgb(c)
            }
            "blackbody" => {
                if p.floats.len() != 1 || p.value_count() != 1 {
                    return Err(Self::count_error(
                        p,
                        "exactly 1 (the temperature; pbrt-v3's [T scale] needs upgrading)".into(),
                    ));
                }
                if p.floats[0] <= 0.0 {
                    return Err(ParamError::InvalidValue {
                        loc: p.loc.clone(),
                        name: name.into(),
                        message: format!("blackbody temperature {} is not positive", p.floats[0]),
                    });
                }
                SpectrumValue::Blackbody(p.floats[0])
            }
            _ => {
                if !p.strings.is_empty() {
                    if p.strings.len() != 1 || p.value_count() != 1 {
                        return Err(Self::count_error(p, "exactly one spectrum name".into()));
                    }
                    SpectrumValue::NameOrFile(p.strings[0].clone())
                } else {
                    if p.floats.len() < 2 || p.floats.len() % 2 != 0 {
                        return Err(Self::count_error(
                            p,
                            "an even number of (wavelength, value) values".into(),
                        ));
                    }
                    SpectrumValue::Sampled(p.floats.chunks_exact(2).map(|c| (c[0], c[1])).collect())
                }
            }
        };
        p.mark_used();
        Ok(Some(v))
    }

    /// The type of the latest parameter named `name`, as written.
    pub fn param_type(&self, name: &str) -> Option<&str> {
        self.named(name).next().map(|p| &*p.ty)
    }

    /// The location of the latest parameter named `name`.
    pub fn loc(&self, name: &str) -> Option<&FileLoc> {
        self.named(name).next().map(|p| &p.loc)
    }

    /// Removes the directive's own parameter `name` of canonical type `ty`
    /// and returns it.
    pub fn remove(&mut self, name: &str, ty: &str) -> Option<ParsedParameter> {
        let i = self
            .params
            .iter()
            .rposition(|p| p.name == name && p.canonical_type() == ty)?;
        Some(self.params.remove(i))
    }

    /// Renames every own parameter called `from` to `to`.
    pub fn rename(&mut self, from: &str, to: &str) {
        for p in &mut self.params {
            if p.name == from {
                p.name = to.to_string();
            }
        }
    }

    /// Warnings for the directive's own parameters no lookup used
    /// (pbrt-v4 `ReportUnused`).
    pub fn report_unused(&self) -> Vec<Diagnostic> {
        self.params
            .iter()
            .filter(|p| !p.is_looked_up())
            .map(|p| Diagnostic::warning(p.loc.clone(), format!("parameter \"{}\" unused", p.name)))
            .collect()
    }
}

fn check_rgb(d: &ParameterDictionary, name: &str, c: [f32; 3]) -> Result<(), ParamError> {
    if c.iter().any(|&v| v < 0.0) {
        let loc = d
            .loc(name)
            .cloned()
            .unwrap_or_else(|| FileLoc::new("".into(), 0, 0));
        return Err(ParamError::InvalidValue {
            loc,
            name: name.to_string(),
            message: format!(
                "RGB ({}, {}, {}) has a negative component",
                c[0], c[1], c[2]
            ),
        });
    }
    Ok(())
}

/// A parameter type as an error message names it, `"float"`, written
/// only when the error is (the lookups of every parameter would otherwise
/// format it each time).
struct Quoted<'a>(&'a str);

impl std::fmt::Display for Quoted<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "\"{}\"", self.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    fn loc(line: u32) -> FileLoc {
        FileLoc::new(Arc::from("p.pbrt"), line, 3)
    }

    fn fl(ty: &str, name: &str, line: u32, v: &[f32]) -> ParsedParameter {
        ParsedParameter::with_floats(ty, name, loc(line), v.to_vec())
    }

    #[test]
    fn type_names_as_written() {
        for ty in ["float", "rgb", "point3", "blackbody"] {
            assert!(matches!(written_type(ty), Cow::Borrowed(t) if t == ty));
        }
        for ty in ["color", "point", "normal3", "floot"] {
            assert!(matches!(written_type(ty), Cow::Owned(t) if t == ty));
        }
    }

    #[test]
    fn declarations_need_exactly_two_words() {
        assert_eq!(split_declaration("float radius"), Ok(("float", "radius")));
        assert_eq!(split_declaration("  point3\t P "), Ok(("point3", "P")));
        assert!(split_declaration("float").unwrap_err().contains("no name"));
        assert!(split_declaration("").unwrap_err().contains("empty"));
        assert!(split_declaration("float a b")
            .unwrap_err()
            .contains("more than two"));
    }

    #[test]
    fn aliases_resolve() {
        assert_eq!(canonical_type("point"), Some("point3"));
        assert_eq!(canonical_type("vector"), Some("vector3"));
        assert_eq!(canonical_type("color"), Some("rgb"));
        assert_eq!(canonical_type("normal3"), Some("normal"));
        assert_eq!(canonical_type("quaternion"), None);
        assert_eq!(value_kind("texture"), Some(ValueKind::String));
        assert_eq!(value_kind("blackbody"), Some(ValueKind::Float));
    }

    #[test]
    fn typed_lookups_and_defaults() {
        let mut i = ParsedParameter::new("integer", "n", loc(1));
        i.ints = vec![7];
        let mut b = ParsedParameter::new("bool", "on", loc(2));
        b.bools = vec![true];
        let s = ParsedParameter::with_strings("string", "file", loc(3), vec!["a.ply".into()]);
        let d = ParameterDictionary::new(vec![
            fl("float", "radius", 4, &[2.5]),
            i,
            b,
            s,
            fl("point", "P", 5, &[0., 1., 2., 3., 4., 5.]),
            fl("normal3", "N", 6, &[0., 0., 1.]),
            fl("color", "Kd", 7, &[0.1, 0.2, 0.3]),
            fl("point2", "uv", 8, &[0., 1.]),
            fl("vector", "dir", 9, &[1., 0., 0.]),
        ]);
        assert_eq!(d.get_one_float("radius", 1.0), Ok(2.5));
        assert_eq!(d.get_one_float("missing", 1.0), Ok(1.0));
        assert_eq!(d.get_one_int("n", 0), Ok(7));
        assert_eq!(d.get_one_bool("on", false), Ok(true));
        assert_eq!(d.get_one_string("file", ""), Ok("a.ply".to_string()));
        assert_eq!(
            d.get_point3_array("P").unwrap(),
            vec![[0., 1., 2.], [3., 4., 5.]]
        );
        assert_eq!(d.get_normal3_array("N").unwrap(), vec![[0., 0., 1.]]);
        assert_eq!(d.get_one_normal3("N", [0.; 3]), Ok([0., 0., 1.]));
        assert_eq!(d.get_one_rgb("Kd"), Ok(Some([0.1, 0.2, 0.3])));
        assert_eq!(d.get_point2_array("uv").unwrap(), vec![[0., 1.]]);
        assert_eq!(d.get_one_vector3("dir", [0.; 3]), Ok([1., 0., 0.]));
        assert!(d.report_unused().is_empty());
    }

    #[test]
    fn wrong_count_is_located() {
        let d = ParameterDictionary::new(vec![fl("point3", "p", 12, &[1., 2., 3., 4.])]);
        let e = d.get_one_point3("p", [0.; 3]).unwrap_err();
        assert_eq!(e.loc().line, 12);
        assert_eq!(
            e.to_string(),
            "p.pbrt:12:3: error: parameter \"point3 p\" has 4 values; expected exactly 3"
        );
        let e = d.get_point3_array("p").unwrap_err();
        assert!(e.to_string().contains("multiple of 3"), "{e}");
        let d = ParameterDictionary::new(vec![fl("float", "r", 2, &[])]);
        assert!(matches!(
            d.get_one_float("r", 0.),
            Err(ParamError::NoValues { .. })
        ));
        let d = ParameterDictionary::new(vec![fl("float", "r", 2, &[1., 2.])]);
        assert!(d.get_one_float("r", 0.).is_err());
        assert_eq!(d.get_float_array("r"), Ok(vec![1., 2.]));
    }

    #[test]
    fn rgb_arrays() {
        let d = ParameterDictionary::new(vec![
            fl("rgb", "sigma_a", 3, &[0.1, 0.2, 0.3, 1., 2., 3.]),
            fl("color", "Le", 4, &[1., 1.]),
            fl("rgb", "bad", 5, &[1., -2., 3.]),
        ]);
        assert_eq!(
            d.get_rgb_array("sigma_a"),
            Ok(vec![[0.1, 0.2, 0.3], [1., 2., 3.]])
        );
        assert_eq!(d.get_rgb_array("missing"), Ok(vec![]));
        let e = d.get_rgb_array("Le").unwrap_err();
        assert_eq!(e.loc().line, 4);
        assert!(e.to_string().contains("multiple of 3"), "{e}");
        let e = d.get_rgb_array("bad").unwrap_err();
        assert_eq!(e.loc().line, 5);
        assert!(e.to_string().contains("negative"), "{e}");
    }

    #[test]
    fn wrong_type_is_located() {
        let d = ParameterDictionary::new(vec![fl("float", "Kd", 4, &[0.5])]);
        let e = d.get_one_rgb("Kd").unwrap_err();
        assert!(matches!(e, ParamError::WrongType { .. }));
        assert_eq!(e.loc().line, 4);
        assert!(e.to_string().contains("has type \"float\""), "{e}");
        assert!(d.get_one_spectrum("Kd").is_err());
        let d = ParameterDictionary::new(vec![ParsedParameter::with_strings(
            "string",
            "radius",
            loc(9),
            vec!["x".into()],
        )]);
        assert!(d.get_one_float("radius", 1.).is_err());
    }

    #[test]
    fn float_or_texture_idiom_is_tolerated() {
        let d = ParameterDictionary::new(vec![
            fl("float", "roughness", 1, &[0.1]),
            ParsedParameter::with_strings("texture", "Kd", loc(2), vec!["checks".into()]),
        ]);
        assert_eq!(d.get_texture("roughness"), Ok(None));
        assert_eq!(d.get_one_float("roughness", 0.), Ok(0.1));
        assert_eq!(d.get_one_rgb("Kd"), Ok(None));
        assert_eq!(d.get_one_spectrum("Kd"), Ok(None));
        assert_eq!(d.get_texture("Kd"), Ok(Some("checks".into())));
    }

    #[test]
    fn spectra_as_raw_data() {
        let d = ParameterDictionary::new(vec![
            fl("rgb", "a", 1, &[1., 0.5, 0.]),
            fl("blackbody", "b", 2, &[6500.]),
            fl("spectrum", "c", 3, &[400., 1., 700., 2.]),
            ParsedParameter::with_strings("spectrum", "d", loc(4), vec!["metal-Cu-eta".into()]),
            fl("blackbody", "e", 5, &[6500., 2.]),
            fl("spectrum", "f", 6, &[400., 1., 700.]),
            fl("rgb", "g", 7, &[-1., 0., 0.]),
        ]);
        assert_eq!(
            d.get_one_spectrum("a"),
            Ok(Some(SpectrumValue::Rgb([1., 0.5, 0.])))
        );
        assert_eq!(
            d.get_one_spectrum("b"),
            Ok(Some(SpectrumValue::Blackbody(6500.)))
        );
        assert_eq!(
            d.get_one_spectrum("c"),
            Ok(Some(SpectrumValue::Sampled(vec![(400., 1.), (700., 2.)])))
        );
        assert_eq!(
            d.get_one_spectrum("d"),
            Ok(Some(SpectrumValue::NameOrFile("metal-Cu-eta".into())))
        );
        assert!(d.get_one_spectrum("e").is_err());
        assert!(d.get_one_spectrum("f").is_err());
        assert!(matches!(
            d.get_one_rgb("g"),
            Err(ParamError::InvalidValue { .. })
        ));
        assert_eq!(d.get_one_spectrum("zzz"), Ok(None));
    }

    #[test]
    fn unused_parameters_are_reported_located() {
        let d = ParameterDictionary::new(vec![
            fl("float", "radius", 3, &[1.]),
            fl("float", "raduis", 4, &[1.]),
        ]);
        d.get_one_float("radius", 0.).unwrap();
        let u = d.report_unused();
        assert_eq!(u.len(), 1);
        assert_eq!(
            u[0].to_string(),
            "p.pbrt:4:3: warning: parameter \"raduis\" unused"
        );
    }

    #[test]
    fn later_duplicates_and_inherited_values() {
        let d = ParameterDictionary::with_inherited(
            vec![fl("float", "r", 1, &[1.]), fl("float", "r", 2, &[2.])],
            vec![fl("float", "r", 3, &[3.]), fl("float", "s", 4, &[4.])],
        );
        assert_eq!(d.get_one_float("r", 0.), Ok(2.));
        assert_eq!(d.get_one_float("s", 0.), Ok(4.));
        // The first "r" was never read and is reported; inherited ones never are.
        assert_eq!(d.report_unused().len(), 1);
    }

    #[test]
    fn remove_and_rename() {
        let mut d = ParameterDictionary::new(vec![
            fl("color", "Kd", 1, &[1., 1., 1.]),
            fl("float", "x", 2, &[1.]),
        ]);
        d.rename("Kd", "reflectance");
        assert_eq!(d.param_type("reflectance"), Some("color"));
        assert!(d.remove("reflectance", "rgb").is_some());
        assert!(d.remove("x", "integer").is_none());
        assert_eq!(d.into_params().len(), 1);
    }
}
