//! The realistic camera (book section 5.4; pbrt-v4 `RealisticCamera`): rays
//! from the film traced through a system of spherical lens elements and an
//! aperture stop, focused by a thick-lens approximation and sampled through
//! precomputed bounds on the exit pupil.
//!
//! Camera space puts the film at z = 0 and the lens elements at z > 0;
//! "lens space" flips z so the elements lie at z < 0, rear element first.

use rpbrt_geometry::{
    dot, lerp, quadratic, safe_sqrt, sqr, Bounds2f, Float, Normal3f, Point2f, Point3f, Ray,
    Vector3f, ONE_MINUS_EPSILON, PI,
};

use super::{differential_by_offset, CameraBase, CameraRay, CameraRayDifferential, CameraSample};

/// One interface of the lens system, in metres (pbrt-v4
/// `LensElementInterface`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LensElementInterface {
    /// Radius of the spherical surface; 0 for the aperture stop; positive
    /// when convex toward the scene.
    pub curvature_radius: Float,
    /// Distance along the axis to the next interface toward the film.
    pub thickness: Float,
    /// Index of refraction of the medium on the film side (0 for the stop).
    pub eta: Float,
    /// Radius of the element's opening.
    pub aperture_radius: Float,
}

/// A single-channel image weighting points of the aperture stop (pbrt-v4
/// uses an `Image` with bilinear lookups and black outside).
#[derive(Clone, Debug, PartialEq)]
pub struct ApertureImage {
    width: usize,
    height: usize,
    data: Vec<Float>,
}

/// Resolution of the built-in aperture shapes.
const BUILTIN_RES: usize = 256;

impl ApertureImage {
    /// An image from row-major values (row 0 first as stored in an image
    /// file), flipped vertically and scaled so that its mean is π/4 (the
    /// fraction of the square a circular aperture covers), as pbrt-v4
    /// prepares aperture images. `None` when the sizes disagree or the
    /// image is all zero.
    pub fn from_pixels(width: usize, height: usize, values: Vec<Float>) -> Option<Self> {
        if width == 0 || height == 0 || values.len() != width * height {
            return None;
        }
        let mut data = Vec::with_capacity(values.len());
        for y in (0..height).rev() {
            data.extend_from_slice(&values[y * width..(y + 1) * width]);
        }
        let sum: f64 = data.iter().map(|&v| v as f64).sum();
        let avg = sum / (width * height) as f64;
        if !(avg > 0.0 && avg.is_finite()) {
            return None;
        }
        let scale = (std::f64::consts::PI / 4.0 / avg) as Float;
        for v in &mut data {
            *v *= scale;
        }
        Some(ApertureImage {
            width,
            height,
            data,
        })
    }

    /// One of pbrt-v4's built-in diaphragm shapes: `gaussian`, `square`,
    /// `pentagon` or `star`.
    pub fn builtin(name: &str) -> Option<Self> {
        let n = BUILTIN_RES;
        let centre = |i: usize| -1.0 + 2.0 * (i as Float + 0.5) / n as Float;
        let values = match name {
            "gaussian" => {
                let mut v = Vec::with_capacity(n * n);
                for y in 0..n {
                    for x in 0..n {
                        let r2 = sqr(centre(x)) + sqr(centre(y));
                        v.push(((-r2).exp() - (-1.0 as Float).exp()).max(0.0));
                    }
                }
                v
            }
            "square" => {
                let mut v = vec![0.0; n * n];
                let (lo, hi) = (n / 4, 3 * n / 4);
                for y in lo..hi {
                    for x in lo..hi {
                        v[y * n + x] = 4.0;
                    }
                }
                v
            }
            "pentagon" => {
                let s5 = (5.0 as Float).sqrt();
                let c1 = (s5 - 1.0) / 4.0;
                let c2 = (s5 + 1.0) / 4.0;
                let s1 = (10.0 + 2.0 * s5).sqrt() / 4.0;
                let s2 = (10.0 - 2.0 * s5).sqrt() / 4.0;
                let vert: Vec<Point2f> = [(0.0, 1.0), (s1, c1), (s2, -c2), (-s2, -c2), (-s1, c1)]
                    .iter()
                    .map(|&(x, y)| Point2f::new(0.8 * x, 0.8 * y))
                    .collect();
                rasterize_polygon(&vert, n)
            }
            "star" => {
                let inner = (72.0 as Float).to_radians().cos() / (36.0 as Float).to_radians().cos();
                let mut vert: Vec<Point2f> = (0..10)
                    .map(|i| {
                        let r = if i & 1 == 1 { 1.0 } else { inner };
                        let a = PI * i as Float / 5.0;
                        Point2f::new(r * a.cos(), r * a.sin())
                    })
                    .collect();
                vert.reverse();
                rasterize_polygon(&vert, n)
            }
            _ => return None,
        };
        ApertureImage::from_pixels(n, n, values)
    }

