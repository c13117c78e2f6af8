//! The `[render]` table to [`RenderSettings`]: every key optional, defaults from
//! `RenderSettings::default()`.
use crate::scene::file::RenderFile;
use crate::settings::{
    parse_sppm_alpha, parse_sppm_photons, parse_sppm_radius, parse_sun_guide, FilterParams,
    IntegratorKind, LightSamplerKind, MediumNee, OffsetMode, PixelFilter, RenderSettings,
};

/// The settings of the `[render]` table `r` (defaults without one).
pub(super) fn render_settings(r: Option<&RenderFile>) -> Result<RenderSettings, String> {
    let mut settings = RenderSettings::default();
    let Some(r) = r else {
        return Ok(settings);
    };
    if let Some(x) = r.spp {
        settings.spp = x.0;
    }
    if let Some(x) = r.max_depth {
        settings.max_depth = x.0;
    }
    if let Some(x) = r.epsilon {
        settings.epsilon = x.get();
    }
    if let Some(x) = r.seed {
        settings.seed = x;
    }
    if let Some(name) = &r.integrator {
        settings.integrator =
            IntegratorKind::parse(name).map_err(|e| format!("render.integrator: {e}"))?;
    }
    if let Some(x) = r.rr_depth {
        settings.rr_depth = x;
    }
    if let Some(name) = &r.offset {
        settings.offset = OffsetMode::parse(name).map_err(|e| format!("render.offset: {e}"))?;
    }
    if let Some(name) = &r.light_sampler {
        settings.light_sampler =
            LightSamplerKind::parse(name).map_err(|e| format!("render.light_sampler: {e}"))?;
    }
    if let Some(name) = &r.medium_nee {
        settings.medium_nee =
            MediumNee::parse(name).map_err(|e| format!("render.medium_nee: {e}"))?;
    }
    if let Some(g) = r.sun_guide {
        settings.sun_guide = parse_sun_guide(g).map_err(|e| format!("render.sun_guide: {e}"))?;
    }
    if let Some(n) = r.sppm_photons {
        settings.sppm.photons =
            parse_sppm_photons(n).map_err(|e| format!("render.sppm_photons: {e}"))?;
    }
    if let Some(v) = r.sppm_alpha {
        settings.sppm.alpha = parse_sppm_alpha(v).map_err(|e| format!("render.sppm_alpha: {e}"))?;
    }
    if let Some(v) = r.sppm_radius {
        settings.sppm.radius =
            parse_sppm_radius(v).map_err(|e| format!("render.sppm_radius: {e}"))?;
    }
    if let Some(b) = r.spectral_bins {
        if !(0..=470).contains(&b) {
            return Err(format!(
                "render.spectral_bins: expected 0 (none) or 1 to 470 bins, got {b}"
            ));
        }
        settings.spectral_bins = b as usize;
    }
    if let Some(p) = r.polarization {
        settings.polarization = p;
    }
    if let Some(h) = r.hide_emitters {
        settings.hide_emitters = h;
    }
    let params = FilterParams {
        radius: r.filter_radius,
        stddev: r.filter_stddev,
        b: r.filter_b,
        c: r.filter_c,
    };
    let given = params.radius.is_some()
        || params.stddev.is_some()
        || params.b.is_some()
        || params.c.is_some();
    if r.filter.is_some() || given {
        let name = r.filter.as_deref().unwrap_or("box");
        settings.filter = PixelFilter::from_parts(name, params, &|k| {
            if k.is_empty() {
                "render.filter".to_string()
            } else {
                format!("render.filter_{k}")
            }
        })?;
    }
    Ok(settings)
}
