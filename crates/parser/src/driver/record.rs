//! Recorded directives: a [`ParserTarget`] that keeps every call, in order,
//! so that a file parsed on another thread (pbrt-v4's `Import`) can be
//! handed to the real target later, exactly as if it had been parsed in
//! place.

use crate::loc::FileLoc;
use crate::target::{DirectiveResult, ParamList, ParserTarget};

/// A directive without arguments.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Bare {
    Identity,
    ActiveTransformAll,
    ActiveTransformEndTime,
    ActiveTransformStartTime,
    ReverseOrientation,
    WorldBegin,
    WorldEnd,
    AttributeBegin,
    AttributeEnd,
    TransformBegin,
    TransformEnd,
    ObjectEnd,
    ImportBegin,
    ImportEnd,
}

/// A directive taking one name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum OneName {
    CoordinateSystem,
    CoordSysTransform,
    SearchPath,
    ColorSpace,
    NamedMaterial,
    ObjectBegin,
    ObjectInstance,
}

/// A directive taking a name and a parameter list.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum WithParams {
    PixelFilter,
    Film,
    Sampler,
    Accelerator,
    Integrator,
    Camera,
    MakeNamedMedium,
    Attribute,
    Material,
    MakeNamedMaterial,
    LightSource,
    AreaLightSource,
    Shape,
    Renderer,
    SurfaceIntegrator,
    VolumeIntegrator,
    Volume,
}

/// One recorded call.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Recorded {
    Bare(Bare, FileLoc),
    Name(OneName, String, FileLoc),
    Params(WithParams, String, ParamList, FileLoc),
    Translate([f32; 3], FileLoc),
    Scale([f32; 3], FileLoc),
    Rotate(f32, [f32; 3], FileLoc),
    LookAt([f32; 3], [f32; 3], [f32; 3], FileLoc),
    ConcatTransform(Box<[f32; 16]>, FileLoc),
    Transform(Box<[f32; 16]>, FileLoc),
    TransformTimes(f32, f32, FileLoc),
    MediumInterface(String, String, FileLoc),
    Option(String, String, FileLoc),
    Texture(String, String, String, ParamList, FileLoc),
}

impl Recorded {
    /// Makes the call on `target`.
    pub(crate) fn replay(self, t: &mut dyn ParserTarget) -> DirectiveResult {
        match self {
            Recorded::Bare(b, l) => match b {
                Bare::Identity => t.identity(l),
                Bare::ActiveTransformAll => t.active_transform_all(l),
                Bare::ActiveTransformEndTime => t.active_transform_end_time(l),
                Bare::ActiveTransformStartTime => t.active_transform_start_time(l),
                Bare::ReverseOrientation => t.reverse_orientation(l),
                Bare::WorldBegin => t.world_begin(l),
                Bare::WorldEnd => t.world_end(l),
                Bare::AttributeBegin => t.attribute_begin(l),
                Bare::AttributeEnd => t.attribute_end(l),
                Bare::TransformBegin => t.transform_begin(l),
                Bare::TransformEnd => t.transform_end(l),
                Bare::ObjectEnd => t.object_end(l),
                Bare::ImportBegin => t.import_begin(l),
                Bare::ImportEnd => t.import_end(l),
            },
            Recorded::Name(k, n, l) => match k {
                OneName::CoordinateSystem => t.coordinate_system(&n, l),
                OneName::CoordSysTransform => t.coord_sys_transform(&n, l),
                OneName::SearchPath => t.search_path(&n, l),
                OneName::ColorSpace => t.color_space(&n, l),
                OneName::NamedMaterial => t.named_material(&n, l),
                OneName::ObjectBegin => t.object_begin(&n, l),
                OneName::ObjectInstance => t.object_instance(&n, l),
            },
            Recorded::Params(k, n, p, l) => match k {
                WithParams::PixelFilter => t.pixel_filter(&n, p, l),
                WithParams::Film => t.film(&n, p, l),
                WithParams::Sampler => t.sampler(&n, p, l),
                WithParams::Accelerator => t.accelerator(&n, p, l),
                WithParams::Integrator => t.integrator(&n, p, l),
                WithParams::Camera => t.camera(&n, p, l),
                WithParams::MakeNamedMedium => t.make_named_medium(&n, p, l),
                WithParams::Attribute => t.attribute(&n, p, l),
                WithParams::Material => t.material(&n, p, l),
                WithParams::MakeNamedMaterial => t.make_named_material(&n, p, l),
                WithParams::LightSource => t.light_source(&n, p, l),
                WithParams::AreaLightSource => t.area_light_source(&n, p, l),
                WithParams::Shape => t.shape(&n, p, l),
                WithParams::Renderer => t.renderer(&n, p, l),
                WithParams::SurfaceIntegrator => t.surface_integrator(&n, p, l),
                WithParams::VolumeIntegrator => t.volume_integrator(&n, p, l),
                WithParams::Volume => t.volume(&n, p, l),
            },
            Recorded::Translate(d, l) => t.translate(d, l),
            Recorded::Scale(s, l) => t.scale(s, l),
            Recorded::Rotate(a, axis, l) => t.rotate(a, axis, l),
            Recorded::LookAt(e, k, u, l) => t.look_at(e, k, u, l),
            Recorded::ConcatTransform(m, l) => t.concat_transform(*m, l),
            Recorded::Transform(m, l) => t.transform(*m, l),
            Recorded::TransformTimes(s, e, l) => t.transform_times(s, e, l),
            Recorded::MediumInterface(i, o, l) => t.medium_interface(&i, &o, l),
            Recorded::Option(n, v, l) => t.option(&n, &v, l),
            Recorded::Texture(n, ty, c, p, l) => t.texture(&n, &ty, &c, p, l),
        }
    }
}

