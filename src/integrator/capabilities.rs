//! What each integrator supports, declared beside it ([`super::Integrator::CAPABILITIES`]),
//! and the rules a render draws from the declarations: which scenes and settings it
//! refuses (each with its one-line message), which packets `--packets auto` runs, and
//! which kernel flags it is specialised on. `render` asks these rules rather than
//! naming integrators, so a new integrator states its support in one place.
use super::capabilities;
use crate::scene::{Features, Scene};
use crate::settings::{
    flag_names, IntegratorKind, KernelChoice, KernelFlags, Packets, RenderSettings, ALL, STRIPPED,
};

/// Whether an integrator supports a feature, and if not, why (the refusal's message).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Support {
    Yes,
    No(&'static str),
}

/// What an integrator supports and how it runs.
#[derive(Clone, Copy, Debug)]
pub struct Capabilities {
    /// The lens camera (`camera.type = "lens"`).
    pub lens: Support,
    /// The orthographic camera (`camera.type = "orthographic"`).
    pub orthographic: Support,
    /// Participating media (a shape's medium).
    pub media: bool,
    /// Polarised transport (`polarization = true`).
    pub polarization: Support,
    /// The per-pixel variance (`--variance`).
    pub variance: Support,
    /// Embree packets of any kind (`--packets`); without, every ray goes alone.
    pub packets: bool,
    /// What `--packets auto` runs (BENCHMARKS.md, "Packets of paths").
    pub auto_packets: Packets,
    /// Whether it starts from the pixel sample's camera ray (so camera packets help).
    pub camera_rays: bool,
    /// Whether the packet engine can advance its paths step by step
    /// ([`super::StepIntegrator`]); without, `--packets paths` runs camera packets (or
    /// none, without camera rays).
    pub steps: bool,
    /// Whether it adds to other pixels than the one it samples (splat planes and
    /// buffers; the pass size).
    pub splats: bool,
    /// The kernel flags it is specialised on for a scene's features; `None`: one general
    /// kernel (every flag on).
    pub kernel: Option<fn(&Features) -> KernelFlags>,
}

/// Why light tracing and BDPT cannot render through the lens camera.
pub(crate) const LENS_NEEDS_WE: &str = "the lens camera (camera.type = \"lens\") has no importance function We and no connection to the film yet, which light tracing and BDPT need to reach the camera from the lights; use integrator = \"path\" or \"whitted\"";

/// Why light tracing and BDPT cannot render through the orthographic camera.
pub(crate) const ORTHOGRAPHIC_NEEDS_WE: &str = "the orthographic camera (camera.type = \"orthographic\") sees along one direction only (its importance is a delta), so no light path can connect to it; use integrator = \"path\", \"sppm\" or \"whitted\"";

/// The kernel flags integrator `kind` needs for a scene with `features`: the flags it
/// is specialised on, or every flag for an integrator with one general kernel.
pub fn kernel_flags(kind: IntegratorKind, features: &Features) -> KernelFlags {
    capabilities(kind).kernel.map_or(ALL, |f| f(features))
}

/// The flags of `k` this build was made without (usually none, hence a function:
/// clippy rejects a mask that is a constant zero).
#[inline]
fn stripped_of(k: KernelFlags) -> KernelFlags {
    k & STRIPPED
}

/// The kernel a render with `kind` of a scene with `features` runs: the specialised one
/// for `Auto`, every flag for `General`. Errors if the integrator does not render the
/// scene's media, or the scene needs a flag this build was made without.
pub fn choose_kernel(
    kind: IntegratorKind,
    features: &Features,
    choice: KernelChoice,
) -> Result<KernelFlags, String> {
    let caps = capabilities(kind);
    if features.media && !caps.media {
        return Err(format!(
            "the scene has participating media (a shape's medium), which only the path integrator renders, not {}; use --integrator path",
            kind.name()
        ));
    }
    let need = kernel_flags(kind, features);
    let missing = stripped_of(need);
    if caps.kernel.is_some() && missing != 0 {
        return Err(format!(
            "this heron was built without {} (HERON_STRIP), which the scene needs",
            flag_names(missing)
        ));
    }
    Ok(match choice {
        KernelChoice::Auto => need,
        KernelChoice::General => ALL,
        KernelChoice::Forced(k) => k & ALL,
    } & !STRIPPED)
}

