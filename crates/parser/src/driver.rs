//! The parser driver: reads files (gzip-aware), follows `Include`/`Import`
//! relative to the including file, turns tokens into directive calls on a
//! [`ParserTarget`] and collects diagnostics (pbrt-v4 `parser.cpp`,
//! `parse`, `ParseFiles`, `ParseString`; book section C.2).
//!
//! Parsing is a flat loop over tokens with an explicit file stack, so deep
//! nesting or long files cannot overflow the call stack. After an error the
//! parser skips to the next directive keyword and continues, stopping after
//! [`ParseOptions::max_errors`] errors.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::budget::MemoryBudget;
use crate::diag::{Diagnostic, Diagnostics, Severity};
use crate::input;
use crate::loc::FileLoc;
use crate::params::{split_declaration, value_kind, ParsedParameter, ValueKind};
use crate::target::{IncludeKind, ParserTarget};
use crate::tokenizer::SourceText;
use crate::tokenizer::{escape_string, Token, TokenKind, Tokenizer};

/// Limits and settings for one parse.
#[derive(Clone, Debug)]
pub struct ParseOptions {
    /// Stop after this many errors (a note says so).
    pub max_errors: usize,
    /// Keep at most this many warnings (a note says how many were dropped).
    pub max_warnings: usize,
    /// Maximum `Include` nesting depth.
    pub max_include_depth: usize,
    /// Maximum number of values in one parameter.
    pub max_values: usize,
    /// Largest file (after decompression) the parser will read, in bytes.
    pub max_file_bytes: u64,
    /// Parse `Import`ed files on threads of their own (pbrt-v4 does);
    /// `false` parses them in place. The target sees the same directives
    /// in the same order either way.
    pub parallel_import: bool,
    /// The memory budget scene text is charged to while it is parsed
    /// (shared with whatever builds the scene from it).
    pub budget: MemoryBudget,
}

impl Default for ParseOptions {
    fn default() -> Self {
        ParseOptions {
            max_errors: 20,
            max_warnings: 1000,
            max_include_depth: 64,
            max_values: 1 << 30,
            max_file_bytes: input::DEFAULT_MAX_SCENE_FILE_BYTES,
            parallel_import: true,
            budget: MemoryBudget::default(),
        }
    }
}

/// Reads a scene file, decompressing it when it starts with the gzip magic
/// bytes (whatever its extension), with the default size limit
/// ([`input::DEFAULT_MAX_SCENE_FILE_BYTES`]).
pub fn read_scene_file(path: impl AsRef<Path>) -> std::io::Result<Vec<u8>> {
    input::read_file_limited(path, input::DEFAULT_MAX_SCENE_FILE_BYTES)
}

/// Parses the given files in order, then calls `end_of_files`.
///
/// `Ok` carries the warnings; `Err` carries every diagnostic when at least
/// one error was reported (by the parser or by the target).
pub fn parse_files<P: AsRef<Path>>(
    paths: &[P],
    target: &mut dyn ParserTarget,
) -> Result<Diagnostics, Diagnostics> {
    Parser::new(ParseOptions::default()).parse_files(paths, target)
}

/// Parses scene text held in memory (reported as `<string>`, includes
/// resolved against the current directory), then calls `end_of_files`.
pub fn parse_string(text: &str, target: &mut dyn ParserTarget) -> Result<Diagnostics, Diagnostics> {
    Parser::new(ParseOptions::default()).parse_bytes(
        "<string>",
        Arc::new(text.as_bytes().to_vec()),
        Path::new("."),
        target,
    )
}

/// A parser with explicit [`ParseOptions`].
#[derive(Clone, Debug, Default)]
pub struct Parser {
    /// The limits used.
    pub options: ParseOptions,
}

impl Parser {
    /// A parser with the given options.
    pub fn new(options: ParseOptions) -> Self {
        Parser { options }
    }

    /// See [`parse_files`].
    pub fn parse_files<P: AsRef<Path>>(
        &self,
        paths: &[P],
        target: &mut dyn ParserTarget,
    ) -> Result<Diagnostics, Diagnostics> {
        let mut run = Run::new(&self.options, target);
        for path in paths {
            if run.stopped {
                break;
            }
            let path = path.as_ref();
            match run.open(path, false) {
                Ok(src) => {
                    run.push(src);
                    run.run();
                }
                Err(msg) => {
                    run.input_missing = true;
                    run.report(Diagnostic::unlocated_error(msg));
                }
            }
        }
        run.finish()
    }

    /// Parses `data` as a file called `name`, resolving includes against `dir`.
    pub fn parse_bytes(
        &self,
        name: &str,
        data: SourceText,
        dir: &Path,
        target: &mut dyn ParserTarget,
    ) -> Result<Diagnostics, Diagnostics> {
        let mut run = Run::new(&self.options, target);
        run.push(Source {
            tok: Tokenizer::new(Arc::from(name), data),
            dir: dir.to_path_buf(),
            canon: None,
        });
        run.run();
        run.finish()
    }
}

struct Source {
    tok: Tokenizer,
    dir: PathBuf,
    canon: Option<PathBuf>,
}

