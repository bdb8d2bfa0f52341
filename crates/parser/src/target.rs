//! The `ParserTarget` trait: one method per scene-file directive (pbrt-v4
//! `parser.h`; book section C.2). The parser calls it; the scene builder and
//! the formatter implement it.
//!
//! Every method receives the directive's arguments and its [`FileLoc`]. A
//! method returns `Err` with a [`Diagnostic`] to report a problem at the
//! directive (an `Err` whose severity is a warning is only a warning); the
//! parser records it and carries on with the next directive. Targets that
//! want to report several messages per directive can queue them and hand
//! them over in [`ParserTarget::take_diagnostics`].

use crate::diag::Diagnostic;
use crate::loc::FileLoc;
use crate::params::ParsedParameter;

/// What a directive method returns.
pub type DirectiveResult = Result<(), Diagnostic>;

/// A directive's parameter list, in file order.
pub type ParamList = Vec<ParsedParameter>;

/// Which directive named a file to read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IncludeKind {
    /// `Include "file"`: textual inclusion.
    Include,
    /// `Import "file"`: pbrt-v4's parallel-parsed inclusion: parsed on a
    /// thread of its own, its directives delivered at the `Import`'s place
    /// between [`ParserTarget::import_begin`] and
    /// [`ParserTarget::import_end`].
    Import,
}

