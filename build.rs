//! Finds Intel Embree and tells rustc how to link it.
//!
//! heron talks to Embree through its own FFI layer (`src/accel/embree/sys.rs`). Embree 3
//! (Debian 12: `libembree-dev` 3.13.5, header `embree3/rtcore.h`, library `-lembree3`) is
//! the supported version; Embree 4 (Debian 13, Ubuntu 24.04) differs in the ray-query
//! argument lists and in `RTCHit`, and is selected with `--cfg heron_embree4`, which only
//! `sys.rs` looks at.
//!
//! Probing order: the `HERON_EMBREE_DIR` prefix (`$dir/include`, `$dir/lib`) if set, then
//! `pkg-config` (if the tool and an `embree3`/`embree4` .pc file exist), then the usual
//! system include directories. Embree 3 is preferred when both are installed, unless
//! `HERON_EMBREE_VERSION=4` is set. If no Embree is found the build fails with one line
//! naming the package to install.
//!
//! The header's `rtcore_config.h` is read to check the compile-time options that change
//! struct layouts or symbol names (`RTC_MAX_INSTANCE_LEVEL_COUNT`, `RTC_MIN_WIDTH`,
//! `EMBREE_API_NAMESPACE`); sys.rs is written for Debian's defaults.
//!
//! **Embree 4 without headers.** `HERON_EMBREE4_LIB=DIR` links the first
//! `libembree4*.so.4` in DIR by its file name (the `embreex` wheel on PyPI ships Embree
//! 4.4 as `embreex.libs/libembree4-<hash>.so.4`, whose SONAME carries the hash) and puts
//! DIR on the binaries' run path, so they run without `LD_LIBRARY_PATH`. heron's FFI
//! needs no header, so there is no `rtcore_config.h` to check here: the Embree test
//! asserts the library's version and runs the same queries against Embree 3.
//! `scripts/test.sh` builds and tests heron this way as well.
//!
//! **The commit a binary was built from.** `HERON_GIT_COMMIT` (the 40-hex `git rev-parse
//! HEAD`, or `unknown` outside a git checkout, e.g. in a source tarball without `.git`) and
//! `HERON_GIT_STATE` (`clean`, `dirty` when the sources the binary is built from differ
//! from that commit, or `unknown`) are set for rustc; `heron --version`,
//! `heron.__version__` and the EXR provenance report them (src/provenance.rs). Only the
//! local `git` is asked, never the network. `HERON_BUILD_COMMIT=NAME` states the commit
//! instead (state `unknown`). See [`git_version`].
use std::env;
use std::path::{Path, PathBuf};
use std::process::Command;

const MISSING: &str = "heron needs Intel Embree: apt-get install libembree-dev";

struct Found {
    major: u32,
    /// Directory containing `embreeN/rtcore.h`.
    include: PathBuf,
    /// Extra library directories (from HERON_EMBREE_DIR or pkg-config).
    lib_dirs: Vec<PathBuf>,
}