    /// The bilinearly interpolated value at `uv` in \[0,1\]², zero outside.
    pub fn bilerp(&self, uv: Point2f) -> Float {
        let x = uv.x * self.width as Float - 0.5;
        let y = uv.y * self.height as Float - 0.5;
        let (xf, yf) = (x.floor(), y.floor());
        let (dx, dy) = (x - xf, y - yf);
        let (xi, yi) = (xf as i64, yf as i64);
        let get = |px: i64, py: i64| -> Float {
            if px < 0 || py < 0 || px >= self.width as i64 || py >= self.height as i64 {
                0.0
            } else {
                self.data[py as usize * self.width + px as usize]
            }
        };
        (1.0 - dx) * (1.0 - dy) * get(xi, yi)
            + dx * (1.0 - dy) * get(xi + 1, yi)
            + (1.0 - dx) * dy * get(xi, yi + 1)
            + dx * dy * get(xi + 1, yi + 1)
    }
}

/// Fills pixels whose centres have a nonzero winding number with respect
/// to the polygon `vert` (over [−1,1]²).
fn rasterize_polygon(vert: &[Point2f], n: usize) -> Vec<Float> {
    let mut out = vec![0.0; n * n];
    for y in 0..n {
        for x in 0..n {
            let p = Point2f::new(
                -1.0 + 2.0 * (x as Float + 0.5) / n as Float,
                -1.0 + 2.0 * (y as Float + 0.5) / n as Float,
            );
            let mut winding = 0;
            for i in 0..vert.len() {
                let (a, b) = (vert[i], vert[(i + 1) % vert.len()]);
                let e = (p.x - a.x) * (b.y - a.y) - (p.y - a.y) * (b.x - a.x);
                if a.y <= p.y {
                    if b.y > p.y && e > 0.0 {
                        winding += 1;
                    }
                } else if b.y <= p.y && e < 0.0 {
                    winding -= 1;
                }
            }
            out[y * n + x] = if winding == 0 { 0.0 } else { 1.0 };
        }
    }
    out
}

/// The radical inverse of `a` in `base` (pbrt-v4 `RadicalInverse`).
fn radical_inverse(base: u64, mut a: u64) -> Float {
    let inv_base = 1.0 / base as f64;
    let mut inv_base_m = 1.0;
    let mut reversed: u64 = 0;
    let limit = u64::MAX / base - base;
    while a != 0 && reversed < limit {
        let next = a / base;
        let digit = a - next * base;
        reversed = reversed * base + digit;
        inv_base_m *= inv_base;
        a = next;
    }
    ((reversed as f64 * inv_base_m) as Float).min(ONE_MINUS_EPSILON)
}

