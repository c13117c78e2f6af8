//! The film's planes: per-pixel arrays of exact integer sums, each with a name, a
//! number of values per pixel that the film's [`Layout`] decides, and one element type
//! that knows how to add and how to be written. Everything that handles the film's
//! state as a whole (tile sums into the image, shard merges, checkpoint files) loops
//! over the planes, so an output channel is one line of the [`planes!`] table below.
//!
//! The sums are fixed point (`fixed.rs`): wrapping integer addition, so a plane's value
//! does not depend on how its samples were grouped (threads, passes, shards).
use super::fixed::SquareSum;

/// What planes a film has and how wide they are.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Layout {
    pub width: u32,
    pub height: u32,
    /// Spectral bins per pixel (0: none).
    pub bins: usize,
    /// Whether splats count in the image: the integrator splats (light tracing, BDPT,
    /// photon mapping), or a sample splatted. The splat planes exist only then.
    pub splats: bool,
    /// Whether the film keeps sums of squares (`--variance`).
    pub variance: bool,
    /// Whether the film keeps S1–S3 (a polarised render).
    pub stokes: bool,
}

impl Layout {
    pub fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// The same planes over a `width` × `height` tile, without the splat planes (a
    /// tile's samples add to their own pixels only; splats go to the film in lists).
    pub fn tile(&self, width: u32, height: u32) -> Layout {
        Layout {
            width,
            height,
            splats: false,
            ..*self
        }
    }
}

/// An element of a plane: added with wrapping arithmetic (associative and commutative
/// exactly), written little-endian.
pub trait Cell: Copy + Default + PartialEq + std::fmt::Debug {
    const BYTES: usize;
    fn add(&mut self, o: &Self);
    fn put(&self, out: &mut Vec<u8>);
    /// From exactly `BYTES` bytes.
    fn get(b: &[u8]) -> Self;
}

