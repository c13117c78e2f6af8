//! What a strategy of polarised BDPT carries: Stokes radiance from the camera subpath's
//! Mueller chain and the light subpath's beam (the BDPT state of the transport
//! `integrator::polarized::Polarized`; unpolarised BDPT carries nothing).
use super::*;
use crate::spectrum::stokes::StokesSpectrum;

/// Polarised BDPT: the camera subpath's [`Chain`] on each of its segments and the light
/// subpath's [`Beam`] on each of its, from which every strategy's Stokes radiance is the
/// camera side's chain through the connection's two events applied to the light side's
/// beam (`integrator::polarized` has the convention).
pub(crate) struct PolarizedSubpaths<const N: usize> {
    /// `chains[i]`: on the segment from camera vertex i to i − 1 (i ≥ 1).
    chains: [Chain<N>; MAX_VERTICES],
    /// `beams[j]`: on the segment from light vertex j − 1 to j (j ≥ 1).
    beams: [Beam<N>; MAX_VERTICES],
}

impl<const N: usize> Bdpt<'_, N> {
    /// The surface event at `v` toward its own subpath's previous vertex.
    fn event<'s>(&'s self, v: &'s Vertex<N>) -> Event<'s> {
        self.event_toward(v, v.wo)
    }

    /// The surface event at `v` with light leaving toward `to` (world).
    fn event_toward<'s>(&'s self, v: &'s Vertex<N>, to: Vec3) -> Event<'s> {
        Event::Surface {
            material: &self.scene().materials[v.material as usize],
            frame: &v.frame,
            wo_local: v.frame.to_local(to),
        }
    }

    /// The chain `chain` past the connection vertex `v` (light arriving from `from`,
    /// leaving toward `to`) by its non-delta lobes.
    fn chain_past(&self, chain: &Chain<N>, v: &Vertex<N>, to: Vec3, from: Vec3) -> Chain<N> {
        let e = self.event_toward(v, to);
        chain.past(&e, from, v.frame.to_local(from), non_delta(&e), self.wl)
    }
}

impl<const N: usize> PolarizedSubpaths<N> {
    /// From the two subpaths, once traced; `dir` is the camera ray's direction.
    pub(crate) fn new(b: &Bdpt<N>, paths: &Subpaths<N>, dir: Vec3) -> Self {
        let light = &paths.light[..paths.n_light];
        let camera = &paths.camera[..paths.n_camera];
        let (scene, wl) = (b.scene(), b.wl);
        let mut chains = [Chain::at_camera(b.ctx, dir); MAX_VERTICES];
        for i in 1..camera.len().saturating_sub(1) {
            let v = &camera[i];
            let wi = direction(v, &camera[i + 1]);
            let e = b.event(v);
            chains[i + 1] = chains[i].past(&e, wi, v.frame.to_local(wi), v.lobe, wl);
        }
        let mut beams = [Beam::unpolarized(); MAX_VERTICES];
        if light.len() > 1 {
            let d = direction(&light[0], &light[1]);
            beams[1] = Beam::emitted(scene, light[0].light as usize, d, wl);
        }
        for j in 1..light.len().saturating_sub(1) {
            let v = &light[j];
            let (to, from) = (direction(v, &light[j + 1]), v.wo);
            let material = &scene.materials[v.material as usize];
            beams[j + 1] = beams[j].scatter(
                material,
                &v.frame,
                v.frame.to_local(to),
                v.frame.to_local(from),
                v.lobe,
                wl,
            );
        }
        PolarizedSubpaths { chains, beams }
    }

    /// The Stokes radiance of strategy (s, t) whose scalar contribution is `c`, with the
    /// vertex `sampled` for it (s = 1: the light's; t = 1: the camera's).
    pub(crate) fn value(
        &self,
        b: &Bdpt<N>,
        paths: &Subpaths<N>,
        (s, t): (usize, usize),
        sampled: Option<&Vertex<N>>,
        c: SampledSpectrum<N>,
    ) -> StokesSpectrum<N> {
        let (light, camera) = (&paths.light, &paths.camera);
        let (scene, wl) = (b.scene(), b.wl);
        if s == 0 {
            // The camera subpath reached a light: an emitting surface, or the lights at
            // infinity together (each weighted by its share of the radiance).
            let pt = &camera[t - 1];
            let d = direction(pt, &camera[t - 2]);
            let chain = &self.chains[t - 1];
            if !pt.infinite {
                let beam = Beam::emitted(scene, pt.light as usize, d, wl);
                return chain.receive(&beam, d, c);
            }
            let total = scene.escaped_radiance(-d, wl);
            let mut out = StokesSpectrum::zero();
            for &i in &scene.infinite_lights {
                let le = scene.lights[i as usize].le(-d, wl);
                let share = SampledSpectrum(std::array::from_fn(|k| {
                    if total.0[k] > 0.0 {
                        c.0[k] * le.0[k] / total.0[k]
                    } else {
                        0.0
                    }
                }));
                out += chain.receive(&Beam::emitted(scene, i as usize, d, wl), d, share);
            }
            return out;
        }
        if t == 1 {
            // A light subpath's vertex seen by the camera.
            let qs = &light[s - 1];
            let d = direction(qs, sampled.expect("t = 1 has a camera vertex"));
            let chain = b.chain_past(&Chain::at_camera(b.ctx, -d), qs, d, qs.wo);
            return chain.receive(&self.beams[s - 1], -qs.wo, c);
        }
        let pt = &camera[t - 1];
        if s == 1 {
            // A light sampled from the camera subpath's vertex.
            let lv = sampled.expect("s = 1 has a light vertex");
            let wi = direction(pt, lv);
            let chain = b.chain_past(&self.chains[t - 1], pt, pt.wo, wi);
            let beam = Beam::emitted(scene, lv.light as usize, -wi, wl);
            return chain.receive(&beam, -wi, c);
        }
        // Two surface vertices joined.
        let qs = &light[s - 1];
        let w = direction(pt, qs);
        let chain = b.chain_past(&self.chains[t - 1], pt, pt.wo, w);
        let chain = b.chain_past(&chain, qs, -w, qs.wo);
        chain.receive(&self.beams[s - 1], -qs.wo, c)
    }
}