/// An error was reported; abandon the directive and resynchronize.
struct Abort;

type P<T> = Result<T, Abort>;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Directive {
    Accelerator,
    ActiveTransform,
    AreaLightSource,
    Attribute,
    AttributeBegin,
    AttributeEnd,
    Camera,
    ColorSpace,
    ConcatTransform,
    CoordSysTransform,
    CoordinateSystem,
    Film,
    Identity,
    Import,
    Include,
    Integrator,
    LightSource,
    LookAt,
    MakeNamedMaterial,
    MakeNamedMedium,
    Material,
    MediumInterface,
    NamedMaterial,
    ObjectBegin,
    ObjectEnd,
    ObjectInstance,
    Option,
    PixelFilter,
    Renderer,
    ReverseOrientation,
    Rotate,
    Sampler,
    Scale,
    SearchPath,
    Shape,
    SurfaceIntegrator,
    Texture,
    Transform,
    TransformBegin,
    TransformEnd,
    TransformTimes,
    Translate,
    Volume,
    VolumeIntegrator,
    WorldBegin,
    WorldEnd,
}

const DIRECTIVES: &[(&str, Directive)] = &[
    ("Accelerator", Directive::Accelerator),
    ("ActiveTransform", Directive::ActiveTransform),
    ("AreaLightSource", Directive::AreaLightSource),
    ("Attribute", Directive::Attribute),
    ("AttributeBegin", Directive::AttributeBegin),
    ("AttributeEnd", Directive::AttributeEnd),
    ("Camera", Directive::Camera),
    ("ColorSpace", Directive::ColorSpace),
    ("ConcatTransform", Directive::ConcatTransform),
    ("CoordSysTransform", Directive::CoordSysTransform),
    ("CoordinateSystem", Directive::CoordinateSystem),
    ("Film", Directive::Film),
    ("Identity", Directive::Identity),
    ("Import", Directive::Import),
    ("Include", Directive::Include),
    ("Integrator", Directive::Integrator),
    ("LightSource", Directive::LightSource),
    ("LookAt", Directive::LookAt),
    ("MakeNamedMaterial", Directive::MakeNamedMaterial),
    ("MakeNamedMedium", Directive::MakeNamedMedium),
    ("Material", Directive::Material),
    ("MediumInterface", Directive::MediumInterface),
    ("NamedMaterial", Directive::NamedMaterial),
    ("ObjectBegin", Directive::ObjectBegin),
    ("ObjectEnd", Directive::ObjectEnd),
    ("ObjectInstance", Directive::ObjectInstance),
    ("Option", Directive::Option),
    ("PixelFilter", Directive::PixelFilter),
    ("Renderer", Directive::Renderer),
    ("ReverseOrientation", Directive::ReverseOrientation),
    ("Rotate", Directive::Rotate),
    ("Sampler", Directive::Sampler),
    ("Scale", Directive::Scale),
    ("SearchPath", Directive::SearchPath),
    ("Shape", Directive::Shape),
    ("SurfaceIntegrator", Directive::SurfaceIntegrator),
    ("Texture", Directive::Texture),
    ("Transform", Directive::Transform),
    ("TransformBegin", Directive::TransformBegin),
    ("TransformEnd", Directive::TransformEnd),
    ("TransformTimes", Directive::TransformTimes),
    ("Translate", Directive::Translate),
    ("Volume", Directive::Volume),
    ("VolumeIntegrator", Directive::VolumeIntegrator),
    ("WorldBegin", Directive::WorldBegin),
    ("WorldEnd", Directive::WorldEnd),
];

/// For each upper-case first letter, the range of [`DIRECTIVES`] (sorted)
/// whose names start with it.
const BY_FIRST_LETTER: [(u8, u8); 26] = {
    let mut t = [(0u8, 0u8); 26];
    let mut k = 0;
    while k < DIRECTIVES.len() {
        let c = (DIRECTIVES[k].0.as_bytes()[0] - b'A') as usize;
        if t[c].1 == 0 {
            t[c].0 = k as u8;
        }
        t[c].1 = k as u8 + 1;
        k += 1;
    }
    t
};

fn lookup_directive(word: &[u8]) -> Option<Directive> {
    // Directive names start with an upper-case letter; numbers (the common
    // case inside meshes) are rejected by the first byte. Then only the
    // names with that first letter (at most six) are compared, length
    // first: this runs for every word of a scene.
    let first = *word.first()?;
    if !first.is_ascii_uppercase() {
        return None;
    }
    let (a, b) = BY_FIRST_LETTER[(first - b'A') as usize];
    DIRECTIVES[a as usize..b as usize]
        .iter()
        .find(|(n, _)| n.len() == word.len() && n.as_bytes() == word)
        .map(|&(_, d)| d)
}

/// Names of all directives the parser knows, for suggestions and tools.
pub fn directive_names() -> impl Iterator<Item = &'static str> {
    DIRECTIVES.iter().map(|(n, _)| *n)
}

fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, &cb) in b.iter().enumerate() {
            let cost = usize::from(ca != cb);
            cur[j + 1] = (prev[j] + cost).min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

/// The known directive closest to `word`, if it is close enough to be a typo.
fn suggest(word: &str) -> Option<&'static str> {
    if word.len() > 40 {
        return None;
    }
    let lower = word.to_ascii_lowercase();
    directive_names()
        .map(|n| (edit_distance(&lower, &n.to_ascii_lowercase()), n))
        .filter(|&(d, n)| d <= 2.max(n.len() / 5))
        .min_by_key(|&(d, _)| d)
        .map(|(_, n)| n)
}

struct Run<'a> {
    opts: &'a ParseOptions,
    target: &'a mut dyn ParserTarget,
    stack: Vec<Source>,
    unget: Option<Token>,
    diags: Diagnostics,
    errors: usize,
    warnings: usize,
    dropped_warnings: usize,
    stopped: bool,
    /// A scene file named on the command line could not be opened: the
    /// scene is incomplete, so its end is not checked (an "end of files
    /// before WorldBegin" would only repeat that the file is missing).
    input_missing: bool,
    warned_transform_begin: bool,
    kept: HashSet<Arc<str>>,
    /// Whether the target wants comments.
    comments: bool,
    /// Comments read but not yet handed to the target: all of them were
    /// read before the next directive keyword.
    pending_comments: Vec<(FileLoc, String)>,
    /// Canonical paths of the files that `Import`ed this run's file (for
    /// cycle checks and the nesting limit).
    ancestors: Vec<PathBuf>,
    /// After the first `Import`: the imports and the directives between
    /// them, delivered to the target in order once parsing is done.
    deferred: Vec<import::Segment>,
    /// This run parses an imported file for another run.
    is_import: bool,
    /// Files read whose directives are delivered later (deferred, or parsed
    /// for an import): kept until it is known whether a diagnostic points
    /// into them.
    held: Vec<(Arc<str>, SourceText)>,
    /// Bytes of scene text charged to the budget, given back when the
    /// parse ends.
    text_charged: u64,
    /// Room for a directive's parameters as they are read.
    params_scratch: Vec<ParsedParameter>,
    /// Room for a parameter's declaration as it is read.
    decl_scratch: String,
}

impl<'a> Run<'a> {
    fn new(opts: &'a ParseOptions, target: &'a mut dyn ParserTarget) -> Self {
        let comments = target.wants_comments();
        Run {
            opts,
            target,
            stack: Vec::new(),
            unget: None,
            diags: Diagnostics::new(),
            errors: 0,
            warnings: 0,
            dropped_warnings: 0,
            stopped: false,
            input_missing: false,
            warned_transform_begin: false,
            kept: HashSet::new(),
            comments,
            pending_comments: Vec::new(),
            ancestors: Vec::new(),
            deferred: Vec::new(),
            is_import: false,
            held: Vec::new(),
            text_charged: 0,
            params_scratch: Vec::new(),
            decl_scratch: String::new(),
        }
    }

    /// Where directives go: the target, or after an `Import` the recorder
    /// of the directives that follow it.
    fn sink(&mut self) -> &mut dyn ParserTarget {
        match self.deferred.last_mut() {
            Some(import::Segment::Main(r)) => r,
            _ => &mut *self.target,
        }
    }

    /// Moves the comments the current file's tokenizer has seen to the
    /// pending list.
    fn collect_comments(&mut self) {
        if self.comments {
            if let Some(src) = self.stack.last_mut() {
                self.pending_comments.extend(src.tok.take_comments());
            }
        }
    }

    /// Hands the pending comments to the target.
    fn flush_comments(&mut self) {
        for (loc, text) in std::mem::take(&mut self.pending_comments) {
            let r = self.target.comment(&text, loc);
            self.drain(r);
        }
    }

    fn report(&mut self, d: Diagnostic) {
        if self.stopped {
            return;
        }
        match d.severity {
            Severity::Warning => {
                if self.warnings >= self.opts.max_warnings {
                    self.dropped_warnings += 1;
                    return;
                }
                self.warnings += 1;
            }
            Severity::Error => self.errors += 1,
        }
        self.diags.push(d);
        if self.errors >= self.opts.max_errors {
            self.diags.push(Diagnostic::unlocated_error(format!(
                "too many errors ({}); stopping",
                self.errors
            )));
            self.stopped = true;
        }
    }

    fn finish(mut self) -> Result<Diagnostics, Diagnostics> {
        if !self.stopped {
            self.replay_deferred();
        }
        if !self.stopped && !self.input_missing {
            self.flush_comments();
            let r = self.target.end_of_files();
            self.drain(r);
        }
        while let Some(src) = self.stack.pop() {
            self.keep_source(&src);
        }
        // An import hands all its files up; the importer keeps those that
        // diagnostics point into.
        for (name, data) in std::mem::take(&mut self.held) {
            let referenced = self
                .diags
                .items
                .iter()
                .any(|d| d.loc.as_ref().is_some_and(|l| l.file == name));
            if self.is_import || referenced {
                self.diags.sources.insert(name, data);
            }
        }
        if self.dropped_warnings > 0 {
            self.diags.push(Diagnostic {
                severity: Severity::Warning,
                loc: None,
                message: format!("{} more warnings not shown", self.dropped_warnings),
            });
        }
        // The text is dropped with the run (but for the few files that
        // diagnostics quote).
        self.opts.budget.release(self.text_charged);
        if self.diags.has_errors() {
            Err(self.diags)
        } else {
            Ok(self.diags)
        }
    }

