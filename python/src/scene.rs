//! `heron.load_scene`, `heron.Scene` and `Scene.render` → `heron.RenderResult`.
use crate::{err, guard, lib_err, panic_message};
use heron_core::film::Film;
use heron_core::render::{RenderOptions, RenderStats};
use heron_core::session::Request;
use heron_core::settings::SettingsArgs;
use numpy::{IntoPyArray, PyArray1, PyArray3, PyArray4, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::panic::AssertUnwindSafe;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc};
use std::time::Duration;

/// The CLI flags `Request::session` names, and the arguments of `Scene.render`.
const RENAMES: &[(&str, &str)] = &[
    ("--spp", "spp"),
    ("--seed", "seed"),
    ("--lanes", "lanes"),
    ("--integrator", "integrator"),
    ("--sampler", "sampler"),
    ("--wavelengths", "wavelengths"),
    ("--spectral-bins", "spectral_bins"),
    ("--max-depth", "max_depth"),
    ("--offset", "offset"),
    ("--packets", "packets"),
    ("--medium-nee", "medium_nee"),
    ("--sun-guide", "sun_guide"),
    ("--sppm-photons", "sppm_photons"),
    ("--sppm-alpha", "sppm_alpha"),
    ("--sppm-radius", "sppm_radius"),
    ("--polarization", "polarization"),
    ("--polarizer", "polarizer"),
    ("--hide-emitters", "hide_emitters"),
    ("--filter", "filter"),
    ("--variance", "variance"),
];

/// How often the thread that called `render` wakes to let Python run its signal
/// handlers (Ctrl-C): short enough to feel immediate, long enough to cost nothing.
const SIGNAL_POLL: Duration = Duration::from_millis(50);

/// The file name a dict scene's error messages carry; its folder (none) makes relative
/// paths (meshes, tables) start at the current directory.
const DICT_SOURCE: &str = "<dict>";

/// A loaded, validated heron scene (immutable; render it as often as you like).
#[pyclass(module = "heron", frozen)]
pub struct Scene {
    pub(crate) inner: Arc<heron_core::scene::Scene>,
}

/// Reads and validates a scene file, as `heron render SCENE` does: heron's TOML, or a
/// Mitsuba 3 (.xml) or pbrt-v4 (.pbrt) scene converted as `heron convert` converts it.
///
/// Relative paths in the file (meshes, tables) start at the file's folder. Raises
/// HeronError with the loader's one-line message (naming the file, the key and what was
/// expected) on a bad or missing file.
#[pyfunction]
pub fn load_scene(py: Python<'_>, path: PathBuf) -> PyResult<Scene> {
    guard(|| {
        let scene = py
            .detach(|| heron_core::scene::load_scene(&path))
            .map_err(|e| lib_err(e, &[]))?;
        Ok(Scene {
            inner: Arc::new(scene),
        })
    })
}

/// A scene argument: a `Scene`, or a path to load.
pub(crate) fn scene_arg(
    py: Python<'_>,
    v: &Bound<'_, PyAny>,
) -> PyResult<Arc<heron_core::scene::Scene>> {
    if let Ok(s) = v.cast::<Scene>() {
        return Ok(s.get().inner.clone());
    }
    match v.extract::<PathBuf>() {
        Ok(p) => Ok(load_scene(py, p)?.inner),
        Err(_) => Err(err(format!(
            "scene: expected a heron.Scene or a path to a scene file, got {}",
            v.repr()?
        ))),
    }
}

#[pymethods]
impl Scene {
    /// A scene from a dict with the schema of heron's TOML scene files, e.g.
    /// `{"camera": {...}, "render": {"spp": 4}, "materials": {...}, "shapes": [...]}`.
    ///
    /// The dict becomes TOML text and goes through the same loader as a file, so the
    /// checks and error messages are the loader's; they name the file `<dict>`. Relative
    /// paths (meshes, tables) start at the current directory. Values: bool, int, float,
    /// str, list/tuple, dict with str keys (numpy scalars and arrays too).
    #[staticmethod]
    fn from_dict(py: Python<'_>, d: &Bound<'_, PyDict>) -> PyResult<Scene> {
        guard(|| {
            let toml::Value::Table(table) = crate::convert::to_toml(d.as_any(), "")? else {
                return Err(err("scene: expected a dict"));
            };
            let text = toml::to_string(&table)
                .map_err(|e| err(format!("{DICT_SOURCE}: cannot write the dict as TOML: {e}")))?;
            let scene = py
                .detach(|| {
                    heron_core::scene::load::load_scene_from_str(&text, Path::new(DICT_SOURCE))
                })
                .map_err(|e| lib_err(e, &[]))?;
            Ok(Scene {
                inner: Arc::new(scene),
            })
        })
    }