/// Refracts `wi` (pointing away from the surface) through normal `n` with
/// relative index `eta`; `None` on total internal reflection.
fn refract(wi: Vector3f, n: Normal3f, eta: Float) -> Option<Vector3f> {
    let mut n = Vector3f::from(n);
    let mut eta = eta;
    let mut cos_i = dot(wi, n);
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
        n = -n;
    }
    let sin2_i = (1.0 - sqr(cos_i)).max(0.0);
    let sin2_t = sin2_i / sqr(eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = safe_sqrt(1.0 - sin2_t);
    Some(-wi / eta + n * (cos_i / eta - cos_t))
}

/// Where a lens-space ray meets a spherical element of `radius` centred at
/// `z_center` on the axis, with the normal facing the ray's origin.
fn intersect_spherical_element(
    radius: Float,
    z_center: Float,
    ray: &Ray,
) -> Option<(Float, Normal3f)> {
    let o = ray.o - Vector3f::new(0.0, 0.0, z_center);
    let d = ray.d;
    let a = d.x * d.x + d.y * d.y + d.z * d.z;
    let b = 2.0 * (d.x * o.x + d.y * o.y + d.z * o.z);
    let c = o.x * o.x + o.y * o.y + o.z * o.z - radius * radius;
    let (t0, t1) = quadratic(a, b, c)?;
    let use_closer = (d.z > 0.0) ^ (radius < 0.0);
    let t = if use_closer { t0.min(t1) } else { t0.max(t1) };
    if t < 0.0 {
        return None;
    }
    let n = Normal3f::from((Vector3f::from(o) + d * t).try_normalize()?);
    Some((t, n.face_forward(-d)))
}

#[inline]
fn flip_z(r: &Ray) -> Ray {
    Ray::with_time(
        Point3f::new(r.o.x, r.o.y, -r.o.z),
        Vector3f::new(r.d.x, r.d.y, -r.d.z),
        r.time,
        r.medium,
    )
}

/// A camera simulating a real lens system.
#[derive(Clone, Debug)]
pub struct RealisticCamera {
    /// Shared camera state.
    pub base: CameraBase,
    /// The sensor's extent in metres, centred on the optical axis.
    pub physical_extent: Bounds2f,
    /// The interfaces from the scene side to the film side; the last one's
    /// thickness is the focused lens–film distance.
    pub elements: Vec<LensElementInterface>,
    /// Optional weighting of the aperture stop.
    pub aperture_image: Option<ApertureImage>,
    /// Exit-pupil bounds on the rear element's plane for rings of film
    /// radius, from the centre out to half the diagonal.
    pub exit_pupil_bounds: Vec<Bounds2f>,
}

/// The number of film-radius rings with exit-pupil bounds.
pub(crate) const EXIT_PUPIL_RINGS: usize = 64;