    /// Keeps a file's text for rendering if a diagnostic points into it.
    fn keep_source(&mut self, src: &Source) {
        let name = src.tok.file_name();
        if self.kept.contains(name) {
            return;
        }
        let referenced = self
            .diags
            .items
            .iter()
            .any(|d| d.loc.as_ref().is_some_and(|l| l.file == *name));
        if referenced {
            self.kept.insert(name.clone());
            self.diags
                .sources
                .insert(name.clone(), src.tok.data().clone());
        } else if self.is_import || !self.deferred.is_empty() {
            self.held.push((name.clone(), src.tok.data().clone()));
        }
    }

    fn drain(&mut self, r: Result<(), Diagnostic>) {
        if let Err(d) = r {
            self.report(d);
        }
        for d in self.target.take_diagnostics() {
            self.report(d);
        }
    }

    /// Reads the scene file `path` whole. An included (or imported) file
    /// must be a regular file: a device or FIFO named by a scene (say
    /// `/dev/zero`) would otherwise be read up to the size limit. Files
    /// named on the command line may be pipes (`rpbrt /dev/stdin`), bounded
    /// by the limit alone.
    ///
    /// The text is charged to the memory budget while the parse runs: a
    /// file is read no further than the budget has room for.
    fn open(&mut self, path: &Path, included: bool) -> Result<Source, String> {
        if included {
            match std::fs::metadata(path) {
                Ok(m) if !m.is_file() => {
                    return Err(format!("{}: not a regular file", path.display()));
                }
                // A missing file is reported by the read below.
                _ => {}
            }
        }
        let budget = &self.opts.budget;
        let room = budget.available();
        let limit = self.opts.max_file_bytes.min(room);
        let what = "this scene file";
        let data = input::read_file_limited(path, limit).map_err(|e| {
            if input::is_too_large(&e) && limit == room {
                format!("{}: {}", path.display(), budget.exceeded(room, what))
            } else {
                format!("{}: {e}", path.display())
            }
        })?;
        budget
            .charge(data.len() as u64, what)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        self.text_charged += data.len() as u64;
        let dir = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        Ok(Source {
            tok: Tokenizer::new(Arc::from(path.display().to_string()), Arc::new(data)),
            dir,
            canon: std::fs::canonicalize(path).ok(),
        })
    }

    fn push(&mut self, mut src: Source) {
        if let Some(d) = src.tok.check_encoding() {
            self.report(d);
            self.keep_source(&src);
            return;
        }
        // Comments read so far in the including file precede this one's.
        self.collect_comments();
        src.tok.set_keep_comments(self.comments);
        self.stack.push(src);
    }

    fn cur(&self) -> Option<&Tokenizer> {
        self.stack.last().map(|s| &s.tok)
    }

    fn loc(&self, t: &Token) -> FileLoc {
        match self.cur() {
            Some(tk) => tk.loc(t),
            None => FileLoc::new(Arc::from("<eof>"), t.line, t.column),
        }
    }

    fn raw(&self, t: &Token) -> &[u8] {
        self.cur().map_or(&[], |tk| tk.raw(t))
    }

    fn display(&self, t: &Token) -> String {
        self.cur().map_or_else(String::new, |tk| tk.display(t))
    }

    /// The next token across the file stack; `Ok(None)` when all files are done.
    fn next(&mut self) -> P<Option<Token>> {
        if let Some(t) = self.unget.take() {
            return Ok(Some(t));
        }
        loop {
            let Some(src) = self.stack.last_mut() else {
                return Ok(None);
            };
            let r = src.tok.next_token();
            self.collect_comments();
            match r {
                Ok(Some(t)) => return Ok(Some(t)),
                Ok(None) => {
                    if let Some(src) = self.stack.pop() {
                        self.keep_source(&src);
                    }
                }
                Err(d) => {
                    self.report(d);
                    return Err(Abort);
                }
            }
        }
    }

    /// The next token, which must exist; `what` describes it for the error.
    fn next_required(&mut self, what: &str, at: &FileLoc) -> P<Token> {
        match self.next()? {
            Some(t) => Ok(t),
            None => {
                self.report(Diagnostic::error(
                    at.clone(),
                    format!("premature end of file: expected {what}"),
                ));
                Err(Abort)
            }
        }
    }

    /// Reports `msg` at `t` and puts `t` back so that a directive keyword
    /// there is not lost to resynchronization.
    fn fail_at(&mut self, t: Token, msg: String) -> Abort {
        let loc = self.loc(&t);
        self.report(Diagnostic::error(loc, msg));
        if t.kind == TokenKind::Word {
            self.unget = Some(t);
        }
        Abort
    }