    /// Image width in pixels.
    #[getter]
    fn width(&self) -> u32 {
        self.inner.camera.width
    }

    /// Image height in pixels.
    #[getter]
    fn height(&self) -> u32 {
        self.inner.camera.height
    }

    /// The scene's `[render] spp` (the default of `render`).
    #[getter]
    fn spp(&self) -> u32 {
        self.inner.settings.spp
    }

    /// The scene's `[render] seed` (the default of `render`).
    #[getter]
    fn seed(&self) -> u64 {
        self.inner.settings.seed
    }

    /// The scene's integrator (`[render] integrator`, default whitted).
    #[getter]
    fn integrator(&self) -> &'static str {
        self.inner.settings.integrator.name()
    }

    /// The material names, in the order of the file.
    #[getter]
    fn materials(&self) -> Vec<String> {
        self.inner.material_names.clone()
    }

    fn __repr__(&self) -> String {
        format!(
            "<heron.Scene {} ({}x{}, {} shapes, {} lights)>",
            self.inner.source.display(),
            self.inner.camera.width,
            self.inner.camera.height,
            self.inner.shapes.len(),
            self.inner.lights.len()
        )
    }

    /// Renders the scene; returns a RenderResult with numpy arrays and statistics.
    ///
    /// The arguments and defaults are `heron render`'s: spp and seed default to the
    /// scene's `[render]` values; lanes 1, 4 or 8; integrator whitted, path, lighttrace
    /// or bdpt (default: the scene's); wavelengths "visible" or "uniform"; threads 0 for
    /// one per core (the image does not depend on it); spectral_bins 0 for none, else
    /// 1–470 equal bins over 360–830 nm; sampler "sobol" or "independent" (default
    /// sobol); max_depth overrides `[render] max_depth`; offset "auto", "epsilon" or
    /// "robust" overrides `[render] offset`; packets "auto", "paths", "camera" or "off"
    /// chooses how rays go to Embree (`heron render --packets`; default auto: packets
    /// of paths under whitted, one path at a time otherwise; the choices agree up to the
    /// last bits of Embree's hits); variance=True also estimates each pixel's
    /// variance (`heron render --variance`, at least 2 spp), as
    /// `RenderResult.variance`. The numbers equal bit for bit the EXR channels `heron
    /// render` writes with the same settings (R, G, B; X, Y, Z with `--xyz`; S0.* with
    /// `--spectral-bins`; variance.R, .G, .B with `--variance`). medium_nee "forced" or
    /// "collision" and sun_guide (a fraction in [0, 1)) choose the path tracer's
    /// estimators in media (`heron render --medium-nee`, `--sun-guide`; default: the
    /// scene's `[render]` values, else forced and 0.25). integrator "sppm" is
    /// stochastic progressive photon mapping, spp its iterations; sppm_photons (per
    /// iteration, 0: one per pixel), sppm_alpha (in (0, 1)) and sppm_radius (scene
    /// units, 0: automatic) are `heron render --sppm-photons`, `--sppm-alpha`,
    /// `--sppm-radius`. hide_emitters=True makes emitters seen directly by the camera
    /// black (`heron render --hide-emitters`; None keeps the scene's `[render]
    /// hide_emitters`). filter is the pixel reconstruction filter in `heron render
    /// --filter`'s syntax, e.g. "gaussian" or "mitchell:b=0,c=0.5" (None keeps the
    /// scene's `[render] filter`, default a box of radius 0.5).
    ///
    /// The GIL is released while rendering. Ctrl-C (KeyboardInterrupt, or an exception
    /// from any other signal handler) abandons the render within a row of a tile and is
    /// raised here; the partial image is discarded.
    #[pyo3(signature = (spp=None, seed=None, lanes=8, integrator=None, wavelengths="visible", threads=0, spectral_bins=None, sampler=None, max_depth=None, offset=None, variance=false, packets=None, medium_nee=None, sun_guide=None, sppm_photons=None, sppm_alpha=None, sppm_radius=None, polarization=None, polarizer=None, hide_emitters=None, filter=None))]
    fn render(
        &self,
        py: Python<'_>,
        spp: Option<i64>,
        seed: Option<u64>,
        lanes: i64,
        integrator: Option<&str>,
        wavelengths: &str,
        threads: i64,
        spectral_bins: Option<i64>,
        sampler: Option<&str>,
        max_depth: Option<i64>,
        offset: Option<&str>,
        variance: bool,
        packets: Option<&str>,
        medium_nee: Option<&str>,
        sun_guide: Option<f64>,
        sppm_photons: Option<i64>,
        sppm_alpha: Option<f64>,
        sppm_radius: Option<f64>,
        polarization: Option<bool>,
        polarizer: Option<f64>,
        hide_emitters: Option<bool>,
        filter: Option<&str>,
    ) -> PyResult<RenderResult> {
        guard(|| {
            // The settings' rules are the CLI's (RenderSettings::apply); the messages name
            // the arguments instead of the flags.
            if threads < 0 || threads > u16::MAX as i64 {
                return Err(err(format!(
                    "threads: expected 0 (one per core) or a number of threads, got {threads}"
                )));
            }
            let request = Request {
                settings: SettingsArgs {
                    spp,
                    seed,
                    lanes: Some(lanes),
                    integrator,
                    sampler,
                    wavelengths: Some(wavelengths),
                    spectral_bins,
                    max_depth,
                    offset,
                    kernel: None,
                    packets,
                    no_packets: false,
                    medium_nee,
                    sun_guide,
                    sppm_photons,
                    sppm_alpha,
                    sppm_radius,
                    polarization,
                    polarizer,
                    hide_emitters,
                    filter,
                },
                variance,
                threads: threads as usize,
            };
            let opts = request
                .session(&self.inner)
                .map_err(|e| lib_err(e, RENAMES))?
                .opts;
            let scene = self.inner.clone();
            let (film, stats, opts) = render_interruptible(py, scene, opts)?;
            RenderResult::new(py, &film, &stats, &opts)
        })
    }
}