impl RealisticCamera {
    /// Builds the camera from lens rows (curvature radius, thickness, eta,
    /// aperture diameter, all in millimetres, four values per interface),
    /// focuses it at `focus_distance` metres, limits the stop to
    /// `aperture_diameter_mm`, and bounds the exit pupil with
    /// `pupil_samples` traced rays per ring (pbrt-v4: 1024²). Returns the
    /// camera and warnings, or an error message.
    pub fn new(
        base: CameraBase,
        lens_params: &[Float],
        focus_distance: Float,
        aperture_diameter_mm: Float,
        aperture_image: Option<ApertureImage>,
        pupil_samples: usize,
    ) -> Result<(Self, Vec<String>), String> {
        let mut warnings = Vec::new();
        if lens_params.is_empty() || !lens_params.chunks_exact(4).remainder().is_empty() {
            return Err(format!(
                "lens description must have four values per element; got {}",
                lens_params.len()
            ));
        }
        let res = base.film.full_resolution;
        let aspect = res.y as Float / res.x as Float;
        let diagonal = base.film.diagonal_m;
        let x = (sqr(diagonal) / (1.0 + sqr(aspect))).sqrt();
        let y = aspect * x;
        let physical_extent = Bounds2f::new(
            Point2f::new(-x / 2.0, -y / 2.0),
            Point2f::new(x / 2.0, y / 2.0),
        );

        let mut set_aperture = aperture_diameter_mm;
        let mut elements = Vec::with_capacity(lens_params.len() / 4);
        for row in lens_params.chunks_exact(4) {
            let curvature_radius = row[0] / 1000.0;
            let thickness = row[1] / 1000.0;
            let eta = row[2];
            let mut diameter = row[3] / 1000.0;
            if !(row.iter().all(|v| v.is_finite()) && diameter > 0.0 && thickness >= 0.0) {
                return Err(format!(
                    "bad lens element [{} {} {} {}]: values must be finite, with a positive \
                     aperture diameter and a non-negative thickness",
                    row[0], row[1], row[2], row[3]
                ));
            }
            if curvature_radius == 0.0 {
                set_aperture /= 1000.0;
                if set_aperture > diameter {
                    warnings.push(format!(
                        "aperture diameter {} is greater than maximum possible {}; clamping it",
                        set_aperture * 1000.0,
                        diameter * 1000.0
                    ));
                } else {
                    diameter = set_aperture;
                }
            } else if eta < 0.0 {
                return Err(format!(
                    "lens element index of refraction {eta} is negative"
                ));
            }
            elements.push(LensElementInterface {
                curvature_radius,
                thickness,
                eta,
                aperture_radius: diameter / 2.0,
            });
        }

        let mut cam = RealisticCamera {
            base,
            physical_extent,
            elements,
            aperture_image,
            exit_pupil_bounds: Vec::new(),
        };
        let film_distance = cam.focus_thick_lens(focus_distance)?;
        if let Some(last) = cam.elements.last_mut() {
            last.thickness = film_distance;
        }
        cam.exit_pupil_bounds = cam.compute_exit_pupil_bounds(pupil_samples.max(1));

        let mut base = cam.base.clone();
        base.find_minimum_differentials(|b, s| {
            differential_by_offset(s, |s| cam.ray_with_base(b, s))
        });
        cam.base = base;
        Ok((cam, warnings))
    }

    /// Finds the minimum differentials again, after the placement changed
    /// ([`super::Camera::placed`]).
    pub(crate) fn refind_minimum_differentials(&mut self) {
        let mut base = self.base.clone();
        base.find_minimum_differentials(|b, s| {
            differential_by_offset(s, |s| self.ray_with_base(b, s))
        });
        self.base = base;
    }

    /// The z of the rear element (the lens–film distance).
    #[inline]
    pub fn lens_rear_z(&self) -> Float {
        self.elements.last().map_or(0.0, |e| e.thickness)
    }

    /// The z of the front element.
    pub fn lens_front_z(&self) -> Float {
        self.elements.iter().map(|e| e.thickness).sum()
    }

    /// The rear element's aperture radius.
    #[inline]
    pub fn rear_element_radius(&self) -> Float {
        self.elements.last().map_or(0.0, |e| e.aperture_radius)
    }

