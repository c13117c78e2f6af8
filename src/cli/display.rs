//! `heron display`: linear colours encoded for display as the PNG preview does.
use super::{display, DisplayFlags};
use anyhow::{bail, Result};
use std::path::PathBuf;

#[derive(clap::Args)]
pub(crate) struct DisplayCmdArgs {
    /// An EXR (R, G, B in linear sRGB) or a CSV with a header naming columns X, Y, Z (CIE
    /// 1931, D65 white at Y = 1, heron's film convention; other columns are ignored).
    input: PathBuf,
    /// The PNG to write for an EXR (required); the CSV to write for a CSV (default:
    /// standard output). Written atomically.
    #[arg(short, long)]
    output: Option<PathBuf>,
    #[command(flatten)]
    display: DisplayFlags,
}

pub(crate) fn run(a: DisplayCmdArgs) -> Result<()> {
    let t = a.display.transform()?;
    let ext = a
        .input
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("exr") => {
            let Some(out) = &a.output else {
                bail!("--output: expected the PNG to write (heron display IN.exr -o OUT.png)");
            };
            heron::session::check_output(out, &["png"])?;
            let (w, h, rgb) = heron::film::exr::read_linear_srgb(&a.input)?;
            heron::film::png::stage_png_rgb(w, h, &rgb, out, &t)?.commit()?;
        }
        Some("csv") => {
            let text = std::fs::read_to_string(&a.input)
                .map_err(|e| anyhow::anyhow!("{}: {e}", a.input.display()))?;
            if let Some(out) = &a.output {
                heron::session::check_output(out, &["csv"])?;
            }
            let csv = heron::spectrum::display::map_xyz_csv(&text, &display(&a.input), &t)
                .map_err(anyhow::Error::msg)?;
            match &a.output {
                Some(out) => heron::files::write_atomically(out, |tmp| {
                    std::fs::write(tmp, &csv).map_err(|e| e.to_string())
                })?,
                None => print!("{csv}"),
            }
        }
        _ => bail!(
            "{}: expected an .exr (to a PNG) or a .csv with columns X, Y, Z",
            a.input.display()
        ),
    }
    Ok(())
}