fn main() {
    println!("cargo::rustc-check-cfg=cfg(heron_embree4)");
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rerun-if-env-changed=HERON_EMBREE_DIR");
    println!("cargo::rerun-if-env-changed=HERON_EMBREE_VERSION");
    println!("cargo::rerun-if-env-changed=PKG_CONFIG_PATH");
    println!("cargo::rerun-if-env-changed=HERON_EMBREE4_LIB");
    strip_features();
    git_version();

    if let Some(dir) = env::var_os("HERON_EMBREE4_LIB").map(PathBuf::from) {
        link_embree4_library(&dir);
        return;
    }

    let preferred: &[u32] = match env::var("HERON_EMBREE_VERSION").as_deref() {
        Ok("4") => &[4, 3],
        _ => &[3, 4],
    };
    let found = preferred.iter().find_map(|&major| probe(major));
    let Some(found) = found else {
        fail(MISSING);
    };

    let config_h = found
        .include
        .join(format!("embree{}", found.major))
        .join("rtcore_config.h");
    // Track only files that exist: a missing path would make cargo rerun this script (and
    // rebuild heron) on every build.
    println!("cargo::rerun-if-changed={}", config_h.display());
    check_config(&config_h, found.major);

    for dir in &found.lib_dirs {
        println!("cargo::rustc-link-search=native={}", dir.display());
    }
    println!("cargo::rustc-link-lib=dylib=embree{}", found.major);
    if found.major == 4 {
        println!("cargo::rustc-cfg=heron_embree4");
    }
    let mut args: Vec<String> = Vec::new();
    if found.major == 4 {
        args.push("-DHERON_EMBREE4".into());
    }
    for dir in &found.lib_dirs {
        args.push(format!("-L{}", dir.display()));
        args.push(format!("-Wl,-rpath,{}", dir.display()));
    }
    args.push(format!("-lembree{}", found.major));
    gcc_args(&args);
}

/// Links a header-less Embree 4 shared library found in `dir` (see the module comment).
fn link_embree4_library(dir: &Path) {
    let entries = std::fs::read_dir(dir).unwrap_or_else(|e| {
        fail(&format!(
            "heron: HERON_EMBREE4_LIB={}: cannot read the directory: {e}",
            dir.display()
        ))
    });
    let mut names: Vec<String> = entries
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.starts_with("libembree4") && n.ends_with(".so.4"))
        .collect();
    names.sort();
    let Some(name) = names.first() else {
        fail(&format!(
            "heron: HERON_EMBREE4_LIB={}: expected a libembree4*.so.4 there (e.g. the \
             embreex wheel's embreex.libs folder)",
            dir.display()
        ));
    };
    let dir = dir
        .canonicalize()
        .unwrap_or_else(|e| fail(&format!("heron: HERON_EMBREE4_LIB={}: {e}", dir.display())));
    println!("cargo::rerun-if-changed={}", dir.join(name).display());
    println!("cargo::rustc-link-search=native={}", dir.display());
    println!("cargo::rustc-link-lib=dylib:+verbatim={name}");
    println!("cargo::rustc-link-arg=-Wl,-rpath,{}", dir.display());
    println!("cargo::rustc-cfg=heron_embree4");
    gcc_args(&[
        "-DHERON_EMBREE4".into(),
        format!("-L{}", dir.display()),
        format!("-l:{name}"),
        format!("-Wl,-rpath,{}", dir.display()),
    ]);
}

/// The gcc arguments that link the same Embree heron links, for the raw-Embree program
/// `heron bench traversal --raw` builds (src/bench/raw.rs), tab-separated in
/// `HERON_EMBREE_GCC_ARGS`.
fn gcc_args(args: &[String]) {
    println!("cargo::rustc-env=HERON_EMBREE_GCC_ARGS={}", args.join("\t"));
}

/// Prints one line and stops the build.
fn fail(message: &str) -> ! {
    eprintln!("{message}");
    std::process::exit(1);
}

fn probe(major: u32) -> Option<Found> {
    let header = |dir: &Path| dir.join(format!("embree{major}")).join("rtcore.h");

    if let Some(prefix) = env::var_os("HERON_EMBREE_DIR").map(PathBuf::from) {
        let include = prefix.join("include");
        if header(&include).is_file() {
            let lib_dirs = ["lib", "lib64"]
                .iter()
                .map(|l| prefix.join(l))
                .filter(|d| d.is_dir())
                .collect();
            return Some(Found {
                major,
                include,
                lib_dirs,
            });
        }
    }

    if let Some((includes, lib_dirs)) = pkg_config(&format!("embree{major}")) {
        if let Some(include) = includes.into_iter().find(|d| header(d).is_file()) {
            return Some(Found {
                major,
                include,
                lib_dirs,
            });
        }
    }

    [
        "/usr/include",
        "/usr/local/include",
        "/opt/homebrew/include",
    ]
    .iter()
    .map(PathBuf::from)
    .find(|d| header(d).is_file())
    .map(|include| Found {
        major,
        include,
        lib_dirs: Vec::new(),
    })
}

