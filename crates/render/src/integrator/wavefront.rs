//! The wavefront path tracer (`--wavefront`; pbrt-v4's flag, not its
//! design): many paths of a tile in flight at once on each thread, taken
//! through the stages of a path vertex together, so that each stage's
//! work can run lane-parallel (book chapter 15 describes pbrt-v4's GPU
//! form of the same idea).
//!
//! The design follows what is fast on a CPU rather than pbrt-v4's
//! `--wavefront` (million-item global queues, one indirect call per item,
//! measured 5–10× slower than its own scalar path): each worker thread
//! keeps a small pool of [`LANES`] paths that stays in cache (MoonRay's
//! per-core queues), refilled from its tile's pixel samples as paths end.
//! A pass over the pool runs four stages:
//!
//! 1. **trace**: the closest hit of every path's ray, as one batch
//!    ([`PrimitiveAggregate::intersect_records`]);
//! 2. **shade**: each path's vertex (the code the scalar loop runs, of
//!    `path` or `volpath`), in two halves: [`VertexIntegrator::begin`]
//!    (delta tracking through media, emission, the BSDF, the sampler
//!    draws) up to the vertex's light-sample request, and, after the
//!    light stage, [`VertexIntegrator::finish`] (the BSDF toward the
//!    light sample, the next ray). Diffuse vertices (`diffuse_lanes.rs`,
//!    of constant or textured reflectance) take both halves in lanes
//!    instead: their surfaces built together
//!    before the first half, their BSDF's answers together before the
//!    second; so do the specular vertices of smooth glass under `path`,
//!    whose whole vertex (no light sample) is the scalar BSDF's sample in
//!    the frame the surface kernel built, and the staged vertices of
//!    constant conductor, rough dielectric and coated materials, whose
//!    BSDF is built in that frame and answered by the BSDF stage, without
//!    the general interaction. Before the surfaces, the hit
//!    meshes' data is prefetched for every path at once where the scene
//!    is too large for the cache;
//! 3. **light**: the requests' lights chosen and sampled together
//!    ([`answer_lights`]: triangle lights' solid-angle samples run
//!    lane-parallel, at the SIMD level's width);
//! 4. **shadow**: the light samples' shadow rays, as one batch, adding the
//!    contributions of the unblocked ones. (In scenes with media or
//!    interfaces `volpath` traces its shadow rays in the shade stage, by
//!    ratio tracking, as its scalar loop does.)
//!
//! With `--stats` each thread times these stages ([`StageClock`]).
//!
//! Every path's arithmetic is the scalar loop's, its sampler
//! dimensions drawn in the same order (each lane keeps a
//! [`SamplerCursor`] into the thread's one sampler), and finished samples
//! are added to the tile in the scalar loop's order through a bounded
//! reorder buffer: the image is the scalar loop's, bit for bit, for
//! any thread count.
//!
//! [`PrimitiveAggregate::intersect_records`]: crate::primitive::PrimitiveAggregate::intersect_records

use super::bsdf_stage::{answer_bsdfs, BsdfAnswers, BsdfBatch, BsdfQuery};
use super::camera_samples::{differential_scale, CameraBatch, CameraDraws, CameraRaySample};
use super::diffuse_lanes::{scatters, surfaces, LaneShade, LaneVertices, LANE_SLOTS};
use super::direct::{answer_lights, LightAnswer, LightBatch, LightRequest};
use super::render::RenderOptions;
use super::stages::{Stage, StageClock};
use super::tile::{add_estimate, RayIntegrator, RayTiles, TileIntegrator};
use super::vertex::{Begin, VertexIntegrator};
use super::Scene;
use crate::film::{FilmTile, SplatBuffer, VisibleSurface};
use crate::primitive::HitRecord;
use crate::sampler::{FourDrawBatch, Sampler, SamplerCursor};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rpbrt_geometry::bounds::Bounds2i;
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::Ray;
use rpbrt_geometry::tuple::*;
use std::ops::Range;

