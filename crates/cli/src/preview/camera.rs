//! `--interactive`'s camera: what the page's controls change. The camera
//! is kept as the scene text that places it (`Scale -1 1 1` where the
//! file's camera is mirrored, then a `LookAt`, one per shutter end for a
//! moving camera) and the lens settings of its `Camera` line; each change
//! edits that text's numbers (`f32`s, printed so that they read back the
//! same) and builds the camera from them as the scene builder would from
//! the text. So pasting the text shown into the file gives the camera
//! rendered. The file's own camera (which need not be a `LookAt`) is kept
//! as it was for "reset".
//!
//! Moves follow pbrt-v4's interactive keys where it has them (W/S forward
//! and back, A/D left and right, the arrows turn); Q/E move down and up.
//! A step is 1% of the scene's bounding-box diagonal (5% with Shift), a
//! turn 1° (5°): pbrt-v4 moves one world unit, which suits no scene scale
//! in particular. Orbits turn about the point picked under the cursor (its
//! depth from the first hit of the ray through it), 180° across the image.

use rpbrt_render::camera::{Camera, LensChange};
use rpbrt_render::geometry::{
    cross, dot, AnimatedTransform, Float, Point2f, Point3f, Transform, Vector3f,
};
use rpbrt_render::integrator::{pick, CameraChange, Pick};
use rpbrt_render::primitive::PrimitiveAggregate;
use serde_json::Value;
use std::sync::Arc;

/// Largest coordinate a moved camera may have.
const MAX_COORD: Float = 1e30;
/// Most steps one request may take.
const MAX_STEPS: u64 = 1000;
/// Turn per arrow-key step, degrees.
const TURN_DEGREES: Float = 1.0;
/// How much faster moves are with Shift.
const FAST: Float = 5.0;
/// Closest the view direction may come to the up vector, degrees.
const MIN_PITCH_GAP: Float = 1.0;

/// One `LookAt`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct LookAt {
    eye: Point3f,
    look: Point3f,
    up: Vector3f,
}

impl LookAt {
    fn dir(&self) -> Vector3f {
        (self.look - self.eye).normalize()
    }

    fn camera_from_world(&self, flip: bool) -> Option<Transform> {
        let t = Transform::look_at(self.eye, self.look, self.up).ok()?;
        Some(if flip {
            Transform::scale(-1.0, 1.0, 1.0) * t
        } else {
            t
        })
    }

    /// Whether the numbers make a camera: finite, bounded, the eye off the
    /// look point and the up vector off the view direction.
    fn valid(&self) -> bool {
        let (e, l, u) = (self.eye, self.look, self.up);
        let bounded = [e.x, e.y, e.z, l.x, l.y, l.z, u.x, u.y, u.z]
            .iter()
            .all(|v| v.is_finite() && v.abs() <= MAX_COORD);
        let d = self.look - self.eye;
        bounded
            && d.length() > 0.0
            && self.up.length() > 0.0
            && cross(self.up.normalize(), d.normalize()).length() > 1e-4
    }

    fn text(&self) -> String {
        let v = |p: [Float; 3]| format!("{} {} {}", p[0], p[1], p[2]);
        format!(
            "LookAt {}  {}  {}",
            v([self.eye.x, self.eye.y, self.eye.z]),
            v([self.look.x, self.look.y, self.look.z]),
            v([self.up.x, self.up.y, self.up.z])
        )
    }
}

/// The camera as scene text: the placement and the lens settings.
#[derive(Clone, Debug, PartialEq)]
struct View {
    /// `Scale -1 1 1` before each `LookAt` (a mirrored camera).
    flip: bool,
    /// One `LookAt`, or two (shutter open and close) for a moving camera.
    looks: Vec<LookAt>,
    lens: LensChange,
}