/// `pkg-config --cflags-only-I --libs-only-L NAME`, parsed; None if the tool or the .pc
/// file is missing. The directories the .pc names (and the default include directory,
/// which pkg-config leaves out) are returned.
fn pkg_config(name: &str) -> Option<(Vec<PathBuf>, Vec<PathBuf>)> {
    let out = Command::new("pkg-config")
        .args(["--cflags-only-I", "--libs-only-L", name])
        .output()
        .ok()?;
    if !out.status.success() {
        return None;
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let mut includes = Vec::new();
    let mut libs = Vec::new();
    for word in text.split_whitespace() {
        if let Some(dir) = word.strip_prefix("-I") {
            includes.push(PathBuf::from(dir));
        } else if let Some(dir) = word.strip_prefix("-L") {
            libs.push(PathBuf::from(dir));
        }
    }
    includes.push(PathBuf::from("/usr/include"));
    Some((includes, libs))
}

/// Checks the compile-time options in `rtcore_config.h` that sys.rs hard-codes.
fn check_config(config_h: &Path, major: u32) {
    let text = std::fs::read_to_string(config_h)
        .unwrap_or_else(|e| fail(&format!("heron: cannot read {}: {e}", config_h.display())));
    let define = |name: &str| -> Option<String> {
        text.lines().find_map(|line| {
            let mut words = line.split_whitespace();
            (words.next() == Some("#define") && words.next() == Some(name))
                .then(|| words.next().unwrap_or("").to_string())
        })
    };
    let expect = |name: &str, want: &str| {
        let got = define(name);
        if got.as_deref() != Some(want) {
            fail(&format!(
                "heron: {} has {name} = {}, but heron's Embree bindings assume {want} \
                 (Debian's libembree-dev default)",
                config_h.display(),
                got.as_deref().unwrap_or("<undefined>")
            ));
        }
    };
    expect("RTC_VERSION_MAJOR", &major.to_string());
    expect("RTC_MAX_INSTANCE_LEVEL_COUNT", "1");
    // RTC_MIN_WIDTH is defined as EMBREE_MIN_WIDTH, which is 0 or 1.
    expect("EMBREE_MIN_WIDTH", "0");
    if define("EMBREE_API_NAMESPACE").is_some() {
        fail(&format!(
            "heron: {} defines EMBREE_API_NAMESPACE (C++-mangled symbols); heron needs \
             Embree built with its C API",
            config_h.display()
        ));
    }
}

/// `HERON_STRIP=shadows,specular,emitters,escape` (any subset): a build whose kernels
/// lack those features' code, to measure the specialised kernels against
/// (`src/scene/features.rs`, `scripts/bench_kernels.py`). Not for rendering.
fn strip_features() {
    const NAMES: [&str; 4] = ["shadows", "specular", "emitters", "escape"];
    for n in NAMES {
        println!("cargo::rustc-check-cfg=cfg(heron_strip_{n})");
    }
    println!("cargo::rerun-if-env-changed=HERON_STRIP");
    let Ok(list) = env::var("HERON_STRIP") else {
        return;
    };
    for n in list.split(',').map(str::trim).filter(|n| !n.is_empty()) {
        if !NAMES.contains(&n) {
            panic!("HERON_STRIP: expected a comma-separated subset of {NAMES:?}, got {n:?}");
        }
        println!("cargo::rustc-cfg=heron_strip_{n}");
    }
}

/// The files the binary is built from: a change to any of them makes the build "dirty".
/// (README, tests, scripts and python/ do not change the binary; watching them would
/// rebuild heron after every edit of the documentation.)
const SOURCES: [&str; 5] = ["src", "spectra", "build.rs", "Cargo.toml", "Cargo.lock"];

/// Sets `HERON_GIT_COMMIT` and `HERON_GIT_STATE` (see the module comment) from the
/// repository this crate is the top of. A crate unpacked inside some other repository
/// (`git rev-parse --show-toplevel` elsewhere) reports `unknown`, not that repository's
/// commit. `git status` runs with `--no-optional-locks` so that it never rewrites the index,
/// which cargo watches: a rewritten index would rerun this script on every build.
fn git_version() {
    println!("cargo::rerun-if-env-changed=HERON_BUILD_COMMIT");
    if let Ok(stated) = env::var("HERON_BUILD_COMMIT") {
        // A commit named by whoever builds: a source archive whose commit is known, or
        // scripts/same_images.sh, which compares two commits' EXR bytes and so builds both
        // with one value. Its state is unknown: nothing here checks the sources.
        if stated.is_empty() || !stated.bytes().all(|b| b.is_ascii_graphic()) {
            fail(&format!(
                "heron: HERON_BUILD_COMMIT={stated:?}: expected a commit name (printable \
                 ASCII, no spaces)"
            ));
        }
        println!("cargo::rustc-env=HERON_GIT_COMMIT={stated}");
        println!("cargo::rustc-env=HERON_GIT_STATE=unknown");
        return;
    }
    let root = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    for s in SOURCES {
        println!("cargo::rerun-if-changed={}", root.join(s).display());
    }
    let git = |args: &[&str]| -> Option<String> {
        let out = Command::new("git")
            .arg("--no-optional-locks")
            .args(args)
            .current_dir(&root)
            .env_remove("GIT_DIR")
            .env_remove("GIT_WORK_TREE")
            .output()
            .ok()?;
        out.status
            .success()
            .then(|| String::from_utf8_lossy(&out.stdout).trim_end().to_string())
    };
    let same_dir = |a: &Path, b: &Path| match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    };
    let ours =
        git(&["rev-parse", "--show-toplevel"]).is_some_and(|top| same_dir(Path::new(&top), &root));
    let commit = ours
        .then(|| git(&["rev-parse", "--verify", "HEAD"]))
        .flatten()
        .filter(|c| c.len() == 40 && c.bytes().all(|b| b.is_ascii_hexdigit()));
    let Some(commit) = commit else {
        println!("cargo::rustc-env=HERON_GIT_COMMIT=unknown");
        println!("cargo::rustc-env=HERON_GIT_STATE=unknown");
        return;
    };
    // Rerun when HEAD moves (a commit, a checkout) or the index changes (git add): the
    // HEAD file, the branch's ref (loose or packed) and the index, in the worktree's own
    // git directory and the common one. Only existing files: a missing path would rerun
    // this script on every build.
    let mut watch = Vec::new();
    if let Some(dir) = git(&["rev-parse", "--absolute-git-dir"]) {
        let dir = PathBuf::from(dir);
        watch.push(dir.join("HEAD"));
        watch.push(dir.join("index"));
    }
    if let (Some(common), Some(head_ref)) = (
        git(&["rev-parse", "--path-format=absolute", "--git-common-dir"]),
        git(&["symbolic-ref", "-q", "HEAD"]),
    ) {
        let common = PathBuf::from(common);
        watch.push(common.join(head_ref));
        watch.push(common.join("packed-refs"));
    }
    for f in watch.iter().filter(|f| f.is_file()) {
        println!("cargo::rerun-if-changed={}", f.display());
    }
    let mut status = vec!["status", "--porcelain", "--untracked-files=no", "--"];
    status.extend(SOURCES);
    let state = match git(&status) {
        Some(s) if s.is_empty() => "clean",
        Some(_) => "dirty",
        None => "unknown",
    };
    println!("cargo::rustc-env=HERON_GIT_COMMIT={commit}");
    println!("cargo::rustc-env=HERON_GIT_STATE={state}");
}
