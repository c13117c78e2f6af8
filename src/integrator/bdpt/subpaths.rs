//! The camera and light subpaths: random walks from the camera and from a light, each
//! vertex with its forward and reverse area densities.
use super::*;

/// Where a subpath's random walk starts: its first ray (whose closest hit `first_hit`
/// holds when already traced), the throughput and solid-angle density `pdf` it was
/// sampled with, how many bounces it may take and whether it carries radiance or
/// importance.
pub(super) struct Walk<const N: usize> {
    ray: Ray,
    first_hit: Option<Option<Hit>>,
    beta: SampledSpectrum<N>,
    pdf: f32,
    max_bounces: usize,
    mode: TransportMode,
}

impl<'a, const N: usize> Bdpt<'a, N> {
    /// Follows a subpath from `w.ray`, storing vertices after `path[0]`; returns the
    /// number stored.
    pub(super) fn random_walk(
        &self,
        w: Walk<N>,
        path: &mut [Vertex<N>],
        sampler: &mut Sampler,
        counters: &mut TraceCounters,
    ) -> usize {
        let Walk {
            mut ray,
            first_hit,
            mut beta,
            pdf,
            max_bounces,
            mode,
        } = w;
        if max_bounces == 0 {
            return 0;
        }
        let scene = self.scene();
        let mut pdf_fwd = pdf;
        let mut ended = path[0].ended;
        let mut bounces = 0usize;
        let mut pending = first_hit;
        let mut bsdf_ctx = BsdfContext::radiance::<N>().with_mode(mode);
        bsdf_ctx.companions_alive = N > 1 && !ended;
        loop {
            let Some(hit) = next_hit(self.ctx, &ray, &mut pending, counters) else {
                // A camera path that escapes ends on the lights at infinity.
                if mode == TransportMode::Radiance && !scene.infinite_lights.is_empty() {
                    let mut v = Vertex::EMPTY;
                    v.kind = Kind::Light;
                    v.infinite = true;
                    v.p = ray.origin + ray.dir;
                    v.beta = beta;
                    v.ended = ended;
                    v.pdf_fwd = pdf_fwd;
                    path[bounces + 1] = v;
                    bounces += 1;
                }
                break;
            };
            let (it, material) = scene.interaction(&ray, &hit, self.ctx.offset.is_robust());
            let mut v = Vertex::EMPTY;
            v.kind = Kind::Surface;
            v.beta = beta;
            v.p = it.position;
            v.err = it.p_err;
            v.n = it.n_outward;
            v.wo = -ray.dir;
            v.frame = it.frame();
            v.material = it.material;
            v.uv = it.uv;
            v.light = scene.shapes[hit.geom_id as usize].light;
            v.ended = ended;
            v.pdf_fwd = convert_density(pdf_fwd, &path[bounces], &v);
            path[bounces + 1] = v;
            bounces += 1;
            if bounces >= max_bounces {
                break;
            }
            let u_lobe = sampler.get_1d();
            let u_dir = sampler.get_2d();
            let wo_l = v.frame.to_local(v.wo);
            let Some(bs) = material.sample(wo_l, u_lobe, u_dir, self.wl, &bsdf_ctx.at(it.uv))
            else {
                break;
            };
            beta *= bs.weight();
            path[bounces].lobe = bs.flags;
            if bs.ended_companions {
                ended = true;
                bsdf_ctx.companions_alive = false;
            }
            pdf_fwd = bs.pdf;
            let mut pdf_rev = material.pdf(bs.wi, wo_l, self.wl, &bsdf_ctx);
            if bs.is_specular() {
                // A delta lobe has no density to compare, but the MIS ratios through a
                // specular chain still need the chain's Jacobian: a delta counted as
                // density one per projected solid angle (|cos| per solid angle, then
                // converted to area at the next vertex as any direction) makes the
                // ratio between the strategies at the chain's two ends that of the
                // beam's étendue, which refraction and reflection conserve. Zeros here
                // (pbrt's convention) dropped the chain's cos/d² factors, so a lens
                // focusing the sun weighted light tracing's caustic down by 1/d² and
                // left the rest to camera paths that find the sun's disk by chance.
                // Each value is a function of the vertex and the direction alone, so
                // both subpaths compute the same one and the weights still sum to one.
                path[bounces].delta = true;
                pdf_fwd = bs.wi.z.abs();
                pdf_rev = wo_l.z.abs();
            }
            let cur = path[bounces];
            path[bounces - 1].pdf_rev = convert_density(pdf_rev, &cur, &path[bounces - 1]);
            if beta.is_zero() {
                break;
            }
            ray = self
                .ctx
                .offset
                .spawn(&v.spawn_point(), v.frame.to_world(bs.wi));
        }
        bounces
    }