/// Paths in flight per thread. (64 was 3–4% faster on the Cornell box
/// and the water caustic, whose vertices are mostly diffuse lanes, but 5%
/// slower on the killeroo scene at 64 spp, whose coated lane groups thin
/// out. With the staged vertex, 128 was 2–4% slower on both the killeroo
/// crop and the water caustic, and 512 level on the first and 2–5% slower
/// on the second.)
const LANES: usize = 256;
const _: () = assert!(
    LANES <= LANE_SLOTS,
    "a pass's lane vertices need a slot each"
);

/// Finished samples the reorder buffer holds ahead of the oldest path
/// still in flight (a power of two). A path can start only when its
/// sample's slot is free, so one long path holds back at most this many.
const REORDER: usize = 4 * LANES;

/// A path tracer (`path` or `volpath`) under the wavefront loop.
pub(crate) struct Wavefront<'a, I>(pub &'a I);

/// A path in flight.
struct Lane<S> {
    /// The sample's position in the tile's order.
    seq: usize,
    /// Its pixel.
    p_pixel: Point2i,
    /// Where its sampler draws continue.
    cursor: SamplerCursor,
    /// Its wavelengths.
    lambda: SampledWavelengths,
    /// Its path.
    path: S,
    /// The camera ray's weight.
    camera_weight: Float,
    /// The filter's weight.
    filter_weight: Float,
    /// The path has ended (once its shadow ray is traced).
    done: bool,
    /// The ray is the camera ray.
    camera: bool,
    /// The vertex being shaded is a diffuse vertex taken in lanes.
    diffuse: bool,
    /// The vertex being shaded is a specular vertex taken in lanes.
    specular: bool,
    /// The vertex being shaded is a staged vertex taken in lanes.
    staged: bool,
}

/// A lane vertex that asks for a light sample: a diffuse vertex of this
/// reflectance, or a staged vertex of this BSDF.
enum LaneLight {
    Diffuse(SampledSpectrum),
    Staged(crate::bxdf::BSDF),
}

/// A finished sample waiting for its turn to be added to the tile.
struct Finished {
    p_pixel: Point2i,
    l: SampledSpectrum,
    lambda: SampledWavelengths,
    filter_weight: Float,
}

/// What a worker thread keeps from one tile to the next
/// ([`TileIntegrator::Buffers`]): the pool's paths and their scratch, the
/// lane vertices' columns, the reorder buffer and the stages' batches,
/// whose allocation for each tile cost page faults and zero-filling
/// (about 450 KB a tile).
pub(crate) struct PassBuffers<S, C> {
    lanes: Vec<Lane<S>>,
    scratch: Vec<C>,
    vertices: LaneVertices,
    reorder: Option<ReorderBuffer>,
    light_batch: LightBatch,
    bsdf_batch: BsdfBatch,
    draw_batch: FourDrawBatch,
    /// The camera stage's buffers (made for the scene's camera on the
    /// first tile: a worker's buffers serve one scene).
    camera_batch: Option<CameraBatch>,
    camera_draws: Vec<(Point2i, CameraDraws)>,
    camera_samples: Vec<CameraRaySample>,
}

impl<S, C> Default for PassBuffers<S, C> {
    fn default() -> Self {
        PassBuffers {
            lanes: Vec::new(),
            scratch: Vec::new(),
            vertices: LaneVertices::default(),
            reorder: None,
            light_batch: LightBatch::default(),
            bsdf_batch: BsdfBatch::default(),
            draw_batch: FourDrawBatch::default(),
            camera_batch: None,
            camera_draws: Vec::new(),
            camera_samples: Vec::new(),
        }
    }
}

/// Finished samples, added to the tile in sequence order.
struct ReorderBuffer {
    slots: Vec<Option<Finished>>,
    /// Their first visible surfaces (G-buffer films only; otherwise
    /// empty, so that the samples moved around stay small).
    visible: Vec<Option<VisibleSurface>>,
    /// The next sample to add.
    next: usize,
}

impl ReorderBuffer {
    fn new(gbuffer: bool) -> Self {
        ReorderBuffer {
            slots: (0..REORDER).map(|_| None).collect(),
            visible: (0..if gbuffer { REORDER } else { 0 })
                .map(|_| None)
                .collect(),
            next: 0,
        }
    }