/// The camera and the polarisation settings a render of `scene` with `settings` asks
/// of its integrator: an error when the integrator does not support them, or an
/// analyser is set without polarised transport.
pub fn check_camera(scene: &Scene, settings: &RenderSettings) -> Result<(), String> {
    let kind = settings.integrator;
    let caps = capabilities(kind);
    if let (Some(_), Support::No(why)) = (&scene.camera.lens, caps.lens) {
        return Err(format!("integrator {}: {why}", kind.name()));
    }
    if let (crate::camera::Projection::Orthographic { .. }, Support::No(why)) =
        (scene.camera.projection, caps.orthographic)
    {
        return Err(format!("integrator {}: {why}", kind.name()));
    }
    if !settings.polarization {
        let which = if settings.polarizer.is_some() {
            Some("--polarizer")
        } else if scene.camera.polarizer.is_some() {
            Some("camera.polarizer")
        } else {
            None
        };
        if let Some(w) = which {
            return Err(format!(
                "{w}: an analyser needs polarised transport; set [render] polarization = true or pass --polarization"
            ));
        }
    }
    if let (true, Support::No(why)) = (settings.polarization, caps.polarization) {
        return Err(format!("integrator {}: {why}", kind.name()));
    }
    check_filter(settings)
}

/// Light tracing reaches the film through the camera's importance at the one point a
/// path lands on (and BDPT's t = 1 strategy likewise): the sample belongs to the
/// pixel it lands in, a box filter. A wider filter would have to splat each such
/// sample into its neighbours, weighted by f, while the camera-ray strategies weight by
/// f/p; that is not implemented, so the combination is refused rather than rendering
/// an image filtered one way by some strategies and another by the rest.
fn check_filter(settings: &RenderSettings) -> Result<(), String> {
    use crate::settings::IntegratorKind::{Bdpt, LightTrace};
    let kind = settings.integrator;
    if matches!(kind, LightTrace | Bdpt) && !settings.filter.is_default() {
        return Err(format!(
            "filter {:?} with integrator {}: light paths reach the film through the camera's importance at one point (a box filter), and splatting them through a wider filter is not implemented; use filter = \"box\" (radius 0.5) with {}, or integrator = \"path\", \"whitted\" or \"sppm\" with this filter",
            settings.filter.name(),
            kind.name(),
            kind.name()
        ));
    }
    Ok(())
}

/// An error when `--variance` is asked of an integrator without it.
pub fn check_variance(kind: IntegratorKind, variance: bool) -> Result<(), String> {
    match (variance, capabilities(kind).variance) {
        (true, Support::No(why)) => Err(format!("--variance: {why}")),
        _ => Ok(()),
    }
}

/// The packets a render with integrator `kind` runs for the setting `p`: `auto`
/// resolved to the integrator's choice, camera packets only for an integrator that
/// traces camera rays, none for one without packets; packets of paths only for an
/// integrator with steps, and not for polarised transport (`polarized`), since the
/// packet engine's throughputs are scalar: camera packets instead (or none).
pub fn packets(kind: IntegratorKind, p: Packets, polarized: bool) -> Packets {
    let caps = capabilities(kind);
    let p = match p {
        _ if !caps.packets => Packets::Off,
        Packets::Auto => caps.auto_packets,
        p => p,
    };
    match p {
        Packets::Camera if !caps.camera_rays => Packets::Off,
        Packets::Paths if polarized || !caps.steps => {
            if caps.camera_rays {
                Packets::Camera
            } else {
                Packets::Off
            }
        }
        p => p,
    }
}
