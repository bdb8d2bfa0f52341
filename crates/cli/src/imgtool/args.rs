//! Argument parsing shared by the imgtool commands, with pbrt-v4's
//! conventions (`ParseArg`): `--name value`, `-name value` or
//! `--name=value`; a boolean flag alone means true and also takes
//! `=true` or `=false`; lists are comma-separated (`--crop 0,10,0,10`).

/// One command-line item.
pub(crate) enum Arg {
    /// A flag, by name without dashes.
    Flag(String),
    /// Anything else (a file name, a negative number).
    Positional(String),
}

/// A cursor over a command's arguments.
pub(crate) struct Args<'a> {
    cmd: &'static str,
    args: &'a [String],
    i: usize,
    inline: Option<String>,
}

fn is_number(s: &str) -> bool {
    s.parse::<f64>().is_ok()
}

impl<'a> Args<'a> {
    /// Arguments of command `cmd` (named in messages).
    pub fn new(cmd: &'static str, args: &'a [String]) -> Self {
        Args {
            cmd,
            args,
            i: 0,
            inline: None,
        }
    }

    /// The next item; a flag's `=value` is kept for the value readers.
    pub fn next_arg(&mut self) -> Option<Arg> {
        let a = self.args.get(self.i)?;
        self.i += 1;
        self.inline = None;
        if a.len() > 1 && a.starts_with('-') && !is_number(a) {
            let name = a.trim_start_matches('-');
            match name.split_once('=') {
                Some((n, v)) => {
                    self.inline = Some(v.to_string());
                    Some(Arg::Flag(n.to_string()))
                }
                None => Some(Arg::Flag(name.to_string())),
            }
        } else {
            Some(Arg::Positional(a.clone()))
        }
    }

    /// An error message prefixed with the command.
    pub fn err(&self, msg: impl std::fmt::Display) -> String {
        format!("{}: {msg}", self.cmd)
    }

    /// The error for a flag the command does not know.
    pub fn unknown(&self, flag: &str) -> String {
        self.err(format!(
            "--{flag}: unknown option (rpbrt imgtool help {} lists them)",
            self.cmd
        ))
    }

    /// The value of flag `flag`: after `=` or the next argument.
    pub fn value(&mut self, flag: &str) -> Result<String, String> {
        if let Some(v) = self.inline.take() {
            return Ok(v);
        }
        let v = self
            .args
            .get(self.i)
            .ok_or_else(|| self.err(format!("--{flag} needs a value")))?;
        self.i += 1;
        Ok(v.clone())
    }

    /// A floating-point value.
    pub fn f32(&mut self, flag: &str) -> Result<f32, String> {
        let v = self.value(flag)?;
        v.trim()
            .parse::<f32>()
            .map_err(|_| self.err(format!("--{flag}: \"{v}\" is not a number")))
    }

    /// An integer value.
    pub fn i32(&mut self, flag: &str) -> Result<i32, String> {
        let v = self.value(flag)?;
        v.trim()
            .parse::<i32>()
            .map_err(|_| self.err(format!("--{flag}: \"{v}\" is not an integer")))
    }

    /// A boolean flag: true alone, or the `=true`/`=false` given.
    pub fn bool(&mut self, flag: &str) -> Result<bool, String> {
        match self.inline.take().as_deref() {
            None | Some("true") | Some("1") => Ok(true),
            Some("false") | Some("0") => Ok(false),
            Some(v) => Err(self.err(format!("--{flag}: \"{v}\" is not true or false"))),
        }
    }

    /// Exactly `n` comma-separated integers.
    pub fn ints(&mut self, flag: &str, n: usize) -> Result<Vec<i32>, String> {
        let v = self.value(flag)?;
        let parsed: Result<Vec<i32>, _> = v.split(',').map(|s| s.trim().parse::<i32>()).collect();
        match parsed {
            Ok(p) if p.len() == n => Ok(p),
            _ => Err(self.err(format!(
                "--{flag}: expected {n} comma-separated integers, got \"{v}\""
            ))),
        }
    }

    /// Exactly `n` comma-separated numbers.
    pub fn floats(&mut self, flag: &str, n: usize) -> Result<Vec<f32>, String> {
        let v = self.value(flag)?;
        let parsed: Result<Vec<f32>, _> = v.split(',').map(|s| s.trim().parse::<f32>()).collect();
        match parsed {
            Ok(p) if p.len() == n => Ok(p),
            _ => Err(self.err(format!(
                "--{flag}: expected {n} comma-separated numbers, got \"{v}\""
            ))),
        }
    }
}

/// The crop window of `--crop x0,x1,y0,y1`.
pub(crate) fn crop(
    a: &mut Args,
    flag: &str,
) -> Result<Option<rpbrt_render::geometry::Bounds2i>, String> {
    let c = a.ints(flag, 4)?;
    Ok(rpbrt_render::image::ops::convert::crop_window([
        c[0], c[1], c[2], c[3],
    ]))
}

/// `x` as C's `%.{p}g`: `p` significant digits, trailing zeros dropped,
/// exponent form for very small or large magnitudes.
pub(crate) fn fmt_g(x: f64, p: usize) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let p = p.max(1);
    let e = x.abs().log10().floor() as i32;
    let trim = |s: String| -> String {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    };
    if e < -4 || e >= p as i32 {
        let s = format!("{:.*e}", p - 1, x);
        let (m, ex) = s.split_once('e').unwrap_or((&s, "0"));
        let ex: i32 = ex.parse().unwrap_or(0);
        format!(
            "{}e{}{:02}",
            trim(m.to_string()),
            if ex < 0 { '-' } else { '+' },
            ex.abs()
        )
    } else {
        trim(format!("{:.*}", (p as i32 - 1 - e).max(0) as usize, x))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn g_format_matches_c() {
        assert_eq!(fmt_g(0.0123456789012, 9), "0.0123456789");
        assert_eq!(fmt_g(1.5, 9), "1.5");
        assert_eq!(fmt_g(1.25e-7, 9), "1.25e-07");
        assert_eq!(fmt_g(123456.0, 3), "1.23e+05");
        assert_eq!(fmt_g(100.0, 6), "100");
    }

    #[test]
    fn flags_take_values_inline_or_next_and_negative_numbers_are_values() {
        let v: Vec<String> = [
            "--scale=2",
            "-gamma",
            "-0.5",
            "--flipy",
            "in.exr",
            "--bw=false",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        let mut a = Args::new("convert", &v);
        let mut seen = Vec::new();
        while let Some(x) = a.next_arg() {
            match x {
                Arg::Flag(f) if f == "scale" => seen.push(format!("s{}", a.f32(&f).unwrap())),
                Arg::Flag(f) if f == "gamma" => seen.push(format!("g{}", a.f32(&f).unwrap())),
                Arg::Flag(f) => seen.push(format!("{f}{}", a.bool(&f).unwrap())),
                Arg::Positional(p) => seen.push(p),
            }
        }
        assert_eq!(seen, ["s2", "g-0.5", "flipytrue", "in.exr", "bwfalse"]);
    }
}
