//! The `Option` directive: scene-wide settings with typed values (pbrt-v4
//! `BasicSceneBuilder::Option` in `scene.cpp`, the fields of `options.h`).

use rpbrt_parser::params::canonical_type;
use rpbrt_parser::{Diagnostic, FileLoc};

use super::entities::{OptionValue, SceneOption};
use super::names::{normalize_option_name, option_type, OptionType, KNOWN_OPTIONS};
use crate::camera::RenderingCoordinateSystem;

/// The contents of a quoted option value, or `None` for a bare word.
fn unquote(value: &str) -> Option<String> {
    let inner = value.strip_prefix('"')?.strip_suffix('"')?;
    let mut out = String::with_capacity(inner.len());
    let mut chars = inner.chars();
    while let Some(c) = chars.next() {
        if c == '\\' {
            match chars.next() {
                Some('n') => out.push('\n'),
                Some('t') => out.push('\t'),
                Some(other) => out.push(other),
                None => out.push('\\'),
            }
        } else {
            out.push(c);
        }
    }
    Some(out)
}

/// Parses `Option "name" value`. `name` may carry a type word
/// (`"bool disablepixeljitter"`), which must then match the option's type;
/// `value` is the token as written (a quoted string keeps its quotes).
/// Unknown options and ill-typed values are located errors.
pub fn parse_option(name: &str, value: &str, loc: &FileLoc) -> Result<SceneOption, Diagnostic> {
    let words: Vec<&str> = name.split_whitespace().collect();
    let (declared, bare) = match words[..] {
        [ty, n] => (Some(ty), n),
        [n] => (None, n),
        _ => (None, name),
    };
    let norm = normalize_option_name(bare);
    let Some(ty) = option_type(&norm) else {
        let known = KNOWN_OPTIONS
            .iter()
            .map(|(n, _)| format!("\"{n}\""))
            .collect::<Vec<_>>()
            .join(", ");
        return Err(Diagnostic::error(
            loc.clone(),
            format!("\"{name}\": unknown option; known options are {known}"),
        ));
    };
    if let Some(d) = declared {
        if canonical_type(d) != Some(ty.word()) {
            return Err(Diagnostic::error(
                loc.clone(),
                format!(
                    "option \"{norm}\" is of type \"{}\", not \"{d}\"",
                    ty.word()
                ),
            ));
        }
    }
    let quoted = unquote(value);
    let text = quoted.clone().unwrap_or_else(|| value.to_string());
    let bad = |what: &str| {
        Diagnostic::error(
            loc.clone(),
            format!("{value}: expected {what} for option \"{norm}\""),
        )
    };
    let parsed = match ty {
        OptionType::Bool => match text.as_str() {
            "true" => OptionValue::Bool(true),
            "false" => OptionValue::Bool(false),
            _ => return Err(bad("\"true\" or \"false\"")),
        },
        OptionType::Int => OptionValue::Int(text.parse().map_err(|_| bad("an integer"))?),
        OptionType::Float => {
            let v: f32 = text.parse().map_err(|_| bad("a number"))?;
            if !v.is_finite() {
                return Err(bad("a finite number"));
            }
            OptionValue::Float(v)
        }
        OptionType::String => {
            if norm == "rendercoordsys" {
                if RenderingCoordinateSystem::from_name(&text).is_none() {
                    return Err(bad("\"cameraworld\", \"camera\" or \"world\""));
                }
                OptionValue::String(text)
            } else {
                match quoted {
                    Some(s) if !s.is_empty() => OptionValue::String(s),
                    _ => return Err(bad("a non-empty quoted string")),
                }
            }
        }
    };
    Ok(SceneOption {
        name: norm,
        value: parsed,
        loc: loc.clone(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    fn loc() -> FileLoc {
        FileLoc::new(Arc::from("o.pbrt"), 4, 1)
    }

    #[test]
    fn typed_values() {
        let o = parse_option("disablepixeljitter", "true", &loc()).unwrap();
        assert_eq!(o.value, OptionValue::Bool(true));
        let o = parse_option("bool disable_pixel_jitter", "false", &loc()).unwrap();
        assert_eq!(o.name, "disablepixeljitter");
        assert_eq!(o.value, OptionValue::Bool(false));
        let o = parse_option("seed", "42", &loc()).unwrap();
        assert_eq!(o.value, OptionValue::Int(42));
        let o = parse_option("displacementedgescale", "0.5", &loc()).unwrap();
        assert_eq!(o.value, OptionValue::Float(0.5));
        let o = parse_option("msereferenceimage", "\"ref.exr\"", &loc()).unwrap();
        assert_eq!(o.value, OptionValue::String("ref.exr".into()));
        let o = parse_option("string rendercoordsys", "\"world\"", &loc()).unwrap();
        assert_eq!(o.value, OptionValue::String("world".into()));
    }

    #[test]
    fn errors_are_located() {
        for (n, v) in [
            ("nosuchoption", "true"),
            ("seed", "abc"),
            ("disablepixeljitter", "maybe"),
            ("float seed", "3"),
            ("rendercoordsys", "\"screen\""),
            ("msereferenceout", "out.exr"),
        ] {
            let e = parse_option(n, v, &loc()).unwrap_err();
            assert!(e.is_error());
            assert_eq!(e.loc, Some(loc()), "{n}");
        }
    }
}