    /// Traces a camera-space ray from the film side through the elements;
    /// returns the aperture weight (0 when blocked) and the ray leaving the
    /// front element, in camera space (pbrt-v4 `TraceLensesFromFilm`).
    pub fn trace_lenses_from_film(&self, r_camera: &Ray) -> (Float, Option<Ray>) {
        let mut element_z = 0.0;
        let mut weight = 1.0;
        let mut r = flip_z(r_camera);
        for i in (0..self.elements.len()).rev() {
            let element = &self.elements[i];
            element_z -= element.thickness;
            let is_stop = element.curvature_radius == 0.0;
            let (t, n) = if is_stop {
                let t = (element_z - r.o.z) / r.d.z;
                if t.is_nan() || t < 0.0 {
                    return (0.0, None);
                }
                (t, Normal3f::default())
            } else {
                let z_center = element_z + element.curvature_radius;
                match intersect_spherical_element(element.curvature_radius, z_center, &r) {
                    Some(hit) => hit,
                    None => return (0.0, None),
                }
            };
            let p_hit = r.at(t);
            match (&self.aperture_image, is_stop) {
                (Some(img), true) => {
                    let uv = Point2f::new(
                        (p_hit.x / element.aperture_radius + 1.0) / 2.0,
                        (p_hit.y / element.aperture_radius + 1.0) / 2.0,
                    );
                    weight = img.bilerp(uv);
                    if weight == 0.0 {
                        return (0.0, None);
                    }
                }
                _ => {
                    if sqr(p_hit.x) + sqr(p_hit.y) > sqr(element.aperture_radius) {
                        return (0.0, None);
                    }
                }
            }
            r.o = p_hit;
            if !is_stop {
                let eta_i = element.eta;
                let eta_t = if i > 0 && self.elements[i - 1].eta != 0.0 {
                    self.elements[i - 1].eta
                } else {
                    1.0
                };
                match refract((-r.d).normalize(), n, eta_t / eta_i) {
                    Some(w) => r.d = w,
                    None => return (0.0, None),
                }
            }
        }
        (weight, Some(flip_z(&r)))
    }

    /// Traces a camera-space ray from the scene side to the film; `None`
    /// when blocked (pbrt-v4 `TraceLensesFromScene`; the aperture image is
    /// ignored).
    pub fn trace_lenses_from_scene(&self, r_camera: &Ray) -> Option<Ray> {
        let mut element_z = -self.lens_front_z();
        let mut r = flip_z(r_camera);
        for (i, element) in self.elements.iter().enumerate() {
            let is_stop = element.curvature_radius == 0.0;
            let (t, n) = if is_stop {
                let t = (element_z - r.o.z) / r.d.z;
                if t.is_nan() || t < 0.0 {
                    return None;
                }
                (t, Normal3f::default())
            } else {
                let z_center = element_z + element.curvature_radius;
                intersect_spherical_element(element.curvature_radius, z_center, &r)?
            };
            let p_hit = r.at(t);
            if sqr(p_hit.x) + sqr(p_hit.y) > sqr(element.aperture_radius) {
                return None;
            }
            r.o = p_hit;
            if !is_stop {
                let eta_i = if i == 0 || self.elements[i - 1].eta == 0.0 {
                    1.0
                } else {
                    self.elements[i - 1].eta
                };
                let eta_t = if element.eta != 0.0 { element.eta } else { 1.0 };
                r.d = refract((-r.d).normalize(), n, eta_t / eta_i)?;
            }
            element_z += element.thickness;
        }
        Some(flip_z(&r))
    }

    /// The principal plane and focal point z for a ray entering parallel to
    /// the axis (`r_in`) and leaving (`r_out`).
    fn cardinal_points(r_in: &Ray, r_out: &Ray) -> (Float, Float) {
        let tf = -r_out.o.x / r_out.d.x;
        let fz = -r_out.at(tf).z;
        let tp = (r_in.o.x - r_out.o.x) / r_out.d.x;
        let pz = -r_out.at(tp).z;
        (pz, fz)
    }

    /// Cardinal points on the film side ([0]) and the scene side ([1]).
    fn thick_lens_approximation(&self) -> Result<([Float; 2], [Float; 2]), String> {
        let x = 0.001 * self.base.film.diagonal_m;
        let r_scene = Ray::new(
            Point3f::new(x, 0.0, self.lens_front_z() + 1.0),
            Vector3f::new(0.0, 0.0, -1.0),
        );
        let r_film = self.trace_lenses_from_scene(&r_scene).ok_or_else(|| {
            "unable to trace a ray from the scene to the film for the thick lens \
             approximation; is the aperture stop extremely small?"
                .to_string()
        })?;
        let (pz0, fz0) = Self::cardinal_points(&r_scene, &r_film);
        let r_film = Ray::new(
            Point3f::new(x, 0.0, self.lens_rear_z() - 1.0),
            Vector3f::new(0.0, 0.0, 1.0),
        );
        let (w, r_scene) = self.trace_lenses_from_film(&r_film);
        let r_scene = match r_scene {
            Some(r) if w != 0.0 => r,
            _ => {
                return Err(
                    "unable to trace a ray from the film to the scene for the thick \
                            lens approximation; is the aperture stop extremely small?"
                        .to_string(),
                )
            }
        };
        let (pz1, fz1) = Self::cardinal_points(&r_film, &r_scene);
        Ok(([pz0, pz1], [fz0, fz1]))
    }

