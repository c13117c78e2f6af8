//! Provenance: what made an image, written into every EXR heron renders as header
//! attributes, and printed back by `heron info`.
//!
//! The attributes are strings named `heron.<key>`: the version of heron and the git commit
//! it was built from ([`COMMIT`]), the scene file's
//! name and the SHA-256 of its text, the SHA-256 of every other file it read (meshes,
//! index and n, k tables), and the render settings that change the pixels: integrator,
//! sampler, samples per pixel reached, seed, lanes, wavelength sampler, maximum depth,
//! ray offsets, camera packets and spectral bins. Nothing that differs between identical runs (no
//! date, no wall time, no thread count, no absolute path) is recorded, so identical
//! renders stay byte-identical.
use crate::scene::Scene;
use crate::settings::{RenderSettings, WavelengthSampler};

/// heron's version, from Cargo.toml.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// The git commit this binary was built from (40 hex digits), or `unknown` when it was
/// built outside a git checkout (a source tarball without `.git`); set by build.rs.
pub const GIT_COMMIT: &str = env!("HERON_GIT_COMMIT");

/// `clean` when the sources the binary is built from (src, spectra, build.rs,
/// Cargo.toml, Cargo.lock) were those of [`GIT_COMMIT`], `dirty` when they differed,
/// `unknown` without git; set by build.rs.
pub const GIT_STATE: &str = env!("HERON_GIT_STATE");

/// The provenance's `commit`: [`GIT_COMMIT`], with `-dirty` appended when the sources
/// differed from it (as `git describe --dirty` marks a tree).
pub const COMMIT: &str = if const_eq(GIT_STATE, "dirty") {
    concat!(env!("HERON_GIT_COMMIT"), "-dirty")
} else {
    env!("HERON_GIT_COMMIT")
};

/// What `heron --version` prints after the program name, e.g. `0.1.0 (commit 3f2a…, clean)`.
pub const LONG_VERSION: &str = concat!(
    env!("CARGO_PKG_VERSION"),
    " (commit ",
    env!("HERON_GIT_COMMIT"),
    ", ",
    env!("HERON_GIT_STATE"),
    ")"
);

