//! Connecting a light subpath's vertex to a camera subpath's: the geometry term, the
//! shadow ray, the power heuristic's weight over every strategy, and the connection's
//! contribution.
use super::*;

impl<'a, const N: usize> Bdpt<'a, N> {
    /// Geometry term between two vertices with their visibility: 0 when blocked (or
    /// degenerate).
    pub(super) fn g(&self, a: &Vertex<N>, b: &Vertex<N>, counters: &mut TraceCounters) -> f32 {
        let w = b.p - a.p;
        let d2 = w.length_squared();
        if d2 == 0.0 {
            return 0.0;
        }
        let d = d2.sqrt();
        let w = w / d;
        let mut g = 1.0 / d2;
        if a.on_surface() {
            g *= a.n.dot(w).abs();
        }
        if b.on_surface() {
            g *= b.n.dot(w).abs();
        }
        if g == 0.0 {
            return 0.0;
        }
        if self.shadow(&a.spawn_point(), w, d, &b.spawn_point(), counters) {
            g
        } else {
            0.0
        }
    }

    /// Whether the shadow ray between two points is clear, with the render's
    /// `RayOffset` cutoffs (points too close to tell apart count as blocked).
    pub(super) fn shadow(
        &self,
        from: &SpawnPoint,
        w: Vec3,
        dist: f32,
        to: &SpawnPoint,
        counters: &mut TraceCounters,
    ) -> bool {
        unoccluded(
            self.ctx,
            self.ctx.offset.shadow(from, w, dist, to),
            counters,
        )
    }

    /// The power-heuristic weight of strategy (s, t); `sampled` replaces the
    /// connection vertex for s = 1 or t = 1.
    pub(super) fn mis_weight(
        &self,
        light: &mut [Vertex<N>],
        camera: &mut [Vertex<N>],
        sampled: Option<Vertex<N>>,
        s: usize,
        t: usize,
    ) -> f32 {
        if s + t == 2 {
            return 1.0;
        }
        let scene = self.scene();
        // Save what the strategy changes, to restore it afterwards.
        let save_l: [Option<Vertex<N>>; 2] = [
            s.checked_sub(1).map(|i| light[i]),
            s.checked_sub(2).map(|i| light[i]),
        ];
        let save_c: [Option<Vertex<N>>; 2] = [
            t.checked_sub(1).map(|i| camera[i]),
            t.checked_sub(2).map(|i| camera[i]),
        ];
        if s == 1 {
            light[0] = sampled.expect("s = 1 has a sampled light vertex");
        } else if t == 1 {
            camera[0] = sampled.expect("t = 1 has a sampled camera vertex");
        }
        if t > 0 {
            camera[t - 1].delta = false;
        }
        if s > 0 {
            light[s - 1].delta = false;
        }
        // Reverse densities at the connection and one vertex beyond on each side.
        if t > 0 {
            let pt = camera[t - 1];
            camera[t - 1].pdf_rev = if s > 0 {
                let qs_minus = (s > 1).then(|| light[s - 2]);
                self.pdf(&light[s - 1], qs_minus.as_ref(), &pt)
            } else {
                self.pdf_light_origin(&pt, &camera[t - 2])
            };
            if t > 1 {
                let pt_minus = camera[t - 2];
                camera[t - 2].pdf_rev = if s > 0 {
                    self.pdf(&pt, Some(&light[s - 1]), &pt_minus)
                } else {
                    self.pdf_light(&pt, &pt_minus)
                };
            }
        }
        if s > 0 {
            let qs = light[s - 1];
            let pt = camera[t - 1];
            let pt_minus = (t > 1).then(|| camera[t - 2]);
            light[s - 1].pdf_rev = self.pdf(&pt, pt_minus.as_ref(), &qs);
            if s > 1 {
                light[s - 2].pdf_rev = self.pdf(&qs, Some(&pt), &light[s - 2]);
            }
        }
        let remap = |f: f32| if f != 0.0 { f } else { 1.0 };
        let mut sum = 0.0f32;
        let mut ri = 1.0f32;
        for i in (1..t).rev() {
            ri *= remap(camera[i].pdf_rev) / remap(camera[i].pdf_fwd);
            if !camera[i].delta && !camera[i - 1].delta {
                sum += ri * ri;
            }
        }
        ri = 1.0;
        for i in (0..s).rev() {
            ri *= remap(light[i].pdf_rev) / remap(light[i].pdf_fwd);
            let delta_before = if i > 0 {
                light[i - 1].delta
            } else {
                light[0].is_delta_light(scene)
            };
            if !light[i].delta && !delta_before {
                sum += ri * ri;
            }
        }
        // Restore.
        for (k, v) in save_l.iter().enumerate() {
            if let Some(v) = v {
                light[s - 1 - k] = *v;
            }
        }
        for (k, v) in save_c.iter().enumerate() {
            if let Some(v) = v {
                camera[t - 1 - k] = *v;
            }
        }
        let w = 1.0 / (1.0 + sum);
        if w.is_finite() {
            w
        } else {
            0.0
        }
    }