/// What a request asks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Op {
    /// A key: `w`/`s` forward and back, `a`/`d` left and right, `q`/`e`
    /// down and up, `left`/`right`/`up`/`down` turn; `steps` times.
    Key { key: Key, steps: u64, fast: bool },
    /// Orbit by a drag of (dx, dy) pixels; `start`: the pixel the drag
    /// began at (picks the point orbited about).
    Orbit {
        start: Option<(Float, Float)>,
        dx: Float,
        dy: Float,
    },
    /// Move along the view direction by `amount` tenths of the distance
    /// to what is under pixel `at` (positive: forward).
    Dolly { amount: Float, at: (Float, Float) },
    /// Set the field of view, lens radius or focal distance.
    Lens(LensChange),
    /// Focus on what is under the pixel.
    Focus(Float, Float),
    /// Back to the file's camera.
    Reset,
}

/// The keys.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Key {
    /// W.
    Forward,
    /// S.
    Back,
    /// A.
    Left,
    /// D.
    Right,
    /// Q.
    Down,
    /// E.
    Up,
    /// Arrow left.
    TurnLeft,
    /// Arrow right.
    TurnRight,
    /// Arrow up.
    TurnUp,
    /// Arrow down.
    TurnDown,
}

/// Reads a request body (JSON) into an [`Op`]: unknown fields, values of
/// the wrong type and non-finite or absurd numbers are errors.
pub fn parse_op(body: &[u8]) -> Result<Op, String> {
    let v: Value = serde_json::from_slice(body).map_err(|e| format!("not JSON: {e}"))?;
    let obj = v.as_object().ok_or("the request must be a JSON object")?;
    let op = obj
        .get("op")
        .and_then(Value::as_str)
        .ok_or("the request needs a string \"op\"")?;
    let allowed: &[&str] = match op {
        "key" => &["op", "key", "steps", "fast"],
        "orbit" => &["op", "start", "dx", "dy"],
        "dolly" => &["op", "amount", "at"],
        "lens" => &["op", "fov", "lensradius", "focaldistance"],
        "focus" => &["op", "at"],
        "reset" => &["op"],
        _ => return Err(format!("unknown op \"{op}\"")),
    };
    if let Some(k) = obj.keys().find(|k| !allowed.contains(&k.as_str())) {
        return Err(format!("unknown field \"{k}\" for op \"{op}\""));
    }
    let num = |name: &str, limit: Float| -> Result<Option<Float>, String> {
        match obj.get(name) {
            None => Ok(None),
            Some(v) => {
                let x = v
                    .as_f64()
                    .ok_or_else(|| format!("\"{name}\" must be a number"))?;
                if !x.is_finite() || x.abs() > limit as f64 {
                    return Err(format!("\"{name}\" {x} is out of range"));
                }
                Ok(Some(x as Float))
            }
        }
    };
    let pixel = |name: &str| -> Result<Option<(Float, Float)>, String> {
        match obj.get(name) {
            None => Ok(None),
            Some(v) => {
                let a = v.as_array().filter(|a| a.len() == 2).ok_or_else(|| {
                    format!("\"{name}\" must be a pixel: an array of two numbers")
                })?;
                let c = |i: usize| {
                    a[i].as_f64()
                        .filter(|x| x.is_finite() && x.abs() <= 1e6)
                        .map(|x| x as Float)
                        .ok_or_else(|| format!("\"{name}\" has a bad coordinate"))
                };
                Ok(Some((c(0)?, c(1)?)))
            }
        }
    };
    let need =
        |v: Option<Float>, name: &str| v.ok_or_else(|| format!("op \"{op}\" needs \"{name}\""));
    Ok(match op {
        "key" => {
            let key = match obj.get("key").and_then(Value::as_str) {
                Some("w") => Key::Forward,
                Some("s") => Key::Back,
                Some("a") => Key::Left,
                Some("d") => Key::Right,
                Some("q") => Key::Down,
                Some("e") => Key::Up,
                Some("left") => Key::TurnLeft,
                Some("right") => Key::TurnRight,
                Some("up") => Key::TurnUp,
                Some("down") => Key::TurnDown,
                Some(k) => return Err(format!("unknown key \"{k}\"")),
                None => return Err("op \"key\" needs a string \"key\"".into()),
            };
            let steps = match obj.get("steps") {
                None => 1,
                Some(v) => v
                    .as_u64()
                    .filter(|&n| (1..=MAX_STEPS).contains(&n))
                    .ok_or_else(|| {
                        format!("\"steps\" must be a whole number from 1 to {MAX_STEPS}")
                    })?,
            };
            let fast = match obj.get("fast") {
                None => false,
                Some(v) => v.as_bool().ok_or("\"fast\" must be true or false")?,
            };
            Op::Key { key, steps, fast }
        }
        "orbit" => Op::Orbit {
            start: pixel("start")?,
            dx: need(num("dx", 1e5)?, "dx")?,
            dy: need(num("dy", 1e5)?, "dy")?,
        },
        "dolly" => Op::Dolly {
            amount: need(num("amount", 1e3)?, "amount")?,
            at: pixel("at")?.ok_or("op \"dolly\" needs \"at\"")?,
        },
        "lens" => {
            let lens = LensChange {
                fov: num("fov", 1e6)?,
                lens_radius: num("lensradius", MAX_COORD)?,
                focal_distance: num("focaldistance", MAX_COORD)?,
            };
            if lens == LensChange::default() {
                return Err(
                    "op \"lens\" needs \"fov\", \"lensradius\" or \"focaldistance\"".into(),
                );
            }
            Op::Lens(lens)
        }
        "focus" => {
            let (x, y) = pixel("at")?.ok_or("op \"focus\" needs \"at\"")?;
            Op::Focus(x, y)
        }
        _ => Op::Reset,
    })
}