/// Renders on a worker thread while this thread, without the GIL, waits for it and
/// every [`SIGNAL_POLL`] takes the GIL to run Python's signal handlers. When a handler
/// raises (KeyboardInterrupt), the render's cancel flag is set, the renderer abandons it
/// within a row of a tile and returns, and the exception is raised.
fn render_interruptible(
    py: Python<'_>,
    scene: Arc<heron_core::scene::Scene>,
    mut opts: RenderOptions,
) -> PyResult<(Film, RenderStats, RenderOptions)> {
    // Ctrl-C abandons the render within a row of a tile (the partial image is discarded
    // anyway).
    let stop = Arc::new(AtomicBool::new(false));
    opts.cancel = Some(stop.clone());
    let (tx, rx) = mpsc::channel();
    let worker = std::thread::Builder::new()
        .name("heron-render".into())
        .spawn(move || {
            let r = std::panic::catch_unwind(AssertUnwindSafe(|| {
                heron_core::render::render(&scene, &opts)
            }));
            // The receiver is gone only if the calling thread itself panicked.
            let _ = tx.send((r, opts));
        })
        .map_err(|e| err(format!("cannot start the render thread: {e}")))?;
    let mut rx = rx;
    loop {
        // The receiver goes into the GIL-free closure and comes back (it is Send, not
        // Sync).
        let (received, back) = py.detach(move || (rx.recv_timeout(SIGNAL_POLL), rx));
        rx = back;
        match received {
            Ok((result, opts)) => {
                let _ = py.detach(|| worker.join());
                return match result {
                    Ok(Ok((film, stats))) => Ok((film, stats, opts)),
                    Ok(Err(e)) => Err(lib_err(e, &[])),
                    Err(p) => Err(err(format!(
                        "internal error in heron (please report it): {}",
                        panic_message(p.as_ref())
                    ))),
                };
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {
                if let Err(e) = py.check_signals() {
                    stop.store(true, Ordering::SeqCst);
                    let _ = py.detach(|| worker.join());
                    return Err(e);
                }
            }
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                let _ = py.detach(|| worker.join());
                return Err(err(
                    "internal error in heron: the render thread ended without a result",
                ));
            }
        }
    }
}