/// A target that records every directive in order.
#[derive(Clone, Debug, Default)]
pub(crate) struct Recorder {
    pub(crate) items: Vec<Recorded>,
    /// Open `AttributeBegin`/`TransformBegin`/`ObjectBegin` blocks, for the
    /// check that an imported file closes what it opens.
    pub(crate) open: Vec<FileLoc>,
}

impl Recorder {
    fn push(&mut self, r: Recorded) -> DirectiveResult {
        self.items.push(r);
        Ok(())
    }
    fn bare(&mut self, b: Bare, loc: FileLoc) -> DirectiveResult {
        match b {
            Bare::AttributeBegin | Bare::TransformBegin => self.open.push(loc.clone()),
            Bare::AttributeEnd | Bare::TransformEnd | Bare::ObjectEnd => {
                self.open.pop();
            }
            _ => {}
        }
        self.push(Recorded::Bare(b, loc))
    }
    fn name(&mut self, k: OneName, n: &str, loc: FileLoc) -> DirectiveResult {
        if k == OneName::ObjectBegin {
            self.open.push(loc.clone());
        }
        self.push(Recorded::Name(k, n.to_string(), loc))
    }
    fn params(&mut self, k: WithParams, n: &str, p: ParamList, loc: FileLoc) -> DirectiveResult {
        self.push(Recorded::Params(k, n.to_string(), p, loc))
    }
}