/// Rotates `v` about the unit axis `k` by `angle` radians (Rodrigues).
fn rotate(v: Vector3f, k: Vector3f, angle: Float) -> Vector3f {
    let (s, c) = angle.sin_cos();
    v * c + cross(k, v) * s + k * (dot(k, v) * (1.0 - c))
}

/// The camera's scene text for its type and parameters.
#[derive(Clone, Debug)]
pub struct CameraDirective {
    /// The camera type.
    pub name: String,
    /// Its parameters as written (`"float fov" [ 40 ]`), by name.
    pub params: Vec<(String, String)>,
}

impl CameraDirective {
    /// The directive of the scene's `Camera` entity.
    pub fn of(entity: &rpbrt_render::scene::SceneEntity) -> Self {
        let params = entity
            .params
            .params()
            .iter()
            .map(|p| {
                let values: Vec<String> = if !p.strings.is_empty() {
                    p.strings
                        .iter()
                        .map(|s| format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\"")))
                        .collect()
                } else if !p.bools.is_empty() {
                    p.bools.iter().map(|b| b.to_string()).collect()
                } else if !p.ints.is_empty() {
                    p.ints.iter().map(|i| i.to_string()).collect()
                } else {
                    p.floats.iter().map(|f| f.to_string()).collect()
                };
                let text = format!("\"{} {}\" [ {} ]", p.ty, p.name, values.join(" "));
                (p.name.clone(), text)
            })
            .collect();
        CameraDirective {
            name: entity.name.to_string(),
            params,
        }
    }
}

/// The interactive camera (see the module docs).
pub struct CameraControl {
    original: Camera,
    original_view: View,
    view: View,
    camera: Camera,
    number: u64,
    aggregate: Arc<PrimitiveAggregate>,
    /// A step, in world units.
    step: Float,
    /// The film's first pixel in raster space (pixel bounds' corner).
    raster_origin: (Float, Float),
    /// The size of the image, pixels.
    size: (Float, Float),
    pivot: Option<Point3f>,
    directive: CameraDirective,
}