    /// The buffer of [`ReorderBuffer::new`]`(gbuffer)`, made from one a
    /// tile left (every sample it started finished, so every slot is
    /// empty again).
    fn reuse(mut self, gbuffer: bool) -> Self {
        debug_assert!(self.slots.iter().all(Option::is_none));
        if self.visible.is_empty() == gbuffer {
            return ReorderBuffer::new(gbuffer);
        }
        self.next = 0;
        self
    }

    /// Whether sample `seq` may start: its slot is free.
    #[inline]
    fn has_room(&self, seq: usize) -> bool {
        seq < self.next + REORDER
    }

    /// Files sample `seq` (and its visible surface) and adds every sample
    /// now in order to `tile`.
    fn finish(
        &mut self,
        seq: usize,
        f: Finished,
        visible: Option<VisibleSurface>,
        tile: &mut FilmTile,
    ) {
        debug_assert!(self.has_room(seq) && seq >= self.next);
        self.slots[seq % REORDER] = Some(f);
        if let Some(slot) = self.visible.get_mut(seq % REORDER) {
            *slot = visible;
        }
        while let Some(f) = self.slots[self.next % REORDER].take() {
            let visible = self
                .visible
                .get_mut(self.next % REORDER)
                .and_then(Option::take);
            add_estimate(
                tile,
                f.p_pixel,
                f.l,
                &f.lambda,
                visible.as_ref(),
                f.filter_weight,
            );
            self.next += 1;
        }
    }
}

