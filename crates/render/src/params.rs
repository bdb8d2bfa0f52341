//! The parameter reader every creator uses (pbrt-v4 `ParameterDictionary`
//! in `paramdict.h/.cpp`, the renderer's half of it; the texture half is
//! [`crate::texture::TextureParams`]).
//!
//! The parser's [`ParameterDictionary`] holds a directive's parameters as
//! written and marks each one it hands out. [`ParamReader`] adds what the
//! renderer needs to read them: the directive's location and colour space,
//! spectra built from `rgb` / `blackbody` / `spectrum` values, file names
//! resolved against the file the parameter was written in, located errors
//! that `?` carries, and one sink for warnings. When a creator is done,
//! [`ParamReader::finish`] adds a warning for every parameter nothing read
//! (pbrt-v4 `ReportUnused`): that is how typos are caught.

use std::cell::RefCell;
use std::path::{Path, PathBuf};

use rpbrt_parser::params::canonical_type;
use rpbrt_parser::{Diagnostic, FileLoc, MemoryBudget, ParameterDictionary};

use crate::spectrum::{spectrum_from_param, RgbColorSpace, Spectrum, SpectrumType};

/// A located error for a type name the renderer does not know, in the one
/// form every kind of entity uses: `"sphre": unknown shape type; expected
/// one of "bilinearmesh", ...`.
pub fn unknown_type(kind: &str, name: &str, known: &[&str], loc: &FileLoc) -> Diagnostic {
    let list = known
        .iter()
        .map(|n| format!("\"{n}\""))
        .collect::<Vec<_>>()
        .join(", ");
    Diagnostic::error(
        loc.clone(),
        format!("\"{name}\": unknown {kind} type; expected one of {list}"),
    )
}

/// The directory that file names written in `file` resolve against.
pub fn dir_of_file(file: &str) -> &Path {
    Path::new(file).parent().unwrap_or_else(|| Path::new("."))
}

/// `file`, written in the scene file `scene_file`, resolved as
/// [`ParamReader::resolve`] does.
pub fn resolve_path(scene_file: &str, file: &str) -> PathBuf {
    let p = Path::new(file);
    if p.is_absolute() {
        return p.to_path_buf();
    }
    let joined = dir_of_file(scene_file).join(p);
    if joined.exists() {
        joined
    } else {
        p.to_path_buf()
    }
}

/// Typed reading of one directive's parameters (see the module docs).
pub struct ParamReader<'a> {
    dict: &'a ParameterDictionary,
    loc: &'a FileLoc,
    color_space: &'static RgbColorSpace,
    warnings: RefCell<Vec<Diagnostic>>,
    budget: MemoryBudget,
}

impl<'a> ParamReader<'a> {
    /// A reader for the parameters `dict` of the directive at `loc`, whose
    /// RGB values are in the colour space named `color_space`.
    pub fn new(
        dict: &'a ParameterDictionary,
        loc: &'a FileLoc,
        color_space: &str,
    ) -> Result<Self, Diagnostic> {
        let Some(cs) = RgbColorSpace::get(color_space) else {
            return Err(Diagnostic::error(
                loc.clone(),
                format!("\"{color_space}\": unknown color space"),
            ));
        };
        Ok(Self::with_color_space(dict, loc, cs))
    }

    /// A reader whose RGB values are in `color_space`.
    pub fn with_color_space(
        dict: &'a ParameterDictionary,
        loc: &'a FileLoc,
        color_space: &'static RgbColorSpace,
    ) -> Self {
        ParamReader {
            dict,
            loc,
            color_space,
            warnings: RefCell::new(Vec::new()),
            budget: MemoryBudget::default(),
        }
    }

    /// The reader charging what its creator allocates for the input to
    /// `budget` (by default, a budget of its own with the default limit).
    pub fn with_budget(mut self, budget: &MemoryBudget) -> Self {
        self.budget = budget.clone();
        self
    }

    /// The memory budget creators charge what the input sizes to.
    pub fn budget(&self) -> &MemoryBudget {
        &self.budget
    }