    /// The light subpath; returns its number of vertices.
    pub(super) fn light_subpath(
        &self,
        path: &mut [Vertex<N>],
        max_vertices: usize,
        sampler: &mut Sampler,
        counters: &mut TraceCounters,
    ) -> usize {
        let scene = self.scene();
        let Some(start) = LightPathStart::sample(self.ctx, self.wl, sampler) else {
            return 0;
        };
        let (li, pmf, le) = (start.index, start.pmf, &start.le);
        let light = &scene.lights[li];
        let mut v = Vertex::EMPTY;
        v.kind = Kind::Light;
        v.light = li as u32;
        v.p = le.origin;
        v.err = le.origin_err;
        v.n = if light.is_infinite() {
            Vec3::ZERO
        } else {
            le.normal.unwrap_or(Vec3::ZERO)
        };
        v.infinite = light.is_infinite();
        // Where on a textured area light the path starts, for its emission toward a
        // camera vertex (`le`).
        v.uv = le.uv;
        v.beta = le.l;
        v.pdf_fwd = le.pdf_pos * pmf;
        // A delta light's vertex is not a delta *vertex*: the light itself cannot be
        // hit (s = 0, which `mis_weight` leaves out by `is_delta_light`), but its first
        // bounce can be reached by next-event estimation (s = 1), so the strategies
        // beyond it count (pbrt-v3's `Vertex::CreateLight` leaves `delta` false too).
        // Setting it here gave (s ≥ 2, t) under a point or spot light the weight of a
        // lone strategy, counting those paths twice.
        v.delta = false;
        path[0] = v;
        let beta = start.beta();
        let ray = self.ctx.offset.spawn(&le.spawn_point(), le.dir);
        let walk = Walk {
            ray,
            first_hit: None,
            beta,
            pdf: le.pdf_dir,
            max_bounces: max_vertices - 1,
            mode: TransportMode::Importance,
        };
        let n = self.random_walk(walk, path, sampler, counters);
        if v.infinite {
            // Light paths from infinity: their first vertex's density is positional
            // (per area across the rays), and the origin's is the directions'.
            let w = -le.dir;
            if n > 0 {
                path[1].pdf_fwd = infinite_position_density(scene, w);
                if path[1].on_surface() {
                    path[1].pdf_fwd *= le.dir.dot(path[1].n).abs();
                }
            }
            path[0].pdf_fwd = infinite_light_density(scene, w);
        }
        n + 1
    }

    /// The camera subpath for the camera ray `ray`; returns its number of vertices.
    pub(super) fn camera_subpath(
        &self,
        ray: Ray,
        first_hit: Option<Option<Hit>>,
        path: &mut [Vertex<N>],
        max_vertices: usize,
        sampler: &mut Sampler,
        counters: &mut TraceCounters,
    ) -> usize {
        let cam = &self.scene().camera;
        let mut v = Vertex::EMPTY;
        v.kind = Kind::Camera;
        v.p = ray.origin;
        v.beta = SampledSpectrum::splat(1.0);
        v.pdf_fwd = 1.0;
        path[0] = v;
        let pdf_dir = cam.pdf_we(ray.dir).1;
        let walk = Walk {
            ray,
            first_hit,
            beta: SampledSpectrum::splat(1.0),
            pdf: pdf_dir,
            max_bounces: max_vertices - 1,
            mode: TransportMode::Radiance,
        };
        let n = self.random_walk(walk, path, sampler, counters);
        n + 1
    }
}