    /// Skips tokens up to the next directive keyword (left unread).
    fn resync(&mut self) {
        while !self.stopped {
            match self.next() {
                Ok(None) => return,
                Ok(Some(t)) => {
                    if t.kind == TokenKind::Word && lookup_directive(self.raw(&t)).is_some() {
                        self.unget = Some(t);
                        return;
                    }
                }
                Err(Abort) => {}
            }
        }
    }

    fn run(&mut self) {
        while !self.stopped {
            let t = match self.next() {
                Ok(Some(t)) => t,
                Ok(None) => return,
                Err(Abort) => {
                    self.resync();
                    continue;
                }
            };
            // Every comment read so far was read before this token.
            self.flush_comments();
            let loc = self.loc(&t);
            let directive = if t.kind == TokenKind::Word {
                lookup_directive(self.raw(&t))
            } else {
                None
            };
            let Some(directive) = directive else {
                let shown = self.display(&t);
                let msg = if t.kind == TokenKind::Word {
                    match suggest(&shown) {
                        Some(s) => format!("unknown directive \"{shown}\"; did you mean \"{s}\"?"),
                        None => format!("unknown directive \"{shown}\""),
                    }
                } else {
                    format!("expected a directive, found {shown}")
                };
                self.report(Diagnostic::error(loc, msg));
                self.resync();
                continue;
            };
            match self.directive(directive, loc) {
                Ok(r) => self.drain(r),
                Err(Abort) => self.resync(),
            }
            // Past the memory budget nothing more fits: the first error
            // says where, and the parse ends there.
            if self.opts.budget.exhausted() && self.errors > 0 {
                self.stopped = true;
            }
        }
    }

    fn float(&mut self, at: &FileLoc) -> P<f32> {
        let t = self.next_required("a number", at)?;
        match self.cur().map(|tk| tk.parse_float(&t)) {
            Some(Ok(v)) => Ok(v),
            Some(Err(d)) => {
                let msg = d.message;
                Err(self.fail_at(t, msg))
            }
            None => Err(Abort),
        }
    }

    fn floats<const N: usize>(&mut self, at: &FileLoc) -> P<[f32; N]> {
        let mut v = [0.0; N];
        for x in &mut v {
            *x = self.float(at)?;
        }
        Ok(v)
    }

    /// 16 numbers, in brackets (pbrt-v4) or bare.
    fn matrix(&mut self, at: &FileLoc) -> P<[f32; 16]> {
        let t = self.next_required("'[' and 16 numbers", at)?;
        let bracketed = t.kind == TokenKind::LBracket;
        if !bracketed {
            self.unget = Some(t);
        }
        let m = self.floats::<16>(at)?;
        if bracketed {
            let t = self.next_required("']'", at)?;
            if t.kind != TokenKind::RBracket {
                let shown = self.display(&t);
                return Err(self.fail_at(
                    t,
                    format!("expected ']' after 16 matrix values, found {shown}"),
                ));
            }
        }
        Ok(m)
    }

    fn string_of(&mut self, t: Token) -> P<String> {
        match self
            .cur()
            .map(|tk| tk.string_value(&t).map(|s| s.into_owned()))
        {
            Some(Ok(s)) => Ok(s),
            Some(Err(d)) => {
                self.report(d);
                Err(Abort)
            }
            None => Err(Abort),
        }
    }

    /// [`Run::string_of`] into `out` (its room reused).
    fn string_into(&mut self, t: Token, out: &mut String) -> P<()> {
        let read = self.cur().map(|tk| {
            tk.string_value(&t).map(|s| {
                out.clear();
                out.push_str(&s);
            })
        });
        match read {
            Some(Ok(())) => Ok(()),
            Some(Err(d)) => {
                self.report(d);
                Err(Abort)
            }
            None => Err(Abort),
        }
    }

    fn quoted(&mut self, what: &str, at: &FileLoc) -> P<String> {
        let t = self.next_required(what, at)?;
        if !t.is_string() {
            let shown = self.display(&t);
            return Err(self.fail_at(
                t,
                format!("expected {what} (a quoted string), found {shown}"),
            ));
        }
        self.string_of(t)
    }

    /// The parameters that follow a directive, in a list of exactly their
    /// number (it is kept with the scene's entity: no room to spare, and
    /// none to give back), gathered in room kept from directive to
    /// directive.
    fn params(&mut self) -> P<Vec<ParsedParameter>> {
        let mut gathered = std::mem::take(&mut self.params_scratch);
        let mut decl = std::mem::take(&mut self.decl_scratch);
        let r = self.params_into(&mut gathered, &mut decl);
        // Drained, not taken: a new list of exactly their number, the
        // kept room staying here.
        #[allow(clippy::drain_collect)]
        let out: Vec<ParsedParameter> = gathered.drain(..).collect();
        self.params_scratch = gathered;
        self.decl_scratch = decl;
        r.map(|()| out)
    }