impl Cell for i128 {
    const BYTES: usize = 16;
    #[inline(always)]
    fn add(&mut self, o: &Self) {
        *self = self.wrapping_add(*o);
    }
    fn put(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
    fn get(b: &[u8]) -> Self {
        i128::from_le_bytes(b.try_into().expect("16 bytes"))
    }
}

impl Cell for u32 {
    const BYTES: usize = 4;
    #[inline(always)]
    fn add(&mut self, o: &Self) {
        *self = self.wrapping_add(*o);
    }
    fn put(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
    fn get(b: &[u8]) -> Self {
        u32::from_le_bytes(b.try_into().expect("4 bytes"))
    }
}

impl Cell for SquareSum {
    const BYTES: usize = 24;
    #[inline(always)]
    fn add(&mut self, o: &Self) {
        SquareSum::add(self, *o);
    }
    fn put(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
    fn get(b: &[u8]) -> Self {
        SquareSum::from_le_bytes(b.try_into().expect("24 bytes"))
    }
}

/// What [`Planes::visit`] calls for each plane.
pub trait Visit {
    fn plane<T: Cell>(&mut self, name: &'static str, data: &[T]);
}

/// What [`Planes::visit_mut`] calls for each plane.
pub trait VisitMut {
    fn plane<T: Cell>(&mut self, name: &'static str, data: &mut Vec<T>);
}

/// What [`Planes::visit_pairs`] calls for each plane of two films.
pub trait VisitPair {
    fn pair<T: Cell>(&mut self, name: &'static str, mine: &mut Vec<T>, theirs: &[T]);
}

/// The plane table: `field: element type, "name", |layout| values per pixel;` (0: the
/// layout has no such plane). Its order is the order of the planes in a film file.
macro_rules! planes {
    ($($(#[$doc:meta])* $field:ident: $ty:ty, $name:literal, |$l:ident| $per:expr;)*) => {
        /// The film's planes, each pixel-major (row-major from the top-left, a pixel's
        /// values together); a plane the layout does not have is empty.
        #[derive(Clone, Debug, Default, PartialEq)]
        pub struct Planes {
            $($(#[$doc])* pub $field: Vec<$ty>,)*
        }

        impl Planes {
            /// Zeroed planes of `layout`.
            #[allow(unused_variables)]
            pub fn new(layout: &Layout) -> Planes {
                let pixels = layout.pixels();
                Planes {
                    $($field: {
                        let $l = layout;
                        vec![<$ty>::default(); pixels * ($per)]
                    },)*
                }
            }

            /// The names of `layout`'s planes, in file order.
            #[allow(unused_variables)]
            pub fn names(layout: &Layout) -> Vec<&'static str> {
                let mut v = Vec::new();
                $({
                    let $l = layout;
                    if ($per) > 0 {
                        v.push($name);
                    }
                })*
                v
            }

            pub fn visit<V: Visit>(&self, v: &mut V) {
                $(v.plane($name, &self.$field);)*
            }

            pub fn visit_mut<V: VisitMut>(&mut self, v: &mut V) {
                $(v.plane($name, &mut self.$field);)*
            }

            pub fn visit_pairs<V: VisitPair>(&mut self, o: &Planes, v: &mut V) {
                $(v.pair($name, &mut self.$field, &o.$field);)*
            }
        }
    };
}

planes! {
    /// Σ XYZ of the finite samples (3 per pixel).
    xyz: i128, "xyz", |l| 3;
    /// The count of finite samples (1 per pixel).
    good: u32, "good", |l| 1;
    /// Σ of the spectral bins (bins per pixel).
    bins: i128, "bins", |l| l.bins;
    /// Σ c² of the finite samples' linear sRGB components (3 per pixel, `--variance`).
    sq: SquareSum, "squares", |l| if l.variance { 3 } else { 0 };
    /// Polarised renders: Σ S1, S2, S3 as XYZ (9 per pixel).
    stokes: i128, "stokes", |l| if l.stokes { 9 } else { 0 };
    /// Polarised renders with bins: S1's bins, then S2's, then S3's (3 × bins per pixel).
    stokes_bins: i128, "stokesBins", |l| if l.stokes { 3 * l.bins } else { 0 };
    /// Σ of the splatted XYZ (3 per pixel).
    splat: i128, "splat", |l| if l.splats { 3 } else { 0 };
    /// Σ of the splatted bins.
    splat_bins: i128, "splatBins", |l| if l.splats { l.bins } else { 0 };
    /// Σ sⱼ² of the samples' splats into the pixel, sⱼ the sum of sample j's splats
    /// there (3 per pixel, `--variance`).
    splat_sq: SquareSum, "splatSquares", |l| if l.splats && l.variance { 3 } else { 0 };
    /// Polarised splats: S1, S2, S3 as XYZ (9 per pixel).
    splat_stokes: i128, "splatStokes", |l| if l.splats && l.stokes { 9 } else { 0 };
    /// Polarised splats with bins (3 × bins per pixel).
    splat_stokes_bins: i128, "splatStokesBins", |l| if l.splats && l.stokes { 3 * l.bins } else { 0 };
}

/// Adds `theirs` to `mine` element by element (planes of the same size).
struct AddAll;

impl VisitPair for AddAll {
    fn pair<T: Cell>(&mut self, _: &'static str, mine: &mut Vec<T>, theirs: &[T]) {
        debug_assert_eq!(mine.len(), theirs.len());
        for (a, b) in mine.iter_mut().zip(theirs) {
            a.add(b);
        }
    }
}

/// Adds a tile's planes into the image's planes at the tile's place.
struct AddRect {
    /// The image's width, the tile's origin and size.
    width: usize,
    x0: usize,
    y0: usize,
    w: usize,
    h: usize,
}

impl VisitPair for AddRect {
    fn pair<T: Cell>(&mut self, _: &'static str, image: &mut Vec<T>, tile: &[T]) {
        if tile.is_empty() {
            return;
        }
        let per = tile.len() / (self.w * self.h);
        let row = self.w * per;
        for y in 0..self.h {
            let dst = ((self.y0 + y) * self.width + self.x0) * per;
            for (a, b) in image[dst..dst + row]
                .iter_mut()
                .zip(&tile[y * row..(y + 1) * row])
            {
                a.add(b);
            }
        }
    }
}

impl Planes {
    /// Adds another film's planes (of the same layout) to these.
    pub fn add(&mut self, o: &Planes) {
        self.visit_pairs(o, &mut AddAll);
    }

    /// Adds the planes of the tile at (`x0`, `y0`) of size `w` × `h` (a layout without
    /// splat planes: `Layout::tile`) into these planes of an image `width` wide.
    pub fn add_tile(&mut self, width: u32, (x0, y0, w, h): (u32, u32, u32, u32), tile: &Planes) {
        self.visit_pairs(
            tile,
            &mut AddRect {
                width: width as usize,
                x0: x0 as usize,
                y0: y0 as usize,
                w: w as usize,
                h: h as usize,
            },
        );
    }

    /// The planes of `layout`, a layout with more planes than these have (the splat
    /// planes of a film that met its first splat): these planes' values, zeros in the
    /// new ones.
    pub fn widen(&mut self, layout: &Layout) {
        struct Fill;
        impl VisitPair for Fill {
            fn pair<T: Cell>(&mut self, _: &'static str, mine: &mut Vec<T>, new: &[T]) {
                if mine.is_empty() {
                    *mine = new.to_vec();
                }
            }
        }
        self.visit_pairs(&Planes::new(layout), &mut Fill);
    }

    /// Writes every plane's values, little-endian, in table order.
    pub fn write(&self, out: &mut Vec<u8>) {
        struct Put<'a>(&'a mut Vec<u8>);
        impl Visit for Put<'_> {
            fn plane<T: Cell>(&mut self, _: &'static str, data: &[T]) {
                for v in data {
                    v.put(self.0);
                }
            }
        }
        self.visit(&mut Put(out));
    }

    /// Reads `layout`'s planes as [`Planes::write`] wrote them from the front of `b`;
    /// returns them and the bytes after them.
    pub fn read<'a>(
        layout: &Layout,
        b: &'a [u8],
    ) -> std::result::Result<(Planes, &'a [u8]), &'static str> {
        // The size first, so that a short file (or a corrupt header) allocates nothing.
        let need = Planes::per_pixel_bytes(layout).saturating_mul(layout.pixels());
        if b.len() < need {
            return Err("the file is truncated");
        }
        struct Get<'a>(&'a [u8]);
        impl VisitMut for Get<'_> {
            fn plane<T: Cell>(&mut self, _: &'static str, data: &mut Vec<T>) {
                for (v, c) in data.iter_mut().zip(self.0.chunks_exact(T::BYTES)) {
                    *v = T::get(c);
                }
                self.0 = &self.0[data.len() * T::BYTES..];
            }
        }
        let mut planes = Planes::new(layout);
        let mut get = Get(b);
        planes.visit_mut(&mut get);
        Ok((planes, get.0))
    }

    /// The bytes one pixel takes in `layout`'s planes.
    fn per_pixel_bytes(layout: &Layout) -> usize {
        struct Size(usize);
        impl Visit for Size {
            fn plane<T: Cell>(&mut self, _: &'static str, data: &[T]) {
                self.0 += data.len() * T::BYTES;
            }
        }
        let one = Planes::new(&Layout {
            width: 1,
            height: 1,
            ..*layout
        });
        let mut s = Size(0);
        one.visit(&mut s);
        s.0
    }
}
