//! One render session: what `heron render` and the Python module's `Scene.render` share
//! beyond their interfaces. [`Request::session`] turns flags or keyword arguments into a
//! [`Session`] by one set of rules ([`RenderSettings::apply`] and the variance rule
//! here); [`Output`] is where a CLI render goes (an image or a film file, with the
//! checks on its path); [`Session::finish`] writes it; [`Report`] is the stop report the
//! CLI prints. The front ends keep only what is theirs: flag parsing, the progress bar,
//! Ctrl-C (a signal handler in the CLI, Python's signal checks in the module).
//!
//! [`RenderSettings::apply`]: crate::settings::RenderSettings::apply
use crate::checkpoint::{Checkpoint, Shard};
use crate::film::exr::{stage_exr, ExrChannels};
use crate::film::png::stage_png;
use crate::film::Film;
use crate::provenance::Provenance;
use crate::render::{render_state, RenderOptions, RenderStats};
use crate::scene::Scene;
use crate::settings::SettingsArgs;
use crate::spectrum::display::DisplayTransform;
use crate::{HeronError, Result};
use std::path::{Path, PathBuf};

/// What a front end asks of a render, before the scene is known: the settings' flags
/// (as [`SettingsArgs`]), whether to estimate the variance, and the worker threads.
#[derive(Clone, Debug, Default)]
pub struct Request<'a> {
    pub settings: SettingsArgs<'a>,
    /// Also estimate each pixel's variance (`--variance`, `variance=True`).
    pub variance: bool,
    /// Worker threads; 0 means one per core.
    pub threads: usize,
}

impl Request<'_> {
    /// The checks that need no scene, so that a bad flag fails before a scene that may
    /// take seconds to load (sky and medium tables).
    pub fn check(&self) -> Result<()> {
        self.settings.check().map_err(HeronError::Invalid)
    }

    /// A session rendering `scene` as asked. The messages name the CLI's flags (the
    /// Python module renames them to its arguments).
    pub fn session(&self, scene: &Scene) -> Result<Session> {
        let mut opts = RenderOptions::from_scene(scene);
        opts.settings
            .apply(&self.settings)
            .map_err(HeronError::Invalid)?;
        // A variance is estimated from the spread of a pixel's samples: one has none.
        if self.variance && opts.settings.spp < 2 {
            return Err(HeronError::Invalid(format!(
                "--variance: needs at least 2 samples per pixel to estimate a variance, got {}",
                opts.settings.spp
            )));
        }
        opts.variance = self.variance;
        opts.threads = self.threads;
        Ok(Session { opts })
    }
}

/// A render's options, decided by [`Request::session`]; the front ends add what only
/// they have (progress, checkpoints, stop flags, previews) to `opts` before running it.
pub struct Session {
    pub opts: RenderOptions,
}

/// Where `heron render` writes: an EXR image, with its PNG preview (and, polarised,
/// its DoLP and AoLP previews) beside it unless `png` is `None`, or (a path ending in
/// `.heronfilm`) the film's unnormalised sums for `heron merge` or `--resume`.
#[derive(Clone, Debug)]
pub struct Output {
    pub path: PathBuf,
    /// A film file, not an image.
    pub film: bool,
    /// The PNG preview's display transform (images only).
    pub png: Option<DisplayTransform>,
    /// Add the CIE XYZ channels to the EXR (a film file records the choice for the
    /// image heron merge writes).
    pub xyz: bool,
}

impl Output {
    /// The output at `path` (an `.exr` image or a `.heronfilm` film file), checked: its
    /// extension, its folder, and that a shard goes to a film file.
    pub fn new(path: &Path, shard: Option<Shard>) -> Result<Output> {
        let film = check_output(path, &["exr", "heronfilm"])? == "heronfilm";
        if let Some(s) = shard {
            if !film {
                return Err(HeronError::Invalid(format!(
                    "--shard {s}: expected --output to end in .heronfilm (a shard is a part for heron merge, not an image)"
                )));
            }
        }
        Ok(Output {
            path: path.to_path_buf(),
            film,
            png: None,
            xyz: false,
        })
    }
}

/// Checks that `path` ends in one of `exts` and that its folder exists; returns the
/// extension. The messages name `--output`.
pub fn check_output(path: &Path, exts: &[&str]) -> Result<String> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if !exts.contains(&ext) {
        let want: Vec<String> = exts.iter().map(|e| format!(".{e}")).collect();
        return Err(HeronError::Invalid(format!(
            "--output {}: expected a path ending in {}",
            path.display(),
            want.join(" or ")
        )));
    }
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(d) = dir {
        if !d.is_dir() {
            return Err(HeronError::Invalid(format!(
                "--output {}: folder {} does not exist",
                path.display(),
                d.display()
            )));
        }
    }
    Ok(ext.to_string())
}

/// A finished (or stopped) render: the film's state and the render's statistics.
pub struct Rendered {
    pub state: Checkpoint,
    pub stats: RenderStats,
}

