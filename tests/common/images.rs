//! Image files written for the tests that read them back (environment maps, textures).
use std::path::Path;

/// Writes a float32 RGB OpenEXR of `w × h` pixels from `f(i, j)` (column, row from the
/// top), through the `exr` crate heron reads with.
pub fn write_exr(path: &Path, w: usize, h: usize, f: impl Fn(usize, usize) -> [f32; 3] + Sync) {
    use exr::prelude::*;
    let img = Image::from_channels(
        (w, h),
        SpecificChannels::rgb(|p: Vec2<usize>| {
            let c = f(p.x(), p.y());
            (c[0], c[1], c[2])
        }),
    );
    img.write().to_file(path).unwrap();
}

/// Writes a Portable Float Map of `w × h` pixels from `f(i, j)` (column, row from the
/// top): `PF` (RGB) or, with `grey`, `Pf` (the first component), little-endian (scale
/// −1) or big-endian (scale 1), rows from the bottom as the format stores them.
pub fn write_pfm(
    path: &Path,
    w: usize,
    h: usize,
    grey: bool,
    little: bool,
    f: impl Fn(usize, usize) -> [f32; 3],
) {
    let magic = if grey { "Pf" } else { "PF" };
    let scale = if little { "-1.0" } else { "1.0" };
    let mut b = format!("{magic}\n{w} {h}\n{scale}\n").into_bytes();
    for j in (0..h).rev() {
        for i in 0..w {
            let c = f(i, j);
            for v in if grey { &c[..1] } else { &c[..] } {
                b.extend(if little {
                    v.to_le_bytes()
                } else {
                    v.to_be_bytes()
                });
            }
        }
    }
    std::fs::write(path, b).unwrap();
}