impl CameraControl {
    /// Control of `camera` (the scene's, as the file placed it), which
    /// renders the pixels from `raster_origin` (the film's pixel bounds)
    /// over `size`, among the geometry `aggregate`.
    pub fn new(
        camera: Camera,
        directive: CameraDirective,
        aggregate: Arc<PrimitiveAggregate>,
        raster_origin: (i32, i32),
        size: (i32, i32),
    ) -> Self {
        let base = camera.base();
        let ct = &base.camera_transform;
        let world_from_camera = |t: &Transform| ct.world_from_render * *t;
        let rfc = &ct.render_from_camera;
        let mut transforms = vec![world_from_camera(&rfc.start_transform())];
        if rfc.is_animated() {
            transforms.push(world_from_camera(&rfc.end_transform()));
        }
        let looks = transforms.iter().map(derive_look_at).collect();
        let lens = camera.lens();
        let view = View {
            flip: transforms[0].swaps_handedness(),
            looks,
            lens: LensChange {
                fov: lens.fov,
                lens_radius: lens.lens_radius,
                focal_distance: lens.focal_distance,
            },
        };
        let b = ct.world_from_render.apply_bounds(&aggregate.bounds());
        let diagonal = (b.p_max - b.p_min).length();
        let step = if diagonal.is_finite() && diagonal > 0.0 {
            0.01 * diagonal
        } else {
            1.0
        };
        CameraControl {
            original: camera.clone(),
            original_view: view.clone(),
            view,
            camera,
            number: 0,
            aggregate,
            step,
            raster_origin: (raster_origin.0 as Float, raster_origin.1 as Float),
            size: (size.0 as Float, size.1 as Float),
            pivot: None,
            directive,
        }
    }

    /// What is under pixel `(x, y)` of the image (pixel centres at .5).
    fn pick(&self, x: Float, y: Float) -> Option<Pick> {
        let p = Point2f::new(self.raster_origin.0 + x, self.raster_origin.1 + y);
        pick(&self.aggregate, &self.camera, p)
    }

