//! The corpus of issue 38 ("scenes from the wild"): scene files in tests/corpus/, written
//! here in the style of the Mitsuba 3 and pbrt-v4 files users bring, each using the
//! forms that once blocked or silently changed them. Every one must import with exactly
//! the warnings listed (what heron approximates, said), load, and render finite,
//! non-black pixels. The serialized mesh is written by the test from a PLY, so the
//! corpus holds no binary mesh.
mod common;

use common::render::run;
use common::serialized::{prism, serialized, Layout};
use heron::scene::import::{import_scene, ImportOptions};
use heron::scene::load::load_imported;
use heron::settings::IntegratorKind;
use std::path::Path;

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        let target = to.join(e.file_name());
        if e.file_type().unwrap().is_dir() {
            copy_dir(&e.path(), &target);
        } else {
            std::fs::copy(e.path(), target).unwrap();
        }
    }
}

/// Imports `scene` (relative to the copied corpus), checks its warnings are exactly
/// those `expected` describes (each warning contains one of the strings, each string is
/// in some warning), and renders it small.
fn check(dir: &Path, scene: &str, expected: &[&str]) {
    let imp = import_scene(&dir.join(scene), &ImportOptions::default())
        .unwrap_or_else(|e| panic!("{scene}: {e}"));
    let messages: Vec<String> = imp.warnings.iter().map(|w| w.to_string()).collect();
    for m in &messages {
        assert!(
            expected.iter().any(|x| m.contains(x)),
            "{scene}: unexpected warning {m}"
        );
    }
    for x in expected {
        assert!(
            messages.iter().any(|m| m.contains(x)),
            "{scene}: no warning says {x:?}: {messages:?}"
        );
    }
    let mut scene_ = load_imported(&imp).unwrap_or_else(|e| panic!("{scene}: {e}"));
    scene_.camera = scene_.camera.resized(24, 24).unwrap();
    let film = run(&scene_, IntegratorKind::Path, 4, 1);
    assert!(film
        .xyz
        .iter()
        .flatten()
        .all(|v| v.is_finite() && *v >= 0.0));
    let mean_y = film.xyz.iter().map(|p| p[1] as f64).sum::<f64>() / film.xyz.len() as f64;
    assert!(mean_y > 0.01, "{scene}: a black image (mean Y {mean_y})");
}

#[test]
fn the_corpus_of_scenes_from_the_wild_imports_and_renders() {
    let tmp = tempfile::tempdir().unwrap();
    let corpus = tmp.path().join("corpus");
    copy_dir(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus"),
        &corpus,
    );
    let meshes = corpus.join("mitsuba/meshes");
    let layout = Layout {
        version: 4,
        double: false,
        extras: true,
    };
    let bytes = serialized(&[prism(tmp.path())], layout);
    std::fs::write(meshes.join("prism.serialized"), bytes).unwrap();

    check(
        &corpus,
        "mitsuba/scene.xml",
        &[
            "moment: the nested integrator is rendered",
            "eta: the table covers 400–700 nm; heron holds its end values",
            "k: the table covers 400–700 nm; heron holds its end values",
            "distribution \"beckmann\" (Mitsuba's default): heron's microfacets are GGX",
            "roughplastic: heron's rough coat lets in all it does not reflect",
        ],
    );
    check(
        &corpus,
        "pbrt/scene.pbrt",
        &[
            "2 triangle(s) of zero area dropped (2 kept)",
            "Texture \"blocks\": a 3D checkerboard is not supported; the 2D one over uv is used",
        ],
    );
}
