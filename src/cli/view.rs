//! `heron view`: the images in the browser (heron::view), and the viewer a render in
//! progress opens with `heron render --view`.
use anyhow::{Context, Result};
use heron::view::{bind, serve, ViewImage, Viewer};
use std::path::PathBuf;
use std::sync::Arc;

#[derive(clap::Args)]
pub(crate) struct ViewArgs {
    /// EXR files to look at (the first is shown; the others are a click, or `F` for an
    /// A/B flip, away).
    #[arg(required = true, value_name = "FILE.exr")]
    files: Vec<PathBuf>,
    #[command(flatten)]
    server: ServerFlags,
}

/// Where the viewer listens and whether a browser is opened.
#[derive(clap::Args, Clone)]
pub(crate) struct ServerFlags {
    /// Port on 127.0.0.1 (0: a free one, printed).
    #[arg(long, default_value_t = 0)]
    port: u16,
    /// Print the address only; do not open a browser.
    #[arg(long)]
    no_browser: bool,
}

pub(crate) fn run(args: ViewArgs) -> Result<()> {
    for f in &args.files {
        ViewImage::check_exr(f)?;
    }
    // Ctrl-C ends the viewer with status 0, also where SIGINT came in ignored (a
    // background job of a non-interactive shell inherits it so).
    ctrlc::set_handler(|| std::process::exit(0))
        .map_err(|e| anyhow::anyhow!("cannot install the Ctrl-C handler: {e}"))?;
    // The address first, the pixels after: the browser starts and loads the page while
    // the files decode (a 4K spectral EXR takes seconds), and the page's first request
    // for an image waits for them.
    let viewer = start(Vec::new(), &args.server, true)?;
    for (i, f) in args.files.iter().enumerate() {
        viewer.replace(i, ViewImage::read_exr(f)?);
    }
    viewer.loaded();
    // Serving happens on the listener's thread; this one only waits for Ctrl-C.
    loop {
        std::thread::park();
    }
}

/// Starts the server for `images` on its own thread and prints its address (and opens
/// a browser unless told not to). With `loading`, requests for images wait until
/// [`Viewer::loaded`].
pub(crate) fn start(
    images: Vec<ViewImage>,
    flags: &ServerFlags,
    loading: bool,
) -> Result<Arc<Viewer>> {
    let listener = bind(flags.port)?;
    let port = listener
        .local_addr()
        .context("the viewer's address")?
        .port();
    let viewer = Arc::new(Viewer::new(images, port));
    if loading {
        viewer.loading();
    }
    let served = viewer.clone();
    std::thread::spawn(move || serve(listener, served));
    let url = format!("http://127.0.0.1:{port}/");
    println!("heron view: {url} (Ctrl-C to stop)");
    if !flags.no_browser {
        // xdg-open hands the address to the desktop's browser; without one (a server,
        // a container) the printed address is the way in.
        if let Err(e) = std::process::Command::new("xdg-open")
            .arg(&url)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
        {
            eprintln!("heron view: cannot open a browser ({e}); open {url}");
        }
    }
    Ok(viewer)
}