    /// Strategy (s, t): its MIS-weighted contribution to the camera's pixel, or (for
    /// t = 1) a splat; None when it adds nothing or its shadow ray is blocked.
    pub(super) fn connect<T: Transport<N>>(
        &self,
        carry: &T::Bdpt,
        paths: &mut Subpaths<N>,
        (s, t): (usize, usize),
        sampler: &mut Sampler,
        counters: &mut TraceCounters,
    ) -> Option<Connection<T::Value>> {
        let scene = self.scene();
        let (light, camera) = (&mut paths.light[..], &mut paths.camera[..]);
        // A camera path that reached a light is only used as such (s = 0).
        if t > 1 && s != 0 && camera[t - 1].kind == Kind::Light {
            return None;
        }
        let mut sampled = None;
        let l = if s == 0 {
            let pt = camera[t - 1];
            if !pt.is_light() {
                return None;
            }
            self.le(&pt, &camera[t - 2]) * pt.beta
        } else if t == 1 {
            let qs = light[s - 1];
            if !qs.connectible(scene) || qs.infinite {
                return None;
            }
            let cam = &scene.camera;
            let cs = cam.sample_wi(qs.p)?;
            let mut cv = Vertex::EMPTY;
            cv.kind = Kind::Camera;
            cv.p = cam.eye;
            cv.beta = SampledSpectrum::splat(cs.we / cs.pdf);
            // s ≥ 2 here: qs is a surface (s = t = 1 is left to s = 0, t = 2).
            let (f, _) = self.f(&qs, &cv, TransportMode::Importance, N > 1 && !qs.ended);
            let mut c = qs.beta * f;
            c *= cv.beta.0[0];
            if qs.on_surface() {
                c *= qs.n.dot(cs.wi).abs();
            }
            let eye = SpawnPoint::free(cam.eye);
            if c.is_zero() {
                return None;
            }
            if !self.shadow(&qs.spawn_point(), cs.wi, cs.dist, &eye, counters) {
                return None;
            }
            sampled = Some(cv);
            let w = self.mis_weight(light, camera, sampled, s, t);
            return Some(Connection {
                c: T::strategy(carry, self, paths, (s, t), sampled.as_ref(), c * w),
                splat: Some(pixel_of(cam, cs.raster)),
            });
        } else if s == 1 {
            let pt = camera[t - 1];
            let u_light = sampler.get_1d();
            let u_point = sampler.get_2d();
            if !pt.connectible(scene) {
                return None;
            }
            let (li, pmf) = scene.light_sampler.sample(u_light)?;
            let lt = &scene.lights[li];
            let ls = lt.sample_li(pt.p, u_point, self.wl)?;
            if !(ls.pdf > 0.0) || ls.l.is_zero() {
                return None;
            }
            let mut lv = Vertex::EMPTY;
            lv.kind = Kind::Light;
            lv.light = li as u32;
            lv.infinite = lt.is_infinite();
            lv.p = if ls.dist.is_finite() {
                pt.p + ls.wi * ls.dist
            } else {
                pt.p + ls.wi * (2.0 * scene.bounds.radius + (pt.p - scene.bounds.center).length())
            };
            lv.n = ls.n;
            lv.beta = ls.l / (ls.pdf * pmf);
            lv.delta = lt.is_delta();
            lv.pdf_fwd = self.pdf_light_origin(&lv, &pt);
            let (f, _) = self.f(&pt, &lv, TransportMode::Radiance, N > 1 && !pt.ended);
            let mut c = pt.beta * f * lv.beta;
            if pt.on_surface() {
                c *= pt.n.dot(ls.wi).abs();
            }
            if c.is_zero() {
                return None;
            }
            if !self.shadow(&pt.spawn_point(), ls.wi, ls.dist, &ls.target(), counters) {
                return None;
            }
            sampled = Some(lv);
            c
        } else {
            let (qs, pt) = (light[s - 1], camera[t - 1]);
            if !qs.connectible(scene) || !pt.connectible(scene) || qs.infinite {
                return None;
            }
            let alive = N > 1 && !qs.ended && !pt.ended;
            let (fq, ended_q) = self.f(&qs, &pt, TransportMode::Importance, alive);
            let (fp, _) = self.f(&pt, &qs, TransportMode::Radiance, alive && !ended_q);
            let mut c = qs.beta * fq * fp * pt.beta;
            if qs.ended && pt.ended {
                // Each subpath carries the hero's factor N; the path carries it once.
                c *= 1.0 / N as f32;
            }
            if c.is_zero() {
                return None;
            }
            c * self.g(&qs, &pt, counters)
        };
        if l.is_zero() {
            return None;
        }
        let c = l * self.mis_weight(light, camera, sampled, s, t);
        Some(Connection {
            c: T::strategy(carry, self, paths, (s, t), sampled.as_ref(), c),
            splat: None,
        })
    }
}