    /// The lens–film distance that focuses at `focus_distance` (pbrt-v4
    /// `FocusThickLens`).
    fn focus_thick_lens(&self, focus_distance: Float) -> Result<Float, String> {
        let (pz, fz) = self.thick_lens_approximation()?;
        let f = fz[0] - pz[0];
        let z = -focus_distance;
        let c = (pz[1] - z - pz[0]) * (pz[1] - z - 4.0 * f - pz[0]);
        if c.is_nan() || c <= 0.0 {
            return Err(format!(
                "focus distance {focus_distance} is too short for this lens system \
                 (thick-lens coefficient {c} is not positive)"
            ));
        }
        let delta = (pz[1] - z + pz[0] - c.sqrt()) / 2.0;
        let d = self.lens_rear_z() + delta;
        if !(d.is_finite() && d > 0.0) {
            return Err(format!(
                "focusing at {focus_distance} gives a lens-film distance of {d}"
            ));
        }
        Ok(d)
    }

    /// Bounds on the rear element's plane of the points that rays from the
    /// film segment [x0, x1] on the x axis pass through (pbrt-v4
    /// `BoundExitPupil`).
    pub fn bound_exit_pupil(&self, film_x0: Float, film_x1: Float, n_samples: usize) -> Bounds2f {
        let mut pupil = Bounds2f::default();
        let rear_r = self.rear_element_radius();
        let proj = Bounds2f::new(
            Point2f::new(-1.5 * rear_r, -1.5 * rear_r),
            Point2f::new(1.5 * rear_r, 1.5 * rear_r),
        );
        let rear_z = self.lens_rear_z();
        for i in 0..n_samples {
            let p_film = Point3f::new(
                lerp((i as Float + 0.5) / n_samples as Float, film_x0, film_x1),
                0.0,
                0.0,
            );
            let u = [radical_inverse(2, i as u64), radical_inverse(3, i as u64)];
            let p_rear = Point3f::new(
                lerp(u[0], proj.p_min.x, proj.p_max.x),
                lerp(u[1], proj.p_min.y, proj.p_max.y),
                rear_z,
            );
            let p2 = Point2f::new(p_rear.x, p_rear.y);
            if !pupil.inside(p2)
                && self
                    .trace_lenses_from_film(&Ray::new(p_film, p_rear - p_film))
                    .0
                    != 0.0
            {
                pupil = pupil.union_point(p2);
            }
        }
        if pupil.p_min.x > pupil.p_max.x || pupil.p_min.y > pupil.p_max.y {
            return pupil;
        }
        let d = proj.diagonal();
        pupil.expand(2.0 * (d.x * d.x + d.y * d.y).sqrt() / (n_samples as Float).sqrt())
    }