impl<I: VertexIntegrator + RayIntegrator> TileIntegrator for Wavefront<'_, I> {
    type Buffers = PassBuffers<I::State, I::Scratch>;

    fn evaluate_pixel_sample(
        &self,
        scene: &Scene,
        opts: &RenderOptions,
        p_pixel: Point2i,
        sampler: &mut Sampler,
        tile: &mut FilmTile,
        splats: &mut SplatBuffer,
        differentials: bool,
    ) {
        RayTiles(self.0).evaluate_pixel_sample(
            scene,
            opts,
            p_pixel,
            sampler,
            tile,
            splats,
            differentials,
        );
    }

    fn render_tile(
        &self,
        scene: &Scene,
        opts: &RenderOptions,
        bounds: Bounds2i,
        samples: Range<i32>,
        sampler: &mut Sampler,
        tile: &mut FilmTile,
        _splats: &mut SplatBuffer,
        differentials: bool,
        buffers: &mut Self::Buffers,
    ) -> u64 {
        let pixels: Vec<Point2i> = bounds.iter().collect();
        let per_pixel = (samples.end - samples.start).max(0) as usize;
        let total = pixels.len() * per_pixel;
        let gbuffer = scene.film.uses_visible_surface();
        let PassBuffers {
            lanes,
            scratch,
            vertices,
            reorder,
            light_batch,
            bsdf_batch,
            draw_batch,
            camera_batch,
            camera_draws,
            camera_samples,
        } = buffers;
        let camera_batch = camera_batch.get_or_insert_with(|| CameraBatch::new(scene));
        let fresh = match reorder.take() {
            Some(r) => r.reuse(gbuffer),
            None => ReorderBuffer::new(gbuffer),
        };
        let reorder = reorder.insert(fresh);
        lanes.clear();
        // The paths' first visible surfaces, by slot (G-buffer films only).
        let mut visibles: Vec<VisibleSurface> = Vec::new();
        // The paths in flight (`lanes`) stay in their slots from start to
        // end (a lane is a few hundred bytes: moving lanes around costs
        // more than indexing them).
        let mut active: Vec<usize> = Vec::with_capacity(LANES);
        let mut free: Vec<usize> = Vec::with_capacity(LANES);
        let mut order: Vec<usize> = Vec::with_capacity(LANES);
        let mut rays: Vec<Ray> = Vec::with_capacity(LANES);
        let mut traced: Vec<Option<HitRecord>> = Vec::with_capacity(LANES);
        let mut hits: Vec<Option<HitRecord>> = Vec::with_capacity(LANES);
        let mut shadow_rays: Vec<(Ray, Float)> = Vec::with_capacity(LANES);
        let mut shadow_lanes: Vec<(usize, SampledSpectrum)> = Vec::with_capacity(LANES);
        let mut blocked: Vec<bool> = Vec::with_capacity(LANES);
        let mut requests: Vec<LightRequest> = Vec::with_capacity(LANES);
        let mut request_lanes: Vec<usize> = Vec::with_capacity(LANES);
        let mut answers: Vec<Option<LightAnswer>> = Vec::with_capacity(LANES);
        let mut bsdf_answers: Vec<BsdfAnswers> = Vec::with_capacity(LANES);
        let mut bsdf_lanes: Vec<usize> = Vec::with_capacity(LANES);
        let mut starts: Vec<(usize, Point2i)> = Vec::with_capacity(LANES);
        let mut cursors: Vec<SamplerCursor> = Vec::with_capacity(LANES);
        let mut draws: Vec<Option<[Float; 6]>> = Vec::with_capacity(LANES);
        let mut shade: Vec<usize> = Vec::with_capacity(LANES);
        let mut predrawn: Vec<Option<[Float; 6]>> = Vec::new();
        // The 1-D draw after them (the second half's Russian roulette).
        let mut next_draws: Vec<Option<Float>> = Vec::with_capacity(LANES);
        let mut predrawn_next: Vec<Option<Float>> = Vec::new();
        let mut diffuse: Vec<usize> = Vec::with_capacity(LANES);
        let mut shades: Vec<LaneShade> = Vec::with_capacity(LANES);
        // A lane's slot in the lane vertices' columns.
        let mut diffuse_slot: Vec<usize> = Vec::new();
        let diff_scale = differential_scale(sampler.samples_per_pixel());
        let mut started = 0;
        let level = opts.simd.unwrap_or_else(crate::simd::level);
        let mut clock = StageClock::new(opts.stage_times.as_deref());
        let prefetch = scene.aggregate.prefetch_pays();
        let mut interleave_shadows = false;
        loop {
            clock.enter(Stage::Camera);
            // Refill the pool in the tile's sample order. Once
            // interrupted, no sample starts; those in flight finish.
            starts.clear();
            cursors.clear();
            while active.len() + starts.len() < LANES
                && started < total
                && reorder.has_room(started)
                && !opts.interrupted()
            {
                let seq = started;
                started += 1;
                let p_pixel = pixels[seq / per_pixel];
                let index = samples.start + (seq % per_pixel) as i32;
                sampler.start_pixel_sample(p_pixel, index, 0);
                starts.push((seq, p_pixel));
                cursors.push(sampler.cursor());
            }
            // The camera samples' draws, computed together and taken by
            // each sample in turn (leaving each cursor past them), then
            // their filter offsets, wavelengths and rays together.
            sampler.four_draws_batch(level, &cursors, draw_batch, &mut draws, None);
            camera_draws.clear();
            for ((&(_, p_pixel), cursor), &d) in starts.iter().zip(cursors.iter_mut()).zip(&draws) {
                let draws = match d {
                    // Taken at the sample's cursor without the sampler.
                    Some(d) => CameraDraws::from_four(cursor.take_four_draws(d)),
                    None => {
                        sampler.set_cursor(cursor);
                        let draws = CameraDraws::take(sampler);
                        *cursor = sampler.cursor();
                        draws
                    }
                };
                camera_draws.push((p_pixel, draws));
            }
            camera_batch.take(
                scene,
                opts,
                level,
                camera_draws,
                differentials,
                diff_scale,
                camera_samples,
            );
            for ((&(seq, p_pixel), cursor), cs) in
                starts.iter().zip(&cursors).zip(camera_samples.drain(..))
            {
                let Some((ray, camera_weight)) = cs.ray else {
                    let f = Finished {
                        p_pixel,
                        l: SampledSpectrum::new(0.0),
                        lambda: cs.lambda,
                        filter_weight: cs.cs.filter_weight,
                    };
                    reorder.finish(seq, f, None, tile);
                    continue;
                };
                let lane = Lane {
                    seq,
                    p_pixel,
                    cursor: *cursor,
                    lambda: cs.lambda,
                    path: self.0.start(ray),
                    camera_weight,
                    filter_weight: cs.cs.filter_weight,
                    done: false,
                    camera: true,
                    diffuse: false,
                    specular: false,
                    staged: false,
                };
                let slot = match free.pop() {
                    Some(slot) => {
                        lanes[slot] = lane;
                        slot
                    }
                    None => {
                        lanes.push(lane);
                        lanes.len() - 1
                    }
                };
                active.push(slot);
                if gbuffer {
                    visibles.resize(lanes.len(), VisibleSurface::default());
                    visibles[slot] = VisibleSurface::default();
                }
            }
            if active.is_empty() {
                break;
            }

            clock.enter(Stage::Trace);
            // Trace: every path's closest hit, camera rays first (as
            // packets: they are consecutive samples of a few pixels).
            order.clear();
            order.extend(active.iter().filter(|&&i| lanes[i].camera));
            let coherent = order.len();
            order.extend(active.iter().filter(|&&i| !lanes[i].camera));
            rays.clear();
            rays.extend(order.iter().map(|&i| I::ray(&lanes[i].path).ray));
            scene.intersect_records(&rays, coherent, level, &mut traced);
            hits.resize(lanes.len(), None);
            for (&i, &h) in order.iter().zip(&traced) {
                hits[i] = h;
            }

            // Shade, first half: one vertex of every path, up to its light
            // sample's request.
            shadow_rays.clear();
            shadow_lanes.clear();
            requests.clear();
            request_lanes.clear();
            if scratch.len() < lanes.len() {
                scratch.resize_with(lanes.len(), Default::default);
            }
            clock.enter(Stage::VertexDraws);
            // The vertices' four draws, together, for the paths that hit
            // something (the others draw nothing; a vertex that draws
            // otherwise, such as a specular one, ignores them), and the
            // 1-D draw after them, which the second half's Russian
            // roulette takes where it draws there.
            shade.clear();
            shade.extend(active.iter().filter(|&&i| hits[i].is_some()));
            cursors.clear();
            cursors.extend(shade.iter().map(|&i| lanes[i].cursor));
            sampler.four_draws_batch(
                level,
                &cursors,
                draw_batch,
                &mut draws,
                Some(&mut next_draws),
            );
            predrawn.clear();
            predrawn.resize(lanes.len(), None);
            predrawn_next.clear();
            predrawn_next.resize(lanes.len(), None);
            for ((&i, &d), &n) in shade.iter().zip(&draws).zip(&next_draws) {
                predrawn[i] = d;
                predrawn_next[i] = n;
            }
            clock.enter(Stage::Surfaces);
            // The diffuse and specular vertices' surfaces, lane-parallel
            // (lanes the surface kernel leaves take the scalar vertex).
            diffuse.clear();
            vertices.clear();
            shades.clear();
            // Their meshes' indices, then vertices, requested for all
            // paths before any is read (large meshes miss the cache).
            for vertices in [false, true].into_iter().filter(|_| prefetch) {
                for &i in &shade {
                    if let Some(h) = &hits[i] {
                        scene.aggregate.prefetch_triangle_hit(h, vertices);
                    }
                }
            }
            for &i in &shade {
                let lane = &lanes[i];
                let Some(h) = &hits[i] else { continue };
                if let Some(shade) =
                    self.0
                        .lane_hit(scene, &lane.path, h, &lane.lambda, gbuffer, vertices)
                {
                    diffuse.push(i);
                    shades.push(shade);
                }
            }
            surfaces(level, vertices);
            diffuse_slot.resize(lanes.len(), 0);
            for &i in &active {
                lanes[i].diffuse = false;
                lanes[i].specular = false;
                lanes[i].staged = false;
            }
            for (k, &i) in diffuse.iter().enumerate() {
                if vertices.ok(k) {
                    match shades[k] {
                        LaneShade::Diffuse(_) | LaneShade::Textured(_) => lanes[i].diffuse = true,
                        LaneShade::Specular(_) => lanes[i].specular = true,
                        LaneShade::Staged(_) => lanes[i].staged = true,
                    }
                    diffuse_slot[i] = k;
                }
            }
            // The textured vertices' lookups prepared together, their
            // texels prefetched.
            for (k, &i) in diffuse.iter().enumerate() {
                if let (true, LaneShade::Textured(m)) = (vertices.ok(k), shades[k]) {
                    vertices.texture_lookup(scene, k, m, I::ray(&lanes[i].path));
                }
            }
            clock.enter(Stage::Begin);
            for &i in &active {
                let lane = &mut lanes[i];
                let k = diffuse_slot[i];
                let shade = (lane.diffuse || lane.specular || lane.staged).then(|| shades[k]);
                lane.camera = false;
                // A staged vertex's BSDF, built first (it draws nothing):
                // one that turns out specular only is left to the scalar
                // vertex, which draws otherwise.
                let lane_light = match shade {
                    Some(LaneShade::Diffuse(r)) => Some(LaneLight::Diffuse(r)),
                    // A black reflectance is left to the scalar vertex.
                    Some(LaneShade::Textured(m)) => {
                        let r = vertices.textured_reflectance(scene, k, m, &lane.lambda);
                        lane.diffuse = r.is_some();
                        r.map(LaneLight::Diffuse)
                    }
                    Some(LaneShade::Staged(m)) => {
                        let mut lambda = lane.lambda;
                        let bsdf = scene
                            .materials
                            .constant_bxdf(m, &mut lambda)
                            .map(|bxdf| vertices.bsdf(k, bxdf))
                            .filter(|b| b.flags().is_non_specular());
                        lane.staged = bsdf.is_some();
                        bsdf.map(|b| {
                            lane.lambda = lambda;
                            LaneLight::Staged(b)
                        })
                    }
                    _ => None,
                };
                if let Some(lane_light) = lane_light {
                    // The draws computed ahead are taken at the lane's
                    // cursor without the sampler.
                    let draws = match predrawn[i] {
                        Some(d) => lane.cursor.take_four_draws(d),
                        None => {
                            sampler.set_cursor(&lane.cursor);
                            let draws = sampler.get_vertex_samples();
                            lane.cursor = sampler.cursor();
                            draws
                        }
                    };
                    let (path, scratch) = (&mut lane.path, &mut scratch[i]);
                    requests.push(match lane_light {
                        LaneLight::Diffuse(r) => {
                            self.0.diffuse_begin(path, scratch, vertices, k, r, draws)
                        }
                        LaneLight::Staged(bsdf) => {
                            self.0.staged_begin(path, scratch, vertices, k, bsdf, draws)
                        }
                    });
                    request_lanes.push(i);
                    continue;
                }
                sampler.set_cursor(&lane.cursor);
                sampler.offer_four_draws(predrawn[i]);
                let begun = match shade {
                    Some(LaneShade::Specular(b)) => Begin::Step(self.0.specular_step(
                        &mut lane.path,
                        &mut scratch[i],
                        &vertices.surface_out(k),
                        b,
                        sampler,
                    )),
                    _ => self.0.begin(
                        scene,
                        &mut lane.path,
                        hits[i],
                        &mut lane.lambda,
                        sampler,
                        visibles.get_mut(i),
                        &mut scratch[i],
                    ),
                };
                lane.cursor = sampler.cursor();
                match begun {
                    Begin::Step(step) => {
                        lane.done = step.done;
                        if let Some(q) = step.shadow {
                            shadow_rays.push((q.ray, q.t_max));
                            shadow_lanes.push((i, q.ld));
                        }
                    }
                    Begin::Light(req) => {
                        requests.push(req);
                        request_lanes.push(i);
                    }
                }
            }

            clock.enter(Stage::Lights);
            // Light: every request's light and its sample.
            answer_lights(
                scene,
                &scene.light_sampler,
                level,
                &requests,
                |k| &lanes[request_lanes[k]].lambda,
                light_batch,
                &mut answers,
            );

            clock.enter(Stage::Bsdfs);
            // BSDF: the other vertices' BSDF queries, lane-parallel for the
            // models with a lane form. Only answers are written: a vertex's
            // second half takes its answers, leaving none behind.
            bsdf_lanes.clear();
            let bsdf_queries: Vec<Option<BsdfQuery>> = request_lanes
                .iter()
                .zip(&answers)
                .filter(|&(&i, _)| !lanes[i].diffuse)
                .filter_map(|(&i, a)| {
                    let q = I::bsdf_query(&lanes[i].path, &scratch[i], a.as_ref())?;
                    bsdf_lanes.push(i);
                    Some(Some(q))
                })
                .collect();
            answer_bsdfs(level, &bsdf_queries, bsdf_batch, &mut bsdf_answers);
            drop(bsdf_queries);
            for (&i, a) in bsdf_lanes.iter().zip(&bsdf_answers) {
                if a.light.is_some() || a.sample.is_some() {
                    *I::bsdf_answers(&mut scratch[i]) = *a;
                }
            }

            clock.enter(Stage::Scatters);
            // The diffuse vertices' BSDF values and samples, lane-parallel.
            for (&i, a) in request_lanes.iter().zip(&answers) {
                if lanes[i].diffuse {
                    let wi = a.as_ref().map_or(Vector3f::default(), |a| a.ls.wi);
                    vertices.set_light_direction(diffuse_slot[i], wi);
                }
            }
            scatters(level, vertices, I::DIFFUSE_SAMPLE_FROM_WO);

            clock.enter(Stage::Finish);
            // Shade, second half: the light samples' shadow queries and the
            // next rays.
            for (&i, answer) in request_lanes.iter().zip(&answers) {
                let lane = &mut lanes[i];
                let step = if lane.diffuse || lane.staged {
                    // The Russian roulette draw, where computed ahead,
                    // taken at the lane's cursor without the sampler.
                    let cursor = &mut lane.cursor;
                    let next = predrawn_next[i];
                    let sampler = &mut *sampler;
                    let draw = || match next {
                        Some(v) => cursor.take_1d(v),
                        None => {
                            sampler.set_cursor(cursor);
                            let v = sampler.get_1d();
                            *cursor = sampler.cursor();
                            v
                        }
                    };
                    let (k, answer) = (diffuse_slot[i], answer.as_ref());
                    if lane.diffuse {
                        let path = &mut lane.path;
                        self.0
                            .diffuse_finish(scene, path, vertices, k, answer, draw)
                    } else {
                        let (path, scratch) = (&mut lane.path, &mut scratch[i]);
                        self.0
                            .staged_finish(scene, path, scratch, vertices, k, answer, draw)
                    }
                } else {
                    sampler.set_cursor(&lane.cursor);
                    sampler.offer_1d(predrawn_next[i]);
                    let step = self.0.finish(
                        scene,
                        &mut lane.path,
                        &mut lane.lambda,
                        sampler,
                        &mut scratch[i],
                        answer.as_ref(),
                    );
                    lane.cursor = sampler.cursor();
                    step
                };
                lane.done = step.done;
                if let Some(q) = step.shadow {
                    shadow_rays.push((q.ray, q.t_max));
                    shadow_lanes.push((i, q.ld));
                }
            }

            clock.enter(Stage::Shadow);
            // Shadow: the light samples' visibility.
            scene.intersect_ps(&shadow_rays, level, interleave_shadows, &mut blocked);
            // Interleaved where most of the last batch was blocked (see
            // `PrimitiveAggregate::intersect_ps`).
            interleave_shadows = 2 * blocked.iter().filter(|&&b| b).count() > blocked.len();
            for (&(i, ld), &b) in shadow_lanes.iter().zip(&blocked) {
                if !b {
                    *I::radiance(&mut lanes[i].path) += ld;
                }
            }

            clock.enter(Stage::Retire);
            // Retire the paths that ended, freeing their slots.
            active.retain(|&i| {
                let lane = &mut lanes[i];
                if !lane.done {
                    return true;
                }
                let f = Finished {
                    p_pixel: lane.p_pixel,
                    l: *I::radiance(&mut lane.path) * lane.camera_weight,
                    lambda: lane.lambda,
                    filter_weight: lane.filter_weight,
                };
                let visible = visibles.get_mut(i).map(std::mem::take);
                reorder.finish(lane.seq, f, visible, tile);
                free.push(i);
                false
            });
        }
        debug_assert_eq!(reorder.next, started);
        started as u64
    }
}