    /// [`Run::params`] into `out`; `decl_buf` holds each declaration.
    fn params_into(&mut self, out: &mut Vec<ParsedParameter>, decl_buf: &mut String) -> P<()> {
        loop {
            let Some(t) = self.next()? else {
                return Ok(());
            };
            if !t.is_string() {
                self.unget = Some(t);
                return Ok(());
            }
            let loc = self.loc(&t);
            self.string_into(t, decl_buf)?;
            let decl: &str = decl_buf;
            let (ty, name) = match split_declaration(decl) {
                Ok(x) => x,
                Err(msg) => {
                    self.report(Diagnostic::error(loc, msg));
                    return Err(Abort);
                }
            };
            let kind = value_kind(ty);
            if kind.is_none() {
                self.report(Diagnostic::error(
                    loc.clone(),
                    format!("unknown parameter type \"{ty}\" in \"{decl}\""),
                ));
            }
            let mut p = ParsedParameter::new(ty, name, loc.clone());
            // (Not `next_required`: its message would be formatted for
            // every parameter.)
            let Some(first) = self.next()? else {
                self.report(Diagnostic::error(
                    loc.clone(),
                    format!("premature end of file: expected a value for \"{decl}\""),
                ));
                return Err(Abort);
            };
            match first.kind {
                TokenKind::LBracket => {
                    let open = self.loc(&first);
                    if matches!(kind, Some(ValueKind::Float | ValueKind::Int))
                        && self.fast_numbers(&mut p)?
                    {
                        out.push(p);
                        continue;
                    }
                    loop {
                        let Some(v) = self.next()? else {
                            self.report(Diagnostic::error(
                                open,
                                format!("unterminated '[' in the values of \"{decl}\""),
                            ));
                            return Err(Abort);
                        };
                        if v.kind == TokenKind::RBracket {
                            break;
                        }
                        if v.kind == TokenKind::LBracket {
                            return Err(self.fail_at(
                                v,
                                format!("unexpected '[' inside the values of \"{decl}\""),
                            ));
                        }
                        self.add_value(&mut p, kind, v, decl, Some(&open))?;
                        if p.value_count() > self.opts.max_values {
                            self.report(Diagnostic::error(
                                loc,
                                format!("\"{decl}\" has more than {} values", self.opts.max_values),
                            ));
                            return Err(Abort);
                        }
                    }
                }
                TokenKind::RBracket => {
                    return Err(self.fail_at(first, format!("unexpected ']' after \"{decl}\"")));
                }
                _ => self.add_value(&mut p, kind, first, decl, None)?,
            }
            if kind.is_some() {
                out.push(p);
            }
        }
    }

    /// The hot path for long numeric arrays: reads numbers straight from
    /// the tokenizer. Returns `true` after the closing `]`; `false` when it
    /// met anything else, which is left for the general loop (and its
    /// error reporting) to handle.
    fn fast_numbers(&mut self, p: &mut ParsedParameter) -> P<bool> {
        if self.unget.is_some() {
            return Ok(false);
        }
        let Some(src) = self.stack.last_mut() else {
            return Ok(false);
        };
        let tk = &mut src.tok;
        let ints = p.canonical_type() == "integer";
        let max = self.opts.max_values;
        loop {
            let t = match tk.next_token() {
                Ok(Some(t)) => t,
                Ok(None) => return Ok(false),
                Err(d) => {
                    self.report(d);
                    return Err(Abort);
                }
            };
            match t.kind {
                TokenKind::Word => {
                    let raw = tk.raw(&t);
                    let ok = if ints {
                        crate::tokenizer::parse_i32(raw)
                            .map(|v| p.ints.push(v))
                            .is_ok()
                    } else {
                        match crate::tokenizer::parse_f32(raw) {
                            Some(v) if v.is_finite() => {
                                p.floats.push(v);
                                true
                            }
                            _ => false,
                        }
                    };
                    if !ok || p.floats.len() + p.ints.len() > max {
                        if ok {
                            p.floats.pop();
                            p.ints.pop();
                        }
                        self.unget = Some(t);
                        return Ok(false);
                    }
                }
                TokenKind::RBracket => return Ok(true),
                _ => {
                    self.unget = Some(t);
                    return Ok(false);
                }
            }
        }
    }