/// The image and statistics of `Scene.render`.
#[pyclass(module = "heron", frozen)]
pub struct RenderResult {
    rgb: Py<PyArray3<f32>>,
    xyz: Py<PyArray3<f32>>,
    spectral: Option<Py<PyArray3<f32>>>,
    wavelengths: Option<Py<PyArray1<f32>>>,
    variance: Option<Py<PyArray3<f32>>>,
    stokes: Option<Py<PyArray4<f32>>>,
    stokes_spectral: Option<Py<PyArray4<f32>>>,
    /// Samples per pixel in the image.
    #[pyo3(get)]
    spp: u32,
    /// All rays traced: camera and continued rays plus shadow rays.
    #[pyo3(get)]
    rays: u64,
    /// Closest-hit rays: camera rays and the rays that continue paths
    /// (the CLI's "camera/continued").
    #[pyo3(get)]
    camera_rays: u64,
    /// Occlusion (shadow) rays.
    #[pyo3(get)]
    shadow_rays: u64,
    /// Samples whose radiance was NaN or infinite, left out of the image.
    #[pyo3(get)]
    nonfinite_samples: u64,
    /// Wall-clock seconds of the render.
    #[pyo3(get)]
    wall_seconds: f64,
    /// Million rays per second (rays / wall_seconds).
    #[pyo3(get)]
    mrays_per_s: f64,
    /// The kernel that ran, as the CLI names it (e.g. "shadows+specular").
    #[pyo3(get)]
    kernel: String,
    /// whitted, path, lighttrace or bdpt.
    #[pyo3(get)]
    integrator: String,
    /// Wavelengths per path: 1, 4 or 8.
    #[pyo3(get)]
    lanes: usize,
    /// sobol or independent.
    #[pyo3(get)]
    sampler: String,
    /// The seed of the render.
    #[pyo3(get)]
    seed: u64,
    /// Image width in pixels.
    #[pyo3(get)]
    width: u32,
    /// Image height in pixels.
    #[pyo3(get)]
    height: u32,
}

impl RenderResult {
    /// The linear sRGB array (for `heron.compare`).
    pub(crate) fn rgb_array(&self, py: Python<'_>) -> Py<PyArray3<f32>> {
        self.rgb.clone_ref(py)
    }

    /// The variance array, if rendered with it (for `heron.compare`).
    pub(crate) fn variance_array(&self, py: Python<'_>) -> Option<Py<PyArray3<f32>>> {
        self.variance.as_ref().map(|a| a.clone_ref(py))
    }

    fn new(
        py: Python<'_>,
        film: &Film,
        stats: &RenderStats,
        opts: &RenderOptions,
    ) -> PyResult<Self> {
        let (w, h) = (film.width as usize, film.height as usize);
        let image = |v: Vec<f32>, c: usize| -> PyResult<Py<PyArray3<f32>>> {
            Ok(v.into_pyarray(py).reshape([h, w, c])?.unbind())
        };
        let flat = |px: Vec<[f32; 3]>| px.into_iter().flatten().collect::<Vec<f32>>();
        let rgb = image(flat(film.linear_srgb()), 3)?;
        let xyz = image(flat(film.xyz.clone()), 3)?;
        let (spectral, wavelengths) = match &film.spectral {
            Some((bins, data)) => (
                Some(image(data.clone(), bins.count)?),
                Some(
                    (0..bins.count)
                        .map(|k| bins.centre(k))
                        .collect::<Vec<f32>>()
                        .into_pyarray(py)
                        .unbind(),
                ),
            ),
            None => (None, None),
        };
        let variance = match &film.variance {
            Some(v) => Some(image(flat(v.clone()), 3)?),
            None => None,
        };
        let stokes = match &film.stokes {
            Some(st) => {
                let rgb = film.linear_srgb();
                let data: Vec<f32> = rgb
                    .iter()
                    .zip(st)
                    .flat_map(|(s0, s)| {
                        let rest = s.map(heron_core::spectrum::color::xyz_to_linear_srgb);
                        std::iter::once(*s0).chain(rest).flatten()
                    })
                    .collect();
                Some(data.into_pyarray(py).reshape([h, w, 4, 3])?.unbind())
            }
            None => None,
        };
        // H × W × 4 × bins: S0's bins (`spectral`), then S1's, S2's, S3's.
        let stokes_spectral = match (&film.spectral, &film.stokes_spectral) {
            (Some((bins, s0)), Some(rest)) => {
                let nb = bins.count;
                let data: Vec<f32> = (0..w * h)
                    .flat_map(|i| {
                        s0[i * nb..(i + 1) * nb]
                            .iter()
                            .chain(&rest[3 * i * nb..3 * (i + 1) * nb])
                            .copied()
                    })
                    .collect();
                Some(data.into_pyarray(py).reshape([h, w, 4, nb])?.unbind())
            }
            _ => None,
        };
        Ok(RenderResult {
            rgb,
            xyz,
            spectral,
            wavelengths,
            variance,
            stokes,
            stokes_spectral,
            spp: stats.spp,
            rays: stats.total_rays(),
            camera_rays: stats.counters.rays,
            shadow_rays: stats.counters.shadow_rays,
            nonfinite_samples: stats.nonfinite,
            wall_seconds: stats.wall.as_secs_f64(),
            mrays_per_s: stats.mrays_per_s(),
            kernel: heron_core::settings::flag_names(stats.kernel),
            integrator: opts.settings.integrator.name().to_string(),
            lanes: opts.settings.lanes.count(),
            sampler: opts.settings.sampler.name().to_string(),
            seed: opts.settings.seed,
            width: film.width,
            height: film.height,
        })
    }
}