    /// Applies `op`: the camera to render from now on, or why not (nothing
    /// changes then).
    pub fn apply(&mut self, op: Op) -> Result<CameraChange, String> {
        if op == Op::Reset {
            self.view = self.original_view.clone();
            self.pivot = None;
            return Ok(self.commit(self.original.clone()));
        }
        let mut view = self.view.clone();
        let first = view.looks[0];
        let dir = first.dir();
        let up_axis = first.up.normalize();
        let right = cross(up_axis, dir).normalize();
        let screen_right = if view.flip { -right } else { right };
        let screen_up = cross(dir, right);
        // Every LookAt (both shutter ends) moves alike.
        let translate = |view: &mut View, d: Vector3f| {
            for l in &mut view.looks {
                l.eye += d;
                l.look += d;
            }
        };
        let spin = |view: &mut View, pivot: Point3f, axis: Vector3f, angle: Float| {
            for l in &mut view.looks {
                l.eye = pivot + rotate(l.eye - pivot, axis, angle);
                l.look = pivot + rotate(l.look - pivot, axis, angle);
            }
        };
        match op {
            Op::Key { key, steps, fast } => {
                let k = steps as Float * if fast { FAST } else { 1.0 };
                let d = self.step * k;
                let turn = (TURN_DEGREES * k).to_radians();
                match key {
                    Key::Forward => translate(&mut view, dir * d),
                    Key::Back => translate(&mut view, dir * -d),
                    Key::Right => translate(&mut view, screen_right * d),
                    Key::Left => translate(&mut view, screen_right * -d),
                    Key::Up => translate(&mut view, screen_up * d),
                    Key::Down => translate(&mut view, screen_up * -d),
                    Key::TurnLeft | Key::TurnRight | Key::TurnUp | Key::TurnDown => {
                        // Yaw about the up vector, pitch about the right axis.
                        let (axis, toward) = match key {
                            Key::TurnRight => (up_axis, screen_right),
                            Key::TurnLeft => (up_axis, -screen_right),
                            Key::TurnUp => (right, screen_up),
                            _ => (right, -screen_up),
                        };
                        let sign = dot(cross(axis, dir), toward).signum();
                        for l in &mut view.looks {
                            l.look = l.eye + rotate(l.look - l.eye, axis, sign * turn);
                        }
                        if !pitch_ok(&view) {
                            return Err(
                                "cannot turn further: the view would be along the up vector".into(),
                            );
                        }
                    }
                }
            }
            Op::Orbit { start, dx, dy } => {
                if let Some((x, y)) = start {
                    self.pivot = Some(self.pick(x, y).map(|p| p.p_world).unwrap_or(first.look));
                }
                let pivot = self.pivot.unwrap_or(first.look);
                // Dragging right turns the scene right: the camera goes left.
                let yaw = -(dx / self.size.0.max(1.0)) * std::f32::consts::PI;
                let v = first.eye - pivot;
                let sign = dot(cross(up_axis, v), screen_right).signum();
                spin(&mut view, pivot, up_axis, sign * yaw);
                let pitched = {
                    let mut v2 = view.clone();
                    let pitch = (dy / self.size.1.max(1.0)) * std::f32::consts::PI;
                    let v = v2.looks[0].eye - pivot;
                    let r = cross(up_axis, v2.looks[0].dir()).normalize();
                    let sign = dot(cross(r, v), screen_up).signum();
                    spin(&mut v2, pivot, r, sign * pitch);
                    v2
                };
                if pitch_ok(&pitched) {
                    view = pitched;
                }
            }
            Op::Dolly { amount, at } => {
                let d = match self.pick(at.0, at.1) {
                    Some(p) => (p.p_world - first.eye).length(),
                    None => 10.0 * self.step,
                };
                translate(&mut view, dir * (0.1 * amount * d));
            }
            Op::Lens(l) => {
                let has = self.original.lens();
                for (asked, have, name) in [
                    (l.fov, has.fov, "fov"),
                    (l.lens_radius, has.lens_radius, "lensradius"),
                    (l.focal_distance, has.focal_distance, "focaldistance"),
                ] {
                    if asked.is_some() && have.is_none() {
                        return Err(format!(
                            "the \"{}\" camera has no \"{name}\" setting",
                            self.original.type_name()
                        ));
                    }
                }
                view.lens.fov = l.fov.or(view.lens.fov);
                view.lens.lens_radius = l.lens_radius.or(view.lens.lens_radius);
                view.lens.focal_distance = l.focal_distance.or(view.lens.focal_distance);
            }
            Op::Focus(x, y) => {
                if view.lens.focal_distance.is_none() {
                    return Err(format!(
                        "the \"{}\" camera has no focal distance",
                        self.original.type_name()
                    ));
                }
                let p = self
                    .pick(x, y)
                    .filter(|p| p.depth > 0.0 && p.depth.is_finite())
                    .ok_or("nothing to focus on under that pixel")?;
                view.lens.focal_distance = Some(p.depth);
            }
            Op::Reset => {}
        }
        if !view.looks.iter().all(LookAt::valid) {
            return Err("the change would make a degenerate or far-off camera".into());
        }
        let camera = self.build(&view)?;
        self.view = view;
        Ok(self.commit(camera))
    }

    /// The camera `view` gives, as the scene builder builds it from the text.
    fn build(&self, view: &View) -> Result<Camera, String> {
        let wfc = |l: &LookAt| {
            l.camera_from_world(view.flip)
                .map(|t| t.inverse())
                .ok_or_else(|| "degenerate LookAt".to_string())
        };
        let start = wfc(&view.looks[0])?;
        let end = match view.looks.get(1) {
            Some(l) => wfc(l)?,
            None => start,
        };
        let rfc = &self.original.base().camera_transform.render_from_camera;
        let animated = AnimatedTransform::new(start, rfc.start_time, end, rfc.end_time);
        self.original.placed(&animated, &view.lens)
    }

    fn commit(&mut self, camera: Camera) -> CameraChange {
        self.number += 1;
        self.camera = camera.clone();
        CameraChange {
            number: self.number,
            camera,
        }
    }