/// Receives the directives of a scene description, in order.
#[allow(clippy::too_many_arguments)]
pub trait ParserTarget {
    /// `Identity`
    fn identity(&mut self, loc: FileLoc) -> DirectiveResult;
    /// `Translate dx dy dz`
    fn translate(&mut self, d: [f32; 3], loc: FileLoc) -> DirectiveResult;
    /// `Scale sx sy sz`
    fn scale(&mut self, s: [f32; 3], loc: FileLoc) -> DirectiveResult;
    /// `Rotate angle ax ay az` (degrees)
    fn rotate(&mut self, angle: f32, axis: [f32; 3], loc: FileLoc) -> DirectiveResult;
    /// `LookAt ex ey ez  lx ly lz  ux uy uz`
    fn look_at(
        &mut self,
        eye: [f32; 3],
        look: [f32; 3],
        up: [f32; 3],
        loc: FileLoc,
    ) -> DirectiveResult;
    /// `ConcatTransform [ m00 .. m33 ]` (16 values, as written)
    fn concat_transform(&mut self, m: [f32; 16], loc: FileLoc) -> DirectiveResult;
    /// `Transform [ m00 .. m33 ]` (16 values, as written)
    fn transform(&mut self, m: [f32; 16], loc: FileLoc) -> DirectiveResult;
    /// `CoordinateSystem "name"`
    fn coordinate_system(&mut self, name: &str, loc: FileLoc) -> DirectiveResult;
    /// `CoordSysTransform "name"`
    fn coord_sys_transform(&mut self, name: &str, loc: FileLoc) -> DirectiveResult;
    /// `SearchPath "dirs"` (pbrt-v1, options block): where pbrt-v1 looked
    /// for its plugins.
    fn search_path(&mut self, path: &str, loc: FileLoc) -> DirectiveResult;
    /// `ActiveTransform All`
    fn active_transform_all(&mut self, loc: FileLoc) -> DirectiveResult;
    /// `ActiveTransform EndTime`
    fn active_transform_end_time(&mut self, loc: FileLoc) -> DirectiveResult;
    /// `ActiveTransform StartTime`
    fn active_transform_start_time(&mut self, loc: FileLoc) -> DirectiveResult;
    /// `TransformTimes start end`
    fn transform_times(&mut self, start: f32, end: f32, loc: FileLoc) -> DirectiveResult;
    /// `ReverseOrientation`
    fn reverse_orientation(&mut self, loc: FileLoc) -> DirectiveResult;
    /// `ColorSpace "name"`
    fn color_space(&mut self, name: &str, loc: FileLoc) -> DirectiveResult;
    /// `PixelFilter "name" params`
    fn pixel_filter(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult;
    /// `Film "name" params`
    fn film(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult;
    /// `Sampler "name" params`
    fn sampler(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult;
    /// `Accelerator "name" params`
    fn accelerator(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult;
    /// `Integrator "name" params`
    fn integrator(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult;
    /// `Camera "name" params`
    fn camera(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult;
    /// `Renderer "name" params` (pbrt-v2; pbrt-v1 had none): how the image
    /// is made, `sampler` (the default), `metropolis` or a tool.
    fn renderer(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult;
    /// `SurfaceIntegrator "name" params` (pbrt-v1 and pbrt-v2): light
    /// transport at surfaces.
    fn surface_integrator(
        &mut self,
        name: &str,
        params: ParamList,
        loc: FileLoc,
    ) -> DirectiveResult;
    /// `VolumeIntegrator "name" params` (pbrt-v1 and pbrt-v2): light
    /// transport in `Volume` regions.
    fn volume_integrator(&mut self, name: &str, params: ParamList, loc: FileLoc)
        -> DirectiveResult;
    /// `Volume "name" params` (pbrt-v1 and pbrt-v2, in the world block): a
    /// participating-medium region with no bounding surface.
    fn volume(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult;
    /// `MakeNamedMedium "name" params`
    fn make_named_medium(&mut self, name: &str, params: ParamList, loc: FileLoc)
        -> DirectiveResult;
    /// `MediumInterface "inside" "outside"`; a single name means both.
    fn medium_interface(&mut self, inside: &str, outside: &str, loc: FileLoc) -> DirectiveResult;
    /// `Option "name" value`. `value` is the token as written: a bare word,
    /// or a quoted (and escaped) string including its quotes.
    fn option(&mut self, name: &str, value: &str, loc: FileLoc) -> DirectiveResult;
    /// `WorldBegin`
    fn world_begin(&mut self, loc: FileLoc) -> DirectiveResult;
    /// `WorldEnd` (pbrt-v3); ignored by default.
    fn world_end(&mut self, loc: FileLoc) -> DirectiveResult {
        let _ = loc;
        Ok(())
    }
    /// `AttributeBegin`
    fn attribute_begin(&mut self, loc: FileLoc) -> DirectiveResult;
    /// `AttributeEnd`
    fn attribute_end(&mut self, loc: FileLoc) -> DirectiveResult;
    /// `Attribute "shape"|"light"|"material"|"medium"|"texture" params`
    fn attribute(&mut self, target: &str, params: ParamList, loc: FileLoc) -> DirectiveResult;
    /// `TransformBegin` (pbrt-v3, deprecated); defaults to `attribute_begin`.
    fn transform_begin(&mut self, loc: FileLoc) -> DirectiveResult {
        self.attribute_begin(loc)
    }
    /// `TransformEnd` (pbrt-v3, deprecated); defaults to `attribute_end`.
    fn transform_end(&mut self, loc: FileLoc) -> DirectiveResult {
        self.attribute_end(loc)
    }
    /// `Texture "name" "float"|"spectrum" "class" params`
    fn texture(
        &mut self,
        name: &str,
        ty: &str,
        texname: &str,
        params: ParamList,
        loc: FileLoc,
    ) -> DirectiveResult;
    /// `Material "type" params`
    fn material(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult;
    /// `MakeNamedMaterial "name" params`
    fn make_named_material(
        &mut self,
        name: &str,
        params: ParamList,
        loc: FileLoc,
    ) -> DirectiveResult;
    /// `NamedMaterial "name"`
    fn named_material(&mut self, name: &str, loc: FileLoc) -> DirectiveResult;
    /// `LightSource "type" params`
    fn light_source(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult;
    /// `AreaLightSource "type" params`
    fn area_light_source(&mut self, name: &str, params: ParamList, loc: FileLoc)
        -> DirectiveResult;
    /// `Shape "type" params`
    fn shape(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult;
    /// `ObjectBegin "name"`
    fn object_begin(&mut self, name: &str, loc: FileLoc) -> DirectiveResult;
    /// `ObjectEnd`
    fn object_end(&mut self, loc: FileLoc) -> DirectiveResult;
    /// `ObjectInstance "name"`
    fn object_instance(&mut self, name: &str, loc: FileLoc) -> DirectiveResult;
    /// Called once after the last file has been parsed.
    fn end_of_files(&mut self) -> DirectiveResult;

    /// `Include "file"` / `Import "file"`, before the file is opened.
    /// Return `Ok(true)` (the default) to have the parser read the file and
    /// deliver its directives here; `Ok(false)` to skip it (the formatter
    /// prints the directive instead).
    fn include(
        &mut self,
        filename: &str,
        kind: IncludeKind,
        loc: FileLoc,
    ) -> Result<bool, Diagnostic> {
        let _ = (filename, kind, loc);
        Ok(true)
    }

    /// The start of an `Import`ed file's directives, at the `Import`
    /// directive. pbrt-v4 parses an imported file with a copy of the
    /// graphics state, so what it changes stays inside it; by default this
    /// is `attribute_begin` (and [`ParserTarget::import_end`]
    /// `attribute_end`).
    fn import_begin(&mut self, loc: FileLoc) -> DirectiveResult {
        self.attribute_begin(loc)
    }

    /// The end of an `Import`ed file's directives.
    fn import_end(&mut self, loc: FileLoc) -> DirectiveResult {
        self.attribute_end(loc)
    }

    /// Whether the target wants the file's `#` comments through
    /// [`ParserTarget::comment`] (the formatter does; recording them costs
    /// the scene builder nothing when it does not).
    fn wants_comments(&self) -> bool {
        false
    }

    /// A `#` comment (its text from the `#` to the end of the line), called
    /// in file order between directives: before the first directive that
    /// starts after it. A comment inside a directive's parameter list comes
    /// after that directive.
    fn comment(&mut self, text: &str, loc: FileLoc) -> DirectiveResult {
        let _ = (text, loc);
        Ok(())
    }

    /// Messages the target queued since the last call; the parser calls
    /// this after every directive.
    fn take_diagnostics(&mut self) -> Vec<Diagnostic> {
        Vec::new()
    }
}
