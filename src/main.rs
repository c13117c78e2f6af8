#![deny(unsafe_code)]
//! The heron command line: the dispatch to one file per subcommand in `cli/`.
use clap::Parser;
use cli::{bench::BenchCommand, Cli, Command};

mod cli;

fn main() {
    // Usage errors get one line and status 1 like every other error (status 2 for
    // heron compare, whose 1 means "different", as diff and cmp do); --help and
    // --version print as usual.
    let compare = std::env::args().nth(1).as_deref() == Some("compare");
    let fail = if compare { 2 } else { 1 };
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) if !e.use_stderr() => e.exit(),
        Err(e) => {
            let text = e.to_string();
            let first = text.lines().next().unwrap_or("invalid arguments");
            eprintln!("{}", first.trim_end());
            std::process::exit(fail);
        }
    };
    let result = match cli.command {
        Command::Render(args) => cli::render::run(args),
        Command::Convert(args) => cli::convert::run(args),
        Command::Merge(args) => cli::merge::run(args),
        Command::Trace(args) => cli::trace::run(args),
        Command::Converge(args) => cli::converge::run(args),
        Command::Bench(BenchCommand::Traversal(args)) => cli::bench::traversal(args),
        Command::Bench(BenchCommand::Record(args)) => cli::bench::record(args),
        Command::Bench(BenchCommand::Replay { log, rounds }) => cli::bench::replay(&log, rounds),
        Command::Bench(BenchCommand::Limit(args)) => cli::bench::limit(args),
        Command::Bench(BenchCommand::Mesh { n, output }) => {
            heron::bench::write_obj(&heron::bench::procedural_mesh(n), &output).map_err(Into::into)
        }
        Command::Color(args) => cli::color::run(args),
        Command::Compare(args) => cli::compare::run(args),
        Command::Display(args) => cli::display::run(args),
        Command::Info { exr } => cli::info::run(&exr),
        Command::Stress(args) => cli::stress::run(args),
        Command::Sky(c) => cli::sky::run(c),
        Command::Halo(c) => cli::halo::run(c),
        Command::Lens(args) => cli::lens::run(args),
        Command::View(args) => cli::view::run(args),
        Command::Spectra { scene } => heron::scene::load_scene(&scene)
            .map_err(Into::into)
            .map(|s| println!("{}", heron::scene::export::spectra_json(&s))),
    };
    if let Err(e) = result {
        eprintln!("error: {e:#}");
        std::process::exit(fail);
    }
}