    /// The camera as scene text to paste in place of the file's camera
    /// transformation and `Camera` line.
    pub fn text(&self) -> String {
        let mut out = String::new();
        let v = &self.view;
        let moving = v.looks.len() > 1;
        for (i, l) in v.looks.iter().enumerate() {
            if moving {
                out += if i == 0 {
                    "ActiveTransform StartTime\n"
                } else {
                    "ActiveTransform EndTime\n"
                };
            }
            if v.flip {
                out += "Scale -1 1 1\n";
            }
            out += &l.text();
            out += "\n";
        }
        if moving {
            out += "ActiveTransform All\n";
        }
        out += &format!("Camera \"{}\"", self.directive.name);
        let orig = self.original_view.lens;
        let lens_values = [
            ("fov", v.lens.fov, orig.fov),
            ("lensradius", v.lens.lens_radius, orig.lens_radius),
            ("focaldistance", v.lens.focal_distance, orig.focal_distance),
        ];
        for (name, text) in &self.directive.params {
            match lens_values.iter().find(|(n, ..)| n == name) {
                Some((_, Some(now), _)) => out += &format!("\n    \"float {name}\" [ {now} ]"),
                _ => out += &format!("\n    {text}"),
            }
        }
        for (name, now, was) in lens_values {
            let written = self.directive.params.iter().any(|(n, _)| n == name);
            if let (Some(now), false) = (now, written) {
                if Some(now) != was {
                    out += &format!("\n    \"float {name}\" [ {now} ]");
                }
            }
        }
        out += "\n";
        out
    }

    /// `/camera`'s and `/status`'s JSON for the camera.
    pub fn json(&self) -> String {
        let n = |v: Option<Float>| v.map_or("null".to_string(), |x| format!("{x}"));
        format!(
            "{{\"number\":{},\"type\":{},\"text\":{},\"fov\":{},\"lensradius\":{},\"focaldistance\":{},\"step\":{}}}",
            self.number,
            super::json_string(self.original.type_name()),
            super::json_string(&self.text()),
            n(self.view.lens.fov),
            n(self.view.lens.lens_radius),
            n(self.view.lens.focal_distance),
            self.step
        )
    }
}

/// Whether every view direction keeps [`MIN_PITCH_GAP`] from its up vector.
fn pitch_ok(view: &View) -> bool {
    let gap = MIN_PITCH_GAP.to_radians().cos();
    view.looks.iter().all(|l| {
        let d = l.look - l.eye;
        d.length() > 0.0 && dot(d.normalize(), l.up.normalize()).abs() < gap
    })
}

/// A `LookAt` giving the placement `world_from_camera` (up to its
/// mirroring, which `Scale -1 1 1` restores): the eye at its origin, the
/// look point one unit along its view direction, and for up the world
/// axis that gives the same orientation when there is one (the scene's
/// own up), else the camera's up.
fn derive_look_at(world_from_camera: &Transform) -> LookAt {
    let eye = world_from_camera.apply_point(Point3f::new(0.0, 0.0, 0.0));
    let dir = world_from_camera
        .apply_vector(Vector3f::new(0.0, 0.0, 1.0))
        .normalize();
    let cam_up = world_from_camera
        .apply_vector(Vector3f::new(0.0, 1.0, 0.0))
        .normalize();
    let axes = [
        Vector3f::new(1.0, 0.0, 0.0),
        Vector3f::new(0.0, 1.0, 0.0),
        Vector3f::new(0.0, 0.0, 1.0),
    ];
    let mut up = cam_up;
    let mut best = 0.0;
    for a in axes.into_iter().flat_map(|a| [a, -a]) {
        let d = dot(a, cam_up);
        // The axis gives the camera's orientation when it lies in the
        // plane of the view direction and the camera's up.
        let off_plane = dot(a, cross(dir, cam_up)).abs();
        if d > best && off_plane < 1e-5 && cross(a, dir).length() > 1e-3 {
            best = d;
            up = a;
        }
    }
    LookAt {
        eye,
        look: eye + dir,
        up,
    }
}

#[cfg(test)]
mod tests;
