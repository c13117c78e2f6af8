//! `heron merge`: the film files of a sharded render into its EXR and PNG.
use super::{display, DisplayFlags};
use anyhow::Result;
use std::path::PathBuf;

#[derive(clap::Args)]
pub(crate) struct MergeArgs {
    /// The film files of every shard K/N of one render, in any order.
    #[arg(required = true, num_args = 1..)]
    parts: Vec<PathBuf>,
    /// Output EXR path; the PNG preview goes next to it with the extension .png.
    #[arg(short, long)]
    output: PathBuf,
    /// Do not write the PNG preview.
    #[arg(long)]
    no_png: bool,
    #[command(flatten)]
    display: DisplayFlags,
}

pub(crate) fn run(args: MergeArgs) -> Result<()> {
    heron::session::check_output(&args.output, &["exr"])?;
    let shown = args.display.transform()?;
    let parts = args
        .parts
        .iter()
        .map(|p| {
            Ok((
                p.clone(),
                heron::checkpoint::Checkpoint::read_as(p, "film file")?,
            ))
        })
        .collect::<Result<Vec<_>>>()?;
    let total = heron::checkpoint::merge(&parts)?;
    let provenance =
        heron::provenance::Provenance::from_key(&total.key.provenance, total.film.spp_done)
            .ok_or_else(|| {
                anyhow::anyhow!(
                    "{}: not a heron film file: its settings lack the provenance",
                    display(&parts[0].0)
                )
            })?;
    let film = total.film.image();
    let png = (!args.no_png).then_some(&shown);
    heron::session::write_image(&film, &args.output, total.xyz_channels, &provenance, png)?;
    eprintln!(
        "{}: merged {} part{}: {}x{} at {} spp, {} rays ({} camera/continued, {} shadow), {} non-finite samples",
        display(&args.output),
        parts.len(),
        if parts.len() == 1 { "" } else { "s" },
        film.width,
        film.height,
        total.film.spp_done,
        total.film.rays + total.film.shadow_rays,
        total.film.rays,
        total.film.shadow_rays,
        total.film.nonfinite
    );
    Ok(())
}