    fn compute_exit_pupil_bounds(&self, n_samples: usize) -> Vec<Bounds2f> {
        let half = self.base.film.diagonal_m / 2.0;
        let ring = |i: usize| {
            let r0 = i as Float / EXIT_PUPIL_RINGS as Float * half;
            let r1 = (i + 1) as Float / EXIT_PUPIL_RINGS as Float * half;
            self.bound_exit_pupil(r0, r1, n_samples)
        };
        let threads = std::thread::available_parallelism()
            .map_or(1, |n| n.get())
            .clamp(1, EXIT_PUPIL_RINGS);
        if threads == 1 {
            return (0..EXIT_PUPIL_RINGS).map(ring).collect();
        }
        let mut out = vec![Bounds2f::default(); EXIT_PUPIL_RINGS];
        let chunk = EXIT_PUPIL_RINGS.div_ceil(threads);
        std::thread::scope(|s| {
            for (c, slots) in out.chunks_mut(chunk).enumerate() {
                let ring = &ring;
                s.spawn(move || {
                    for (j, slot) in slots.iter_mut().enumerate() {
                        *slot = ring(c * chunk + j);
                    }
                });
            }
        });
        out
    }

    /// A point on the rear element's plane inside the exit pupil for film
    /// point `p_film` (metres) and its density per unit area.
    pub fn sample_exit_pupil(&self, p_film: Point2f, u_lens: Point2f) -> Option<(Point3f, Float)> {
        let r_film = (sqr(p_film.x) + sqr(p_film.y)).sqrt();
        let n = self.exit_pupil_bounds.len();
        let idx = (r_film / (self.base.film.diagonal_m / 2.0) * n as Float) as usize;
        let bounds = self.exit_pupil_bounds.get(idx.min(n.checked_sub(1)?))?;
        if bounds.p_min.x > bounds.p_max.x || bounds.p_min.y > bounds.p_max.y {
            return None;
        }
        let p_lens = bounds.lerp(u_lens);
        let pdf = 1.0 / bounds.area();
        let (sin_t, cos_t) = if r_film != 0.0 {
            (p_film.y / r_film, p_film.x / r_film)
        } else {
            (0.0, 1.0)
        };
        Some((
            Point3f::new(
                cos_t * p_lens.x - sin_t * p_lens.y,
                sin_t * p_lens.x + cos_t * p_lens.y,
                self.lens_rear_z(),
            ),
            pdf,
        ))
    }

    /// The physical film point (camera space, metres) for a raster
    /// position; x is mirrored because the lens inverts the image.
    pub fn film_point(&self, p_raster: Point2f) -> Point3f {
        let res = self.base.film.full_resolution;
        let s = Point2f::new(p_raster.x / res.x as Float, p_raster.y / res.y as Float);
        let p = self.physical_extent.lerp(s);
        Point3f::new(-p.x, p.y, 0.0)
    }

    fn ray_with_base(&self, base: &CameraBase, sample: &CameraSample) -> Option<CameraRay> {
        let p_film = self.film_point(sample.p_film);
        let (p_pupil, pdf) =
            self.sample_exit_pupil(Point2f::new(p_film.x, p_film.y), sample.p_lens)?;
        let r_film = Ray::new(p_film, p_pupil - p_film);
        let (mut weight, ray) = self.trace_lenses_from_film(&r_film);
        let mut ray = ray?;
        if weight == 0.0 {
            return None;
        }
        ray.time = base.sample_time(sample.time);
        ray.medium = base.medium;
        let mut ray = base.render_from_camera_ray(&ray);
        ray.d = ray.d.normalize();
        let cos_theta = r_film.d.normalize().z;
        weight *= sqr(sqr(cos_theta)) / (pdf * sqr(self.lens_rear_z()));
        Some(CameraRay { ray, weight })
    }

    /// The ray for a film sample, traced through the lens system; `None`
    /// when it is vignetted.
    #[inline]
    pub fn generate_ray(&self, sample: &CameraSample) -> Option<CameraRay> {
        self.ray_with_base(&self.base, sample)
    }

    /// The ray with its neighbours, found by offsetting the film sample.
    pub fn generate_ray_differential(
        &self,
        sample: &CameraSample,
    ) -> Option<CameraRayDifferential> {
        differential_by_offset(sample, |s| self.generate_ray(s))
    }
}
