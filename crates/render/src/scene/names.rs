//! The type names pbrt-v4 accepts for each kind of scene entity, and the
//! scene-wide `Option` settings (pbrt-v4 `scene.cpp`, the `Create` functions
//! of each base type, and `options.h`).
//!
//! The builder only checks that a name is one of these; whether the renderer
//! implements each is checked when the entity is turned into a render object.

use std::borrow::Cow;

use crate::medium::MEDIUM_NAMES;
use crate::params::unknown_type;
use rpbrt_parser::{Diagnostic, FileLoc};

/// The kinds of named entity whose type name the builder validates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum EntityKind {
    /// `Shape`
    Shape,
    /// `Material` and `MakeNamedMaterial`'s `"string type"`.
    Material,
    /// `LightSource`
    Light,
    /// `AreaLightSource`
    AreaLight,
    /// `Texture` classes.
    Texture,
    /// `Film`
    Film,
    /// `Sampler`
    Sampler,
    /// `PixelFilter`
    Filter,
    /// `Integrator`
    Integrator,
    /// `Accelerator`
    Accelerator,
    /// `Camera`
    Camera,
    /// `MakeNamedMedium`'s `"string type"`.
    Medium,
}

impl EntityKind {
    /// The type names of this kind, sorted; each module that creates the
    /// objects owns its list.
    pub fn known_names(self) -> &'static [&'static str] {
        match self {
            EntityKind::Shape => crate::shape::create::SHAPE_NAMES,
            EntityKind::Material => crate::material::MATERIAL_NAMES,
            EntityKind::Light => crate::light::LIGHT_NAMES,
            EntityKind::AreaLight => crate::light::AREA_LIGHT_NAMES,
            EntityKind::Texture => crate::texture::TEXTURE_NAMES,
            EntityKind::Film => crate::film::FILM_NAMES,
            EntityKind::Sampler => crate::sampler::SAMPLER_NAMES,
            EntityKind::Filter => crate::filter::FILTER_NAMES,
            EntityKind::Integrator => crate::integrator::INTEGRATOR_NAMES,
            EntityKind::Accelerator => crate::accel::AccelParams::NAMES,
            EntityKind::Camera => crate::camera::CAMERA_NAMES,
            EntityKind::Medium => MEDIUM_NAMES,
        }
    }

    /// How the kind is named in messages.
    pub fn describe(self) -> &'static str {
        match self {
            EntityKind::Shape => "shape",
            EntityKind::Material => "material",
            EntityKind::Light => "light",
            EntityKind::AreaLight => "area light",
            EntityKind::Texture => "texture class",
            EntityKind::Film => "film",
            EntityKind::Sampler => "sampler",
            EntityKind::Filter => "pixel filter",
            EntityKind::Integrator => "integrator",
            EntityKind::Accelerator => "accelerator",
            EntityKind::Camera => "camera",
            EntityKind::Medium => "medium",
        }
    }

    /// True when `name` is a known type of this kind. Materials also accept
    /// `""` and `"none"` (pbrt-v4 treats both as `interface`).
    pub fn is_known(self, name: &str) -> bool {
        (self == EntityKind::Material && (name.is_empty() || name == "none"))
            || self.known_names().contains(&name)
    }

    /// `name`, held without a copy when it is one of this kind's known
    /// names (one allocation less for each of a scene's shapes).
    pub fn interned(self, name: String) -> Cow<'static, str> {
        match self.known_names().iter().find(|&&n| n == name) {
            Some(&n) => Cow::Borrowed(n),
            None => Cow::Owned(name),
        }
    }

    /// `Ok` for a known name, else a located error listing the known ones.
    pub fn check(self, name: &str, loc: &FileLoc) -> Result<(), Diagnostic> {
        if self.is_known(name) {
            return Ok(());
        }
        Err(unknown_type(self.describe(), name, self.known_names(), loc))
    }
}

/// The type of an `Option` setting's value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OptionType {
    /// `true` / `false`.
    Bool,
    /// A whole number.
    Int,
    /// A number.
    Float,
    /// A quoted string.
    String,
}

impl OptionType {
    /// The parameter-type word for this type (`bool`, `integer`, ...).
    pub fn word(self) -> &'static str {
        match self {
            OptionType::Bool => "bool",
            OptionType::Int => "integer",
            OptionType::Float => "float",
            OptionType::String => "string",
        }
    }
}

/// The options `Option` knows, with their types (pbrt-v4
/// `BasicSceneBuilder::Option`, plus `rendercoordsys`, which pbrt-v4 takes
/// on the command line).
pub const KNOWN_OPTIONS: [(&str, OptionType); 11] = [
    ("disablepixeljitter", OptionType::Bool),
    ("disabletexturefiltering", OptionType::Bool),
    ("disablewavelengthjitter", OptionType::Bool),
    ("displacementedgescale", OptionType::Float),
    ("forcediffuse", OptionType::Bool),
    ("msereferenceimage", OptionType::String),
    ("msereferenceout", OptionType::String),
    ("pixelstats", OptionType::Bool),
    ("rendercoordsys", OptionType::String),
    ("seed", OptionType::Int),
    ("wavefront", OptionType::Bool),
];

/// The type of option `name` (already normalized), if known.
pub fn option_type(name: &str) -> Option<OptionType> {
    KNOWN_OPTIONS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|&(_, t)| t)
}

/// pbrt-v4's `normalizeArg`: lower case, without `-` and `_`.
pub fn normalize_option_name(name: &str) -> String {
    name.chars()
        .filter(|&c| c != '-' && c != '_')
        .map(|c| c.to_ascii_lowercase())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    #[test]
    fn known_names_are_sorted_and_checked() {
        let kinds = [
            EntityKind::Shape,
            EntityKind::Material,
            EntityKind::Light,
            EntityKind::AreaLight,
            EntityKind::Texture,
            EntityKind::Film,
            EntityKind::Sampler,
            EntityKind::Filter,
            EntityKind::Integrator,
            EntityKind::Accelerator,
            EntityKind::Camera,
            EntityKind::Medium,
        ];
        for k in kinds {
            let names = k.known_names();
            assert!(names.windows(2).all(|w| w[0] < w[1]), "{k:?}");
        }
        let loc = FileLoc::new(Arc::from("f"), 2, 3);
        assert!(EntityKind::Material.check("none", &loc).is_ok());
        let e = EntityKind::Shape.check("sphre", &loc).unwrap_err();
        assert_eq!(e.loc, Some(loc));
        assert!(e.message.contains("\"sphere\""), "{}", e.message);
    }

    #[test]
    fn option_names_normalize() {
        assert_eq!(
            normalize_option_name("Disable_Pixel-Jitter"),
            "disablepixeljitter"
        );
        assert_eq!(option_type("seed"), Some(OptionType::Int));
        assert_eq!(option_type("bogus"), None);
    }
}