#[pymethods]
impl RenderResult {
    /// Linear sRGB, H×W×3 float32: the EXR's R, G, B (Film::linear_srgb, no chromatic
    /// adaptation), row 0 at the top.
    #[getter]
    fn rgb(&self, py: Python<'_>) -> Py<PyArray3<f32>> {
        self.rgb.clone_ref(py)
    }

    /// CIE 1931 XYZ, H×W×3 float32 (the EXR's X, Y, Z; Y = 1 for the constant spectral
    /// radiance 1).
    #[getter]
    fn xyz(&self, py: Python<'_>) -> Py<PyArray3<f32>> {
        self.xyz.clone_ref(py)
    }

    /// Mean spectral radiance per bin, H×W×bins float32 (the EXR's S0.* channels), or
    /// None when rendered with spectral_bins=0.
    #[getter]
    fn spectral(&self, py: Python<'_>) -> Option<Py<PyArray3<f32>>> {
        self.spectral.as_ref().map(|a| a.clone_ref(py))
    }

    /// The variance of each pixel's R, G, B (of the mean over its samples), H×W×3
    /// float32 (the EXR's variance.R, .G, .B), or None when rendered without
    /// variance=True.
    #[getter]
    fn variance(&self, py: Python<'_>) -> Option<Py<PyArray3<f32>>> {
        self.variance.as_ref().map(|a| a.clone_ref(py))
    }

    /// The Stokes vector of each pixel in linear sRGB, H×W×4×3 float32: [..., k, c] is
    /// S_k of channel c (R, G, B), in the camera's frame (S1 > 0 horizontal polarisation
    /// in the picture, S2 > 0 at +45° counter-clockwise, S3 > 0 right-circular; the EXR's
    /// R, G, B and S1.R … S3.B), or None when rendered without polarization.
    #[getter]
    fn stokes(&self, py: Python<'_>) -> Option<Py<PyArray4<f32>>> {
        self.stokes.as_ref().map(|a| a.clone_ref(py))
    }

    /// The Stokes vector of each pixel per spectral bin, H×W×4×bins float32: [..., k, b]
    /// is the mean spectral radiance of S_k in bin b (the EXR's S0.* … S3.* channels;
    /// [..., 0, :] is `spectral`), or None without polarization or spectral bins.
    #[getter]
    fn stokes_spectral(&self, py: Python<'_>) -> Option<Py<PyArray4<f32>>> {
        self.stokes_spectral.as_ref().map(|a| a.clone_ref(py))
    }

    /// The spectral bins' centres in nm (float32), or None without spectral bins.
    #[getter]
    fn wavelengths(&self, py: Python<'_>) -> Option<Py<PyArray1<f32>>> {
        self.wavelengths.as_ref().map(|a| a.clone_ref(py))
    }

    fn __repr__(&self) -> String {
        format!(
            "<heron.RenderResult {}x{} at {} spp, {} lanes, {}, {} (kernel {}) in {:.3} s: {} rays ({} camera/continued, {} shadow), {} non-finite samples>",
            self.width,
            self.height,
            self.spp,
            self.lanes,
            self.sampler,
            self.integrator,
            self.kernel,
            self.wall_seconds,
            self.rays,
            self.camera_rays,
            self.shadow_rays,
            self.nonfinite_samples
        )
    }
}
