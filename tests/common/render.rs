//! Renders and image statistics for the tests that check rendered images against
//! analytic answers or against each other (`tests/bidir.rs`, `tests/media.rs`,
//! `tests/transport.rs`, `tests/render.rs`, `tests/sampler.rs`). Two renders are held
//! to each other by `heron compare`'s test ([`compare_xyz`]).
//!
//! Every render here asserts that no sample was non-finite: a NaN or infinite sample is
//! left out of the image (and counted), so an image could look right while the
//! integrator is broken.
use heron::compare::{compare, Comparison, Correction, Image, Options};
use heron::film::Film;
use heron::render::{render, RenderOptions, Renderer};
use heron::scene::Scene;
use heron::settings::IntegratorKind;

/// Renders `scene` with its own settings (`RenderOptions::from_scene`) as `set` changes
/// them, and asserts that every sample was finite.
pub fn render_with(scene: &Scene, set: impl FnOnce(&mut RenderOptions)) -> Film {
    let mut o = RenderOptions::from_scene(scene);
    set(&mut o);
    let (film, stats) = render(scene, &o).unwrap();
    assert_eq!(
        stats.nonfinite, 0,
        "{:?}: non-finite samples",
        o.settings.integrator
    );
    film
}

/// Renders `scene` with integrator `kind`, `spp` samples per pixel and `seed`; every
/// other setting is the scene's.
pub fn run(scene: &Scene, kind: IntegratorKind, spp: u32, seed: u64) -> Film {
    render_with(scene, |o| {
        o.settings.integrator = kind;
        o.settings.spp = spp;
        o.settings.seed = seed;
    })
}

/// [`run`] with `lanes` wavelength lanes per path.
pub fn run_lanes(scene: &Scene, kind: IntegratorKind, spp: u32, seed: u64, lanes: usize) -> Film {
    render_with(scene, |o| {
        o.settings.integrator = kind;
        o.settings.spp = spp;
        o.settings.seed = seed;
        o.settings.lanes = heron::settings::Lanes::from_count(lanes as i64).unwrap();
    })
}

/// Mean and standard error of independent values.
pub fn mean_se(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
    (m, (var / n).sqrt())
}

/// The film's Y, pixel by pixel.
pub fn y_of(film: &Film) -> Vec<f64> {
    film.xyz.iter().map(|c| c[1] as f64).collect()
}

/// Mean and standard error of the film's Y over all pixels, which are independent
/// estimates when every pixel sees the same radiance.
pub fn mean_se_y(film: &Film) -> (f64, f64) {
    mean_se(&y_of(film))
}

/// `heron compare` of two films' CIE XYZ (standard errors from the spread within
/// `region`-pixel regions: the films of these tests keep no variance) at family-wise
/// level `alpha` with Šidák's correction, over the pixels of `mask`; panics if they
/// cannot be compared. `Comparison::same` is the verdict; the report says why.
pub fn compare_xyz(
    a: &Film,
    b: &Film,
    region: u32,
    alpha: f64,
    mask: Option<Vec<bool>>,
) -> Comparison {
    compare(
        &Image::from_film_xyz(a),
        &Image::from_film_xyz(b),
        &Options {
            region,
            alpha,
            correction: Correction::Sidak,
            mask,
            tolerance: 0.0,
        },
    )
    .unwrap()
}

/// Pixels whose camera ray (pinhole) meets, at all four corners, a surface whose
/// material `keep` accepts: what light tracing, which reaches the camera only from
/// diffuse or glossy vertices, can render (`tests/bidir.rs`, `tests/agree.rs`).
pub fn first_hit_mask(
    r: &Renderer,
    scene: &Scene,
    keep: impl Fn(&heron::bsdf::Material) -> bool,
) -> Vec<bool> {
    first_hit_mask_by(r, scene, |geom| {
        geom.is_some_and(|g| keep(&scene.materials[scene.shapes[g as usize].material as usize]))
    })
}

/// Pixels whose four corners' camera rays all first meet a shape (its geometry id,
/// or None for nothing) that `keep` accepts.
pub fn first_hit_mask_by(
    r: &Renderer,
    scene: &Scene,
    keep: impl Fn(Option<u32>) -> bool,
) -> Vec<bool> {
    let cam = &scene.camera;
    let mut mask = Vec::with_capacity((cam.width * cam.height) as usize);
    for y in 0..cam.height {
        for x in 0..cam.width {
            mask.push(
                [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                    .iter()
                    .all(|&(dx, dy)| {
                        let q = heron::accel::embree::RayQuery {
                            origin: cam.eye,
                            dir: cam.direction(x as f32 + dx, y as f32 + dy),
                            tnear: 0.0,
                            tfar: f32::INFINITY,
                        };
                        keep(r.accel().intersect1(&q).map(|h| h.geom_id))
                    }),
            );
        }
    }
    mask
}

/// The bits of the CIE XYZ film of a path-traced render of `scene` at `spp` on
/// `threads` threads: renders that must not depend on the thread count compare them.
#[allow(dead_code)]
pub fn path_bits(scene: &Scene, spp: u32, threads: usize) -> Vec<u32> {
    let mut o = RenderOptions::from_scene(scene);
    o.settings.integrator = IntegratorKind::Path;
    o.settings.spp = spp;
    o.threads = threads;
    let (film, _) = render(scene, &o).unwrap();
    film.xyz.iter().flatten().map(|v| v.to_bits()).collect()
}
