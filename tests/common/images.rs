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
