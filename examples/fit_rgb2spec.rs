//! Fits heron's RGB → spectrum coefficient table (Jakob & Hanika 2019) and writes
//! spectra/rgb2spec_srgb.bin; see src/spectrum/rgb2spec.rs and spectra/README.md.
//!
//! ```sh
//! cargo run --release --example fit_rgb2spec                       # res 64 → spectra/
//! cargo run --release --example fit_rgb2spec -- --res 32 --out /tmp/t.bin
//! cargo run --release --example fit_rgb2spec -- --sweep 16,24,32,48,64   # measure only
//! ```
//!
//! For each table it prints how the fits went (largest ΔE*ab at the nodes, iterations)
//! and the round trip through the film: linear sRGB → table → reflectance → XYZ under
//! D65 (heron's film convention) → linear sRGB, as the largest absolute error over a
//! 1/32 grid of the sRGB cube, random colours inside it and random colours on its
//! faces (where the spectra are most saturated).
use heron::math::rng::Rng;
use heron::spectrum::cie::{d65_unit, spectrum_to_xyz};
use heron::spectrum::color::xyz_to_linear_srgb;
use heron::spectrum::rgb2spec::fit::{build_table, BuiltTable};
use heron::spectrum::rgb2spec::{table_file_len, Rgb2SpecTable};
use heron::spectrum::DenseSpectrum;
use rayon::prelude::*;
use std::time::Instant;

const DEFAULT_RES: usize = 64;
const DEFAULT_OUT: &str = "spectra/rgb2spec_srgb.bin";

fn usage() -> ! {
    eprintln!(
        "usage: fit_rgb2spec [--res N] [--out PATH]\n       fit_rgb2spec --sweep N,N,...   (measure only, writes nothing)"
    );
    std::process::exit(2)
}

/// Colours the round trip is measured on.
fn test_colours() -> Vec<[f32; 3]> {
    let mut v = Vec::new();
    let n = 32;
    for r in 0..=n {
        for g in 0..=n {
            for b in 0..=n {
                v.push([r, g, b].map(|c| c as f32 / n as f32));
            }
        }
    }
    let mut rng = Rng::new(2019, 7);
    for i in 0..60_000 {
        let mut c = [rng.uniform(), rng.uniform(), rng.uniform()];
        if i % 2 == 1 {
            // On a face of the cube: one component 0 or 1.
            let axis = (rng.next_u32() % 3) as usize;
            c[axis] = (rng.next_u32() % 2) as f32;
        }
        v.push(c);
    }
    v
}

/// Round trip of the colours through one table, both for the paper's trilinear lookup
/// alone and for heron's uplift (lookup + Gauss–Newton polish).
struct RoundTrip {
    /// Largest |Δrgb| of the trilinear lookup alone, and where.
    lookup_max: f32,
    lookup_worst: [f32; 3],
    /// Share of colours whose trilinear lookup misses by more than 1e-3.
    lookup_over_1e3: f64,
    /// 99th percentile of the trilinear lookup's error.
    lookup_p99: f32,
    /// Largest |Δrgb| after the polish (what heron's uplift gives), and where.
    uplift_max: f32,
    uplift_worst: [f32; 3],
    /// Gauss–Newton iterations of the polish: mean and largest.
    polish_mean: f64,
    polish_max: u32,
    /// Reflectance range over all uplifted colours.
    reflectance: (f32, f32),
}

fn film_rgb(s: &DenseSpectrum) -> [f32; 3] {
    xyz_to_linear_srgb(spectrum_to_xyz(&s.mul(d65_unit())))
}

fn max_abs_diff(a: [f32; 3], b: [f32; 3]) -> f32 {
    (0..3).map(|i| (a[i] - b[i]).abs()).fold(0.0, f32::max)
}

/// One colour's round trip: lookup error, uplift error, polish iterations, reflectance
/// minimum and maximum.
type PerColour = (f32, f32, u32, f32, f32);

fn round_trip(table: &Rgb2SpecTable, colours: &[[f32; 3]]) -> RoundTrip {
    let per: Vec<PerColour> = colours
        .par_iter()
        .map(|&rgb| {
            let pure = max_abs_diff(film_rgb(&table.lookup(rgb).to_dense()), rgb);
            let (c, fit) = table.coefficients_and_fit(rgb);
            let s = c.to_dense();
            let e = max_abs_diff(film_rgb(&s), rgb);
            (
                pure,
                e,
                fit.map_or(0, |f| f.iterations),
                s.min_value(),
                s.max_value(),
            )
        })
        .collect();
    let arg_max = |f: &dyn Fn(&PerColour) -> f32| {
        let i = (0..per.len())
            .max_by(|&a, &b| f(&per[a]).total_cmp(&f(&per[b])))
            .unwrap();
        (f(&per[i]), colours[i])
    };
    let (lookup_max, lookup_worst) = arg_max(&|p| p.0);
    let (uplift_max, uplift_worst) = arg_max(&|p| p.1);
    let mut sorted: Vec<f32> = per.iter().map(|p| p.0).collect();
    sorted.sort_by(f32::total_cmp);
    RoundTrip {
        lookup_max,
        lookup_worst,
        lookup_over_1e3: per.iter().filter(|p| p.0 > 1e-3).count() as f64 / per.len() as f64,
        lookup_p99: sorted[sorted.len() * 99 / 100],
        uplift_max,
        uplift_worst,
        polish_mean: per.iter().map(|p| p.2 as f64).sum::<f64>() / per.len() as f64,
        polish_max: per.iter().map(|p| p.2).max().unwrap(),
        reflectance: (
            per.iter().map(|p| p.3).fold(f32::MAX, f32::min),
            per.iter().map(|p| p.4).fold(f32::MIN, f32::max),
        ),
    }
}