/// String equality in a const context (`==` on `str` is not const).
const fn const_eq(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

/// The attribute-name prefix.
pub const PREFIX: &str = "heron.";

/// The provenance of a render, as (key, value) pairs in a fixed order; the EXR
/// attribute of each is `heron.<key>`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Provenance(pub Vec<(&'static str, String)>);

/// The provenance keys, in the order [`Provenance::of_render`] writes them.
pub const KEYS: [&str; 15] = [
    "version",
    "commit",
    "scene",
    "sceneSha256",
    "inputs",
    "integrator",
    "sampler",
    "spp",
    "seed",
    "lanes",
    "wavelengths",
    "maxDepth",
    "offset",
    "packets",
    "spectralBins",
];

/// Keys written after [`KEYS`] only when the scene has a participating medium (the
/// path tracer's estimators there), so that other scenes' EXRs keep their bytes.
pub const MEDIA_KEYS: [&str; 2] = ["mediumNee", "sunGuide"];

/// Keys written last only for photon mapping (`integrator = "sppm"`): its photons per
/// iteration (as resolved for the image), α and initial radius (0: automatic).
pub const SPPM_KEYS: [&str; 3] = ["sppmPhotons", "sppmAlpha", "sppmRadius"];

/// Keys written last only for a polarised render (`[render] polarization`), so that
/// unpolarised EXRs keep their bytes.
pub const POLARIZATION_KEYS: [&str; 2] = ["polarization", "polarizer"];

/// The key written last only when emitters seen directly are hidden (`[render]
/// hide_emitters`), so that other EXRs keep their bytes; a checkpoint or shard of the
/// other setting then differs from this render's in it, and is refused.
pub const HIDE_EMITTERS_KEYS: [&str; 1] = ["hideEmitters"];

/// The key written last only for a reconstruction filter other than the default box
/// (`[render] filter`), e.g. `gaussian radius=1.5 stddev=0.5`, so that other EXRs keep
/// their bytes; a checkpoint or shard of another filter is refused.
pub const FILTER_KEYS: [&str; 1] = ["filter"];

impl Provenance {
    /// The provenance a film's settings key holds (`FilmKey::provenance`: every entry
    /// but spp), with `spp` samples per pixel: what `heron merge` writes, the same as the
    /// one render with all the samples would.
    pub fn from_key(
        key: &std::collections::BTreeMap<String, String>,
        spp: u32,
    ) -> Option<Provenance> {
        KEYS.iter()
            .chain(MEDIA_KEYS.iter().filter(|k| key.contains_key(**k)))
            .chain(SPPM_KEYS.iter().filter(|k| key.contains_key(**k)))
            .chain(POLARIZATION_KEYS.iter().filter(|k| key.contains_key(**k)))
            .chain(HIDE_EMITTERS_KEYS.iter().filter(|k| key.contains_key(**k)))
            .chain(FILTER_KEYS.iter().filter(|k| key.contains_key(**k)))
            .map(|&k| {
                Some((
                    k,
                    if k == "spp" {
                        spp.to_string()
                    } else {
                        key.get(k)?.clone()
                    },
                ))
            })
            .collect::<Option<Vec<_>>>()
            .map(Provenance)
    }

    /// What `scene` rendered with `settings` to `spp` samples per pixel records.
    pub fn of_render(scene: &Scene, settings: &RenderSettings, spp: u32) -> Provenance {
        let name = scene
            .source
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let inputs = scene
            .inputs
            .iter()
            .map(|(f, h)| format!("{h}  {f}"))
            .collect::<Vec<_>>()
            .join("\n");
        let wavelengths = match settings.wavelengths {
            WavelengthSampler::Uniform => "uniform",
            WavelengthSampler::Visible => "visible",
        };
        let mut p = Provenance(vec![
            ("version", VERSION.to_string()),
            ("commit", COMMIT.to_string()),
            ("scene", name),
            ("sceneSha256", scene.source_sha256.clone()),
            ("inputs", inputs),
            ("integrator", settings.integrator.name().to_string()),
            ("sampler", settings.sampler.name().to_string()),
            ("spp", spp.to_string()),
            ("seed", settings.seed.to_string()),
            ("lanes", settings.lanes.to_string()),
            ("wavelengths", wavelengths.to_string()),
            ("maxDepth", settings.max_depth.to_string()),
            (
                "offset",
                settings.ray_offset(settings.integrator).to_string(),
            ),
            ("packets", settings.packets.provenance().to_string()),
            ("spectralBins", settings.spectral_bins.to_string()),
        ]);
        if !scene.media.is_empty() {
            p.0.push(("mediumNee", settings.medium_nee.name().to_string()));
            p.0.push(("sunGuide", settings.sun_guide.to_string()));
        }
        if settings.integrator == crate::settings::IntegratorKind::Sppm {
            let pixels = scene.camera.width * scene.camera.height;
            let sppm = &settings.sppm;
            p.0.push(("sppmPhotons", sppm.photons_for(pixels).to_string()));
            p.0.push(("sppmAlpha", sppm.alpha.to_string()));
            p.0.push(("sppmRadius", sppm.radius.to_string()));
        }
        if settings.polarization {
            p.0.push(("polarization", "stokes".to_string()));
            // The analyser in degrees, the flag's over the scene's.
            if let Some(a) = settings.polarizer.or(scene.camera.polarizer) {
                p.0.push(("polarizer", a.to_degrees().to_string()));
            }
        }
        if settings.hide_emitters {
            p.0.push(("hideEmitters", "true".to_string()));
        }
        if !settings.filter.is_default() {
            p.0.push(("filter", settings.filter.describe()));
        }
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::load::load_scene_from_str;

    /// `from_key` must rebuild exactly what `of_render` writes, in its order, or a
    /// merged EXR's header would differ from the one render's.
    #[test]
    fn the_settings_key_rebuilds_the_provenance() {
        let scene = load_scene_from_str(
            "[camera]\neye = [0.0, 0.0, 1.0]\nlook_at = [0.0, 0.0, 0.0]\nresolution = [8, 8]\n",
            std::path::Path::new("p.toml"),
        )
        .unwrap();
        let settings = &scene.settings;
        let p = Provenance::of_render(&scene, settings, 7);
        let names: Vec<&str> = p.0.iter().map(|(k, _)| *k).collect();
        assert_eq!(names, KEYS);
        // As a film's key holds it: every entry but spp.
        let key: std::collections::BTreeMap<String, String> =
            Provenance::of_render(&scene, settings, settings.spp)
                .0
                .into_iter()
                .filter(|(k, _)| *k != "spp")
                .map(|(k, v)| (k.to_string(), v))
                .collect();
        assert_eq!(Provenance::from_key(&key, 7), Some(p));
        let mut partial = key.clone();
        partial.remove("seed");
        assert_eq!(Provenance::from_key(&partial, 7), None);
    }
}