impl ParserTarget for Recorder {
    fn identity(&mut self, loc: FileLoc) -> DirectiveResult {
        self.bare(Bare::Identity, loc)
    }
    fn translate(&mut self, d: [f32; 3], loc: FileLoc) -> DirectiveResult {
        self.push(Recorded::Translate(d, loc))
    }
    fn scale(&mut self, s: [f32; 3], loc: FileLoc) -> DirectiveResult {
        self.push(Recorded::Scale(s, loc))
    }
    fn rotate(&mut self, angle: f32, axis: [f32; 3], loc: FileLoc) -> DirectiveResult {
        self.push(Recorded::Rotate(angle, axis, loc))
    }
    fn look_at(
        &mut self,
        eye: [f32; 3],
        look: [f32; 3],
        up: [f32; 3],
        loc: FileLoc,
    ) -> DirectiveResult {
        self.push(Recorded::LookAt(eye, look, up, loc))
    }
    fn concat_transform(&mut self, m: [f32; 16], loc: FileLoc) -> DirectiveResult {
        self.push(Recorded::ConcatTransform(Box::new(m), loc))
    }
    fn transform(&mut self, m: [f32; 16], loc: FileLoc) -> DirectiveResult {
        self.push(Recorded::Transform(Box::new(m), loc))
    }
    fn coordinate_system(&mut self, name: &str, loc: FileLoc) -> DirectiveResult {
        self.name(OneName::CoordinateSystem, name, loc)
    }
    fn coord_sys_transform(&mut self, name: &str, loc: FileLoc) -> DirectiveResult {
        self.name(OneName::CoordSysTransform, name, loc)
    }
    fn search_path(&mut self, path: &str, loc: FileLoc) -> DirectiveResult {
        self.name(OneName::SearchPath, path, loc)
    }
    fn active_transform_all(&mut self, loc: FileLoc) -> DirectiveResult {
        self.bare(Bare::ActiveTransformAll, loc)
    }
    fn active_transform_end_time(&mut self, loc: FileLoc) -> DirectiveResult {
        self.bare(Bare::ActiveTransformEndTime, loc)
    }
    fn active_transform_start_time(&mut self, loc: FileLoc) -> DirectiveResult {
        self.bare(Bare::ActiveTransformStartTime, loc)
    }
    fn transform_times(&mut self, start: f32, end: f32, loc: FileLoc) -> DirectiveResult {
        self.push(Recorded::TransformTimes(start, end, loc))
    }
    fn reverse_orientation(&mut self, loc: FileLoc) -> DirectiveResult {
        self.bare(Bare::ReverseOrientation, loc)
    }
    fn color_space(&mut self, name: &str, loc: FileLoc) -> DirectiveResult {
        self.name(OneName::ColorSpace, name, loc)
    }
    fn pixel_filter(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.params(WithParams::PixelFilter, name, params, loc)
    }
    fn film(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.params(WithParams::Film, name, params, loc)
    }
    fn sampler(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.params(WithParams::Sampler, name, params, loc)
    }
    fn accelerator(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.params(WithParams::Accelerator, name, params, loc)
    }
    fn integrator(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.params(WithParams::Integrator, name, params, loc)
    }
    fn renderer(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.params(WithParams::Renderer, name, params, loc)
    }
    fn surface_integrator(
        &mut self,
        name: &str,
        params: ParamList,
        loc: FileLoc,
    ) -> DirectiveResult {
        self.params(WithParams::SurfaceIntegrator, name, params, loc)
    }
    fn volume_integrator(
        &mut self,
        name: &str,
        params: ParamList,
        loc: FileLoc,
    ) -> DirectiveResult {
        self.params(WithParams::VolumeIntegrator, name, params, loc)
    }
    fn volume(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.params(WithParams::Volume, name, params, loc)
    }
    fn camera(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.params(WithParams::Camera, name, params, loc)
    }
    fn make_named_medium(
        &mut self,
        name: &str,
        params: ParamList,
        loc: FileLoc,
    ) -> DirectiveResult {
        self.params(WithParams::MakeNamedMedium, name, params, loc)
    }
    fn medium_interface(&mut self, inside: &str, outside: &str, loc: FileLoc) -> DirectiveResult {
        self.push(Recorded::MediumInterface(
            inside.to_string(),
            outside.to_string(),
            loc,
        ))
    }
    fn option(&mut self, name: &str, value: &str, loc: FileLoc) -> DirectiveResult {
        self.push(Recorded::Option(name.to_string(), value.to_string(), loc))
    }
    fn world_begin(&mut self, loc: FileLoc) -> DirectiveResult {
        self.bare(Bare::WorldBegin, loc)
    }
    fn world_end(&mut self, loc: FileLoc) -> DirectiveResult {
        self.bare(Bare::WorldEnd, loc)
    }
    fn attribute_begin(&mut self, loc: FileLoc) -> DirectiveResult {
        self.bare(Bare::AttributeBegin, loc)
    }
    fn attribute_end(&mut self, loc: FileLoc) -> DirectiveResult {
        self.bare(Bare::AttributeEnd, loc)
    }
    fn attribute(&mut self, target: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.params(WithParams::Attribute, target, params, loc)
    }
    fn transform_begin(&mut self, loc: FileLoc) -> DirectiveResult {
        self.bare(Bare::TransformBegin, loc)
    }
    fn transform_end(&mut self, loc: FileLoc) -> DirectiveResult {
        self.bare(Bare::TransformEnd, loc)
    }
    fn texture(
        &mut self,
        name: &str,
        ty: &str,
        texname: &str,
        params: ParamList,
        loc: FileLoc,
    ) -> DirectiveResult {
        self.push(Recorded::Texture(
            name.to_string(),
            ty.to_string(),
            texname.to_string(),
            params,
            loc,
        ))
    }
    fn material(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.params(WithParams::Material, name, params, loc)
    }
    fn make_named_material(
        &mut self,
        name: &str,
        params: ParamList,
        loc: FileLoc,
    ) -> DirectiveResult {
        self.params(WithParams::MakeNamedMaterial, name, params, loc)
    }
    fn named_material(&mut self, name: &str, loc: FileLoc) -> DirectiveResult {
        self.name(OneName::NamedMaterial, name, loc)
    }
    fn light_source(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.params(WithParams::LightSource, name, params, loc)
    }
    fn area_light_source(
        &mut self,
        name: &str,
        params: ParamList,
        loc: FileLoc,
    ) -> DirectiveResult {
        self.params(WithParams::AreaLightSource, name, params, loc)
    }
    fn shape(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.params(WithParams::Shape, name, params, loc)
    }
    fn object_begin(&mut self, name: &str, loc: FileLoc) -> DirectiveResult {
        self.name(OneName::ObjectBegin, name, loc)
    }
    fn object_end(&mut self, loc: FileLoc) -> DirectiveResult {
        self.bare(Bare::ObjectEnd, loc)
    }
    fn object_instance(&mut self, name: &str, loc: FileLoc) -> DirectiveResult {
        self.name(OneName::ObjectInstance, name, loc)
    }
    fn end_of_files(&mut self) -> DirectiveResult {
        Ok(())
    }
    fn import_begin(&mut self, loc: FileLoc) -> DirectiveResult {
        self.push(Recorded::Bare(Bare::ImportBegin, loc))
    }
    fn import_end(&mut self, loc: FileLoc) -> DirectiveResult {
        self.push(Recorded::Bare(Bare::ImportEnd, loc))
    }
}