    fn add_value(
        &mut self,
        p: &mut ParsedParameter,
        kind: Option<ValueKind>,
        t: Token,
        decl: &str,
        open: Option<&FileLoc>,
    ) -> P<()> {
        let Some(kind) = kind else {
            return Ok(()); // unknown type, already reported: skip values
        };
        let Some(tk) = self.cur() else {
            return Err(Abort);
        };
        let res = match (kind, t.kind) {
            (ValueKind::Float, TokenKind::Word) => tk.parse_float(&t).map(|v| p.floats.push(v)),
            (ValueKind::Spectrum, TokenKind::Word) if p.strings.is_empty() => {
                tk.parse_float(&t).map(|v| p.floats.push(v))
            }
            (ValueKind::Int, TokenKind::Word) => tk.parse_int(&t).map(|v| p.ints.push(v)),
            (ValueKind::Bool, _) => match tk.raw(&t) {
                b"true" => {
                    p.bools.push(true);
                    Ok(())
                }
                b"false" => {
                    p.bools.push(false);
                    Ok(())
                }
                _ => Err(Diagnostic::error(
                    tk.loc(&t),
                    format!("{}: expected true or false for \"{decl}\"", tk.display(&t)),
                )),
            },
            (ValueKind::String, TokenKind::Str { .. }) => {
                tk.string_value(&t).map(|s| p.strings.push(s.into_owned()))
            }
            (ValueKind::Spectrum, TokenKind::Str { .. }) if p.floats.is_empty() => {
                tk.string_value(&t).map(|s| p.strings.push(s.into_owned()))
            }
            (ValueKind::String, _) => Err(Diagnostic::error(
                tk.loc(&t),
                format!(
                    "{}: expected a quoted string for \"{decl}\"",
                    tk.display(&t)
                ),
            )),
            (ValueKind::Spectrum, _) => Err(Diagnostic::error(
                tk.loc(&t),
                format!(
                    "{}: \"{decl}\" mixes numbers and spectrum names",
                    tk.display(&t)
                ),
            )),
            (_, _) => Err(Diagnostic::error(
                tk.loc(&t),
                format!("{}: expected a number for \"{decl}\"", tk.display(&t)),
            )),
        };
        match res {
            Ok(()) => Ok(()),
            Err(mut d) => {
                // A directive keyword inside brackets means a missing ']'.
                if let Some(open) = open {
                    if t.kind == TokenKind::Word && lookup_directive(tk.raw(&t)).is_some() {
                        d = Diagnostic::error(
                            open.clone(),
                            format!("missing ']' to close the values of \"{decl}\""),
                        );
                    }
                }
                self.report(d);
                if t.kind == TokenKind::Word {
                    self.unget = Some(t);
                }
                Err(Abort)
            }
        }
    }

    fn include(&mut self, name: &str, kind: IncludeKind, loc: &FileLoc) {
        match self.target.include(name, kind, loc.clone()) {
            Ok(true) => {}
            Ok(false) => return,
            Err(d) => {
                self.report(d);
                return;
            }
        }
        if self.stack.len() + self.ancestors.len() >= self.opts.max_include_depth {
            self.report(Diagnostic::error(
                loc.clone(),
                format!(
                    "\"{name}\": includes nested more than {} deep",
                    self.opts.max_include_depth
                ),
            ));
            return;
        }
        let rel = Path::new(name);
        let path = match self.stack.last() {
            Some(s) if rel.is_relative() => s.dir.join(rel),
            _ => rel.to_path_buf(),
        };
        let canon = std::fs::canonicalize(&path).ok();
        if let Some(canon) = &canon {
            let in_stack = self.stack.iter().any(|s| s.canon.as_ref() == Some(canon));
            if in_stack || self.ancestors.contains(canon) {
                let chain: Vec<String> = self
                    .ancestors
                    .iter()
                    .map(|p| p.display().to_string())
                    .chain(self.stack.iter().map(|s| s.tok.file_name().to_string()))
                    .collect();
                self.report(Diagnostic::error(
                    loc.clone(),
                    format!(
                        "include cycle: \"{}\" is already being read (via {})",
                        path.display(),
                        chain.join(" -> ")
                    ),
                ));
                return;
            }
        }
        if kind == IncludeKind::Import {
            self.start_import(path, canon, loc);
            return;
        }
        match self.open(&path, true) {
            Ok(src) => self.push(src),
            Err(msg) => self.report(Diagnostic::error(loc.clone(), format!("cannot read {msg}"))),
        }
    }