    /// Charges `bytes`, what `what` ("this film") needs, to the memory
    /// budget; when it does not fit, an error located at the directive.
    pub fn charge(&self, bytes: u64, what: &str) -> Result<(), Diagnostic> {
        self.budget
            .charge(bytes, what)
            .map_err(|e| self.error(e.to_string()))
    }

    /// A reader for parameters without colours (RGB values in sRGB).
    pub fn plain(dict: &'a ParameterDictionary, loc: &'a FileLoc) -> Self {
        Self::with_color_space(dict, loc, RgbColorSpace::srgb())
    }

    /// The parameters as written.
    pub fn dict(&self) -> &'a ParameterDictionary {
        self.dict
    }

    /// Where the directive was.
    pub fn loc(&self) -> &'a FileLoc {
        self.loc
    }

    /// The colour space RGB values are in.
    pub fn color_space(&self) -> &'static RgbColorSpace {
        self.color_space
    }

    /// Where parameter `name` was written, or else the directive.
    pub fn param_loc(&self, name: &str) -> FileLoc {
        self.dict.loc(name).unwrap_or(self.loc).clone()
    }

    /// True when a parameter `name` was given (of any type).
    pub fn has(&self, name: &str) -> bool {
        self.dict.param_type(name).is_some()
    }

    /// The canonical type (`float`, `rgb`, `texture`...) of parameter
    /// `name`, if given.
    pub fn param_type(&self, name: &str) -> Option<&'a str> {
        self.dict
            .param_type(name)
            .map(|t| canonical_type(t).unwrap_or(t))
    }

    /// An error located at the directive.
    pub fn error(&self, msg: impl Into<String>) -> Diagnostic {
        Diagnostic::error(self.loc.clone(), msg)
    }

    /// An error located at parameter `name` (or the directive), with the
    /// message as given.
    pub fn error_at(&self, name: &str, msg: impl Into<String>) -> Diagnostic {
        Diagnostic::error(self.param_loc(name), msg)
    }

    /// An error about parameter `name`'s value: `parameter "name": msg`.
    pub fn invalid(&self, name: &str, msg: impl std::fmt::Display) -> Diagnostic {
        Diagnostic::error(self.param_loc(name), format!("parameter \"{name}\": {msg}"))
    }

    /// A warning located at the directive.
    pub fn warn(&self, msg: impl Into<String>) {
        self.warn_located(self.loc.clone(), msg);
    }

    /// A warning located at parameter `name` (or the directive).
    pub fn warn_at(&self, name: &str, msg: impl Into<String>) {
        self.warn_located(self.param_loc(name), msg);
    }

    /// A warning at `loc`.
    pub fn warn_located(&self, loc: FileLoc, msg: impl Into<String>) {
        self.warnings
            .borrow_mut()
            .push(Diagnostic::warning(loc, msg));
    }

    /// Adds diagnostics raised elsewhere (e.g. by a mesh loader) to the
    /// warnings.
    pub fn extend_warnings(&self, warnings: impl IntoIterator<Item = Diagnostic>) {
        self.warnings.borrow_mut().extend(warnings);
    }

    /// The warnings so far, without the unused-parameter check (for
    /// parameters several creators share, which are checked once at the
    /// end, and for creators that failed).
    pub fn take_warnings(&self) -> Vec<Diagnostic> {
        std::mem::take(&mut self.warnings.borrow_mut())
    }

    /// The warnings, then one for every parameter nothing read.
    pub fn finish(self) -> Vec<Diagnostic> {
        let mut w = self.warnings.into_inner();
        w.extend(self.dict.report_unused());
        w
    }

    /// `"float name"`, or `default`.
    pub fn float(&self, name: &str, default: f32) -> Result<f32, Diagnostic> {
        Ok(self.dict.get_one_float(name, default)?)
    }

    /// `"integer name"`, or `default`.
    pub fn int(&self, name: &str, default: i32) -> Result<i32, Diagnostic> {
        Ok(self.dict.get_one_int(name, default)?)
    }

    /// `"bool name"`, or `default`.
    pub fn bool(&self, name: &str, default: bool) -> Result<bool, Diagnostic> {
        Ok(self.dict.get_one_bool(name, default)?)
    }

    /// `"string name"`, or `default`.
    pub fn string(&self, name: &str, default: &str) -> Result<String, Diagnostic> {
        Ok(self.dict.get_one_string(name, default)?)
    }

    /// `"string name"`, if given.
    pub fn string_opt(&self, name: &str) -> Result<Option<String>, Diagnostic> {
        Ok(self.dict.get_one_string_opt(name)?)
    }

    /// `"point2 name"`, or `default`.
    pub fn point2(&self, name: &str, default: [f32; 2]) -> Result<[f32; 2], Diagnostic> {
        Ok(self.dict.get_one_point2(name, default)?)
    }

    /// `"point3 name"`, or `default`.
    pub fn point3(&self, name: &str, default: [f32; 3]) -> Result<[f32; 3], Diagnostic> {
        Ok(self.dict.get_one_point3(name, default)?)
    }

    /// `"vector3 name"`, or `default`.
    pub fn vector3(&self, name: &str, default: [f32; 3]) -> Result<[f32; 3], Diagnostic> {
        Ok(self.dict.get_one_vector3(name, default)?)
    }

    /// Every value of `"float name"` (empty when absent).
    pub fn floats(&self, name: &str) -> Result<Vec<f32>, Diagnostic> {
        Ok(self.dict.get_float_array(name)?)
    }

    /// Every triple of `"rgb name"` (empty when absent; negative
    /// components are an error).
    pub fn rgbs(&self, name: &str) -> Result<Vec<[f32; 3]>, Diagnostic> {
        Ok(self.dict.get_rgb_array(name)?)
    }

    /// Every value of `"integer name"` (empty when absent).
    pub fn ints(&self, name: &str) -> Result<Vec<i32>, Diagnostic> {
        Ok(self.dict.get_int_array(name)?)
    }

    /// Every value of `"string name"` (empty when absent).
    pub fn strings(&self, name: &str) -> Result<Vec<String>, Diagnostic> {
        Ok(self.dict.get_string_array(name)?)
    }

    /// Every value of `"point2 name"` (empty when absent).
    pub fn point2s(&self, name: &str) -> Result<Vec<[f32; 2]>, Diagnostic> {
        Ok(self.dict.get_point2_array(name)?)
    }

    /// Every value of `"point3 name"` (empty when absent).
    pub fn point3s(&self, name: &str) -> Result<Vec<[f32; 3]>, Diagnostic> {
        Ok(self.dict.get_point3_array(name)?)
    }

    /// Every value of `"vector3 name"` (empty when absent).
    pub fn vector3s(&self, name: &str) -> Result<Vec<[f32; 3]>, Diagnostic> {
        Ok(self.dict.get_vector3_array(name)?)
    }

    /// Every value of `"normal name"` (empty when absent).
    pub fn normals(&self, name: &str) -> Result<Vec<[f32; 3]>, Diagnostic> {
        Ok(self.dict.get_normal3_array(name)?)
    }

    /// The texture named by `"texture name"`, if given.
    pub fn texture_name(&self, name: &str) -> Result<Option<String>, Diagnostic> {
        Ok(self.dict.get_texture(name)?)
    }

    /// A spectrum given as `rgb` (in the reader's colour space),
    /// `blackbody` or `spectrum` (values, a named spectrum or a file next
    /// to the scene file), converted for use as `ty`; `None` when absent.
    pub fn spectrum(&self, name: &str, ty: SpectrumType) -> Result<Option<Spectrum>, Diagnostic> {
        self.spectrum_in(name, ty, self.color_space)
    }

    /// [`ParamReader::spectrum`] with RGB values in `cs`.
    pub fn spectrum_in(
        &self,
        name: &str,
        ty: SpectrumType,
        cs: &RgbColorSpace,
    ) -> Result<Option<Spectrum>, Diagnostic> {
        let Some(v) = self.dict.get_one_spectrum(name)? else {
            return Ok(None);
        };
        let loc = self.param_loc(name);
        spectrum_from_param(&v, ty, cs, dir_of_file(&loc.file))
            .map(Some)
            .map_err(|m| Diagnostic::error(loc, format!("parameter \"{name}\": {m}")))
    }

    /// `file` (a name written in parameter `name`) resolved against the
    /// directory of the scene file the parameter was written in (pbrt-v4
    /// `ResolveFilename`, with the including file's directory as the
    /// search directory): absolute names, and names not found there, are
    /// kept as written.
    pub fn resolve(&self, name: &str, file: &str) -> PathBuf {
        resolve_path(&self.param_loc(name).file, file)
    }

    /// `"string name"` as a file name resolved against the scene file it
    /// was written in; `None` when absent or empty.
    pub fn path(&self, name: &str) -> Result<Option<PathBuf>, Diagnostic> {
        let file = self.string(name, "")?;
        Ok((!file.is_empty()).then(|| self.resolve(name, &file)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rpbrt_parser::ParsedParameter;
    use std::sync::Arc;

    fn loc(file: &str, line: u32, col: u32) -> FileLoc {
        FileLoc::new(Arc::from(file), line, col)
    }

    fn dict() -> ParameterDictionary {
        ParameterDictionary::new(vec![
            ParsedParameter::with_floats("float", "radius", loc("dir/a.pbrt", 3, 7), vec![2.0]),
            ParsedParameter::with_strings(
                "string",
                "filename",
                loc("dir/sub/b.pbrt", 9, 2),
                vec!["tex.png".into()],
            ),
            ParsedParameter::with_floats("float", "raduis", loc("dir/a.pbrt", 4, 1), vec![1.0]),
        ])
    }

    #[test]
    fn reads_values_and_reports_what_was_not_read() {
        let d = dict();
        let at = loc("dir/a.pbrt", 3, 1);
        let r = ParamReader::plain(&d, &at);
        assert_eq!(r.float("radius", 1.0).unwrap(), 2.0);
        assert_eq!(r.float("zmin", -1.0).unwrap(), -1.0);
        // Paths resolve against the file the parameter was written in
        // when the file is there, else stay as written.
        assert_eq!(r.path("filename").unwrap(), Some(PathBuf::from("tex.png")));
        r.warn_at("radius", "a warning");
        let w = r.finish();
        assert_eq!(w.len(), 2, "{w:?}");
        assert_eq!(w[0].loc, Some(loc("dir/a.pbrt", 3, 7)));
        assert_eq!(w[1].loc, Some(loc("dir/a.pbrt", 4, 1)));
        assert!(w[1].message.contains("\"raduis\""), "{}", w[1].message);
    }

    #[test]
    fn paths_resolve_against_the_including_file() {
        let dir = std::env::temp_dir().join(format!("rpbrt-params-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        std::fs::write(dir.join("sub/t.png"), b"x").unwrap();
        let scene = dir.join("sub/scene.pbrt");
        let scene = scene.to_str().unwrap();
        assert_eq!(resolve_path(scene, "t.png"), dir.join("sub/t.png"));
        assert_eq!(
            resolve_path(scene, "missing.png"),
            PathBuf::from("missing.png")
        );
        assert_eq!(
            resolve_path(scene, "/abs/x.png"),
            PathBuf::from("/abs/x.png")
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn errors_are_located_at_the_parameter() {
        let d = dict();
        let at = loc("dir/a.pbrt", 3, 1);
        let r = ParamReader::plain(&d, &at);
        let e = r.int("radius", 0).unwrap_err();
        assert_eq!(e.loc, Some(loc("dir/a.pbrt", 3, 7)));
        let e = r.invalid("radius", "must be positive");
        assert_eq!(e.message, "parameter \"radius\": must be positive");
        assert_eq!(r.error_at("absent", "x").loc, Some(at.clone()));
        assert!(ParamReader::new(&d, &at, "nosuchspace").is_err());
    }

    #[test]
    fn unknown_type_lists_the_known_ones() {
        let at = loc("a.pbrt", 1, 2);
        let e = unknown_type("shape", "sphre", &["disk", "sphere"], &at);
        assert_eq!(
            e.message,
            "\"sphre\": unknown shape type; expected one of \"disk\", \"sphere\""
        );
        assert_eq!(e.loc, Some(at));
    }
}