fn build_and_report(res: usize, colours: &[[f32; 3]]) -> (BuiltTable, f64, RoundTrip) {
    let t0 = Instant::now();
    let built = build_table(res);
    let secs = t0.elapsed().as_secs_f64();
    let (worst, at) = built.worst();
    let its: Vec<u32> = built.nodes.iter().map(|n| n.iterations).collect();
    let over = |t: f64| built.nodes.iter().filter(|n| n.delta_e > t).count();
    println!(
        "res {res}: {} nodes fitted in {secs:.1} s; worst ΔE*ab {worst:.2e} at (l, k, yi, xi) = {at:?} \
         (rgb {:?}); nodes above 1e-8: {}, above 1e-4: {}; iterations mean {:.2}, max {}",
        built.nodes.len(),
        built.table.node_rgb(at[0], at[1], at[2], at[3]),
        over(1e-8),
        over(1e-4),
        its.iter().map(|&i| i as f64).sum::<f64>() / its.len() as f64,
        its.iter().max().unwrap(),
    );
    let t0 = Instant::now();
    let rt = round_trip(&built.table, colours);
    println!(
        "res {res}: round trip of {} colours ({:.1} s): trilinear lookup max |Δrgb| {:.2e} at {:?}, \
         99th percentile {:.2e}, {:.2}% above 1e-3; after the polish max {:.2e} at {:?} \
         (iterations mean {:.2}, max {}); reflectance range [{}, {}]; file {} bytes",
        colours.len(),
        t0.elapsed().as_secs_f64(),
        rt.lookup_max,
        rt.lookup_worst,
        rt.lookup_p99,
        100.0 * rt.lookup_over_1e3,
        rt.uplift_max,
        rt.uplift_worst,
        rt.polish_mean,
        rt.polish_max,
        rt.reflectance.0,
        rt.reflectance.1,
        table_file_len(res),
    );
    (built, secs, rt)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut res = DEFAULT_RES;
    let mut out = DEFAULT_OUT.to_string();
    let mut sweep: Option<Vec<usize>> = None;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut val = || it.next().cloned().unwrap_or_else(|| usage());
        match a.as_str() {
            "--res" => res = val().parse().unwrap_or_else(|_| usage()),
            "--out" => out = val(),
            "--sweep" => {
                sweep = Some(
                    val()
                        .split(',')
                        .map(|s| s.trim().parse().unwrap_or_else(|_| usage()))
                        .collect(),
                )
            }
            _ => usage(),
        }
    }
    let colours = test_colours();
    if let Some(list) = sweep {
        let mut rows = Vec::new();
        for r in list {
            let (built, secs, rt) = build_and_report(r, &colours);
            rows.push(format!(
                "| {r} | {secs:.1} | {:.1e} | {:.2e} | {:.2e} | {:.2}% | {:.2e} | {:.2} / {} | {} |",
                built.worst().0,
                rt.lookup_max,
                rt.lookup_p99,
                100.0 * rt.lookup_over_1e3,
                rt.uplift_max,
                rt.polish_mean,
                rt.polish_max,
                table_file_len(r)
            ));
        }
        println!(
            "| res | fit time (s) | worst node ΔE*ab | lookup max | lookup p99 | lookup > 1e-3 \
             | uplift max | polish iterations mean / max | file bytes |"
        );
        println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- |");
        for row in rows {
            println!("{row}");
        }
        return;
    }
    if !(3..=256).contains(&res) {
        usage();
    }
    let (built, _, _) = build_and_report(res, &colours);
    let bytes = built.table.to_bytes();
    // Check what will be embedded parses back to the same table, then write through a
    // temporary file so a failed run never leaves a partial table behind.
    assert_eq!(Rgb2SpecTable::from_bytes(&bytes).as_ref(), Ok(&built.table));
    let tmp = format!("{out}.tmp");
    std::fs::write(&tmp, &bytes).unwrap_or_else(|e| panic!("{tmp}: {e}"));
    std::fs::rename(&tmp, &out).unwrap_or_else(|e| panic!("{out}: {e}"));
    println!("wrote {out} ({} bytes)", bytes.len());
}