impl Session {
    /// Renders, keeping the film's sums (for a film file, a checkpoint or an image).
    pub fn render_state(&self, scene: &Scene) -> Result<Rendered> {
        let (state, stats) = render_state(scene, &self.opts)?;
        Ok(Rendered { state, stats })
    }

    /// Writes `rendered` to `output`: the sums as they are to a film file (heron merge,
    /// or --resume if the render stopped early, carries on from them), or the image.
    pub fn finish(&self, rendered: &mut Rendered, output: &Output) -> Result<()> {
        rendered.state.xyz_channels = output.xyz;
        if output.film {
            return rendered.state.write(&output.path);
        }
        // From the settings key, as heron merge does: the same header either way (the
        // key records what ran, e.g. no packets for light tracing).
        let provenance = Provenance::from_key(&rendered.state.key.provenance, rendered.stats.spp)
            .expect("the settings key holds the provenance");
        let film = rendered.state.film.image();
        write_image(
            &film,
            &output.path,
            output.xyz,
            &provenance,
            output.png.as_ref(),
        )
    }
}

/// Writes the EXR and (given a display transform) the PNG of `film`, and a polarised
/// film's DoLP and AoLP previews. The EXR and the PNG are staged first and renamed into
/// place together: an error in either leaves neither behind.
pub fn write_image(
    film: &Film,
    exr_path: &Path,
    xyz: bool,
    provenance: &Provenance,
    png: Option<&DisplayTransform>,
) -> Result<()> {
    let channels = ExrChannels {
        xyz,
        spectral: film.spectral.is_some(),
    };
    let exr = stage_exr(film, exr_path, channels, provenance)?;
    let png = match png {
        None => None,
        Some(d) => Some(stage_png(film, &exr_path.with_extension("png"), d)?),
    };
    exr.commit()?;
    if let Some(p) = png {
        p.commit()?;
        if film.stokes.is_some() {
            crate::plot::stokes::write_previews(
                film,
                &exr_path.with_extension("dolp.png"),
                &exr_path.with_extension("aolp.png"),
            )?;
        }
    }
    Ok(())
}

/// Why a render stopped before its last sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stopped {
    Interrupted,
    TimeLimit,
}

/// The lines `heron render` prints when it ends.
pub struct Report<'a> {
    pub rendered: &'a Rendered,
    pub opts: &'a RenderOptions,
    pub output: &'a Output,
    /// The checkpoint the render resumed from, if any.
    pub resumed: Option<&'a Path>,
    /// Why it stopped early, if it did.
    pub stopped: Option<Stopped>,
}

impl Report<'_> {
    /// One line per fact: the summary; the non-finite samples; the resume; the stop,
    /// with the command that continues it.
    pub fn lines(&self) -> Vec<String> {
        let (stats, opts) = (&self.rendered.stats, self.opts);
        let film = &self.rendered.state.film.layout;
        let path = self.output.path.display();
        let shard = opts
            .shard
            .map_or(String::new(), |s| format!(" (shard {s})"));
        let mut lines = vec![format!(
            "{path}{shard}: {}x{} at {} spp, {} lanes, {}, {} (kernel {}) in {:.3} s: {} rays ({} camera/continued, {} shadow), {:.2} Mrays/s, {} non-finite samples",
            film.width,
            film.height,
            stats.spp,
            opts.settings.lanes,
            opts.settings.sampler.name(),
            opts.settings.integrator.name(),
            crate::settings::flag_names(stats.kernel),
            stats.wall.as_secs_f64(),
            stats.total_rays(),
            stats.counters.rays,
            stats.counters.shadow_rays,
            stats.mrays_per_s(),
            stats.nonfinite
        )];
        if stats.nonfinite > 0 {
            let at = match stats.first_nonfinite {
                Some((x, y, s)) => format!("; the first at pixel ({x}, {y}), sample {s}"),
                None => " (in splats)".to_string(),
            };
            lines.push(format!(
                "non-finite: {} samples were NaN or infinite and left out of the image{at}",
                stats.nonfinite
            ));
        }
        if let Some(from) = stats.resumed_from {
            let file = self.resumed.unwrap_or(Path::new(""));
            lines.push(format!("resumed from {from} spp ({})", file.display()));
        }
        if let Some(why) = self.stopped {
            lines.push(self.stop_line(why));
        }
        lines
    }

    fn stop_line(&self, why: Stopped) -> String {
        let opts = self.opts;
        let want = opts.shard.map_or(opts.settings.spp, |s| {
            s.samples(opts.settings.spp).len() as u32
        });
        // A film file is a checkpoint too.
        let resume = match &opts.checkpoint {
            Some((c, _)) => Some(c.as_path()),
            None if self.output.film => Some(self.output.path.as_path()),
            None => None,
        };
        format!(
            "{}: the {} holds {} of {want} spp per pixel{}",
            match why {
                Stopped::Interrupted => "interrupted",
                Stopped::TimeLimit => "time limit reached",
            },
            if self.output.film { "film" } else { "image" },
            self.rendered.stats.spp,
            match resume {
                Some(c) => format!("; continue with --resume {}", c.display()),
                None => String::new(),
            }
        )
    }
}