    fn directive(&mut self, d: Directive, loc: FileLoc) -> P<Result<(), Diagnostic>> {
        use Directive as D;
        let l = loc.clone();
        Ok(match d {
            D::Identity => self.sink().identity(loc),
            D::Translate => {
                let v = self.floats::<3>(&l)?;
                self.sink().translate(v, loc)
            }
            D::Scale => {
                let v = self.floats::<3>(&l)?;
                self.sink().scale(v, loc)
            }
            D::Rotate => {
                let v = self.floats::<4>(&l)?;
                self.sink().rotate(v[0], [v[1], v[2], v[3]], loc)
            }
            D::LookAt => {
                let v = self.floats::<9>(&l)?;
                self.sink().look_at(
                    [v[0], v[1], v[2]],
                    [v[3], v[4], v[5]],
                    [v[6], v[7], v[8]],
                    loc,
                )
            }
            D::ConcatTransform => {
                let m = self.matrix(&l)?;
                self.sink().concat_transform(m, loc)
            }
            D::Transform => {
                let m = self.matrix(&l)?;
                self.sink().transform(m, loc)
            }
            D::CoordinateSystem => {
                let n = self.quoted("a coordinate system name", &l)?;
                self.sink().coordinate_system(&n, loc)
            }
            D::CoordSysTransform => {
                let n = self.quoted("a coordinate system name", &l)?;
                self.sink().coord_sys_transform(&n, loc)
            }
            D::SearchPath => {
                let n = self.quoted("a search path", &l)?;
                self.sink().search_path(&n, loc)
            }
            D::ActiveTransform => {
                let t = self.next_required("All, StartTime or EndTime", &l)?;
                match self.raw(&t) {
                    b"All" => self.sink().active_transform_all(loc),
                    b"StartTime" => self.sink().active_transform_start_time(loc),
                    b"EndTime" => self.sink().active_transform_end_time(loc),
                    _ => {
                        let shown = self.display(&t);
                        return Err(self.fail_at(
                            t,
                            format!("ActiveTransform: expected All, StartTime or EndTime, found {shown}"),
                        ));
                    }
                }
            }
            D::TransformTimes => {
                let v = self.floats::<2>(&l)?;
                self.sink().transform_times(v[0], v[1], loc)
            }
            D::ReverseOrientation => self.sink().reverse_orientation(loc),
            D::ColorSpace => {
                let n = self.quoted("a color space name", &l)?;
                self.sink().color_space(&n, loc)
            }
            D::PixelFilter
            | D::Film
            | D::Sampler
            | D::Accelerator
            | D::Integrator
            | D::Camera
            | D::MakeNamedMedium
            | D::Attribute
            | D::Material
            | D::MakeNamedMaterial
            | D::LightSource
            | D::AreaLightSource
            | D::Shape
            | D::Renderer
            | D::SurfaceIntegrator
            | D::VolumeIntegrator
            | D::Volume => {
                let n = self.quoted("a name", &l)?;
                let p = self.params()?;
                let t = self.sink();
                match d {
                    D::PixelFilter => t.pixel_filter(&n, p, loc),
                    D::Film => t.film(&n, p, loc),
                    D::Sampler => t.sampler(&n, p, loc),
                    D::Accelerator => t.accelerator(&n, p, loc),
                    D::Integrator => t.integrator(&n, p, loc),
                    D::Camera => t.camera(&n, p, loc),
                    D::MakeNamedMedium => t.make_named_medium(&n, p, loc),
                    D::Attribute => t.attribute(&n, p, loc),
                    D::Material => t.material(&n, p, loc),
                    D::MakeNamedMaterial => t.make_named_material(&n, p, loc),
                    D::LightSource => t.light_source(&n, p, loc),
                    D::AreaLightSource => t.area_light_source(&n, p, loc),
                    D::Renderer => t.renderer(&n, p, loc),
                    D::SurfaceIntegrator => t.surface_integrator(&n, p, loc),
                    D::VolumeIntegrator => t.volume_integrator(&n, p, loc),
                    D::Volume => t.volume(&n, p, loc),
                    _ => t.shape(&n, p, loc),
                }
            }
            D::MediumInterface => {
                let inside = self.quoted("a medium name", &l)?;
                let outside = match self.next()? {
                    Some(t) if t.is_string() => self.string_of(t)?,
                    Some(t) => {
                        self.unget = Some(t);
                        inside.clone()
                    }
                    None => inside.clone(),
                };
                self.sink().medium_interface(&inside, &outside, loc)
            }
            D::Option => {
                let name = self.quoted("an option name", &l)?;
                let t = self.next_required("an option value", &l)?;
                let value = if t.is_string() {
                    format!("\"{}\"", escape_string(&self.string_of(t)?))
                } else if t.kind == TokenKind::Word {
                    self.string_of(t)?
                } else {
                    let shown = self.display(&t);
                    return Err(self.fail_at(t, format!("expected an option value, found {shown}")));
                };
                self.sink().option(&name, &value, loc)
            }
            D::WorldBegin => self.sink().world_begin(loc),
            D::WorldEnd => self.sink().world_end(loc),
            D::AttributeBegin => self.sink().attribute_begin(loc),
            D::AttributeEnd => self.sink().attribute_end(loc),
            D::TransformBegin | D::TransformEnd => {
                if !self.warned_transform_begin {
                    self.warned_transform_begin = true;
                    self.report(Diagnostic::warning(
                        loc.clone(),
                        "TransformBegin/TransformEnd are deprecated; use AttributeBegin/AttributeEnd",
                    ));
                }
                if d == D::TransformBegin {
                    self.sink().transform_begin(loc)
                } else {
                    self.sink().transform_end(loc)
                }
            }
            D::Texture => {
                let name = self.quoted("a texture name", &l)?;
                let ty = self.quoted("a texture type (\"float\" or \"spectrum\")", &l)?;
                let class = self.quoted("a texture class", &l)?;
                let p = self.params()?;
                self.sink().texture(&name, &ty, &class, p, loc)
            }
            D::NamedMaterial => {
                let n = self.quoted("a material name", &l)?;
                self.sink().named_material(&n, loc)
            }
            D::ObjectBegin => {
                let n = self.quoted("an object name", &l)?;
                self.sink().object_begin(&n, loc)
            }
            D::ObjectEnd => self.sink().object_end(loc),
            D::ObjectInstance => {
                let n = self.quoted("an object name", &l)?;
                self.sink().object_instance(&n, loc)
            }
            D::Include | D::Import => {
                let n = self.quoted("a file name", &l)?;
                let kind = if d == D::Include {
                    IncludeKind::Include
                } else {
                    IncludeKind::Import
                };
                self.include(&n, kind, &l);
                Ok(())
            }
        })
    }
}

#[cfg(test)]
mod tests;

mod import;
mod record;
