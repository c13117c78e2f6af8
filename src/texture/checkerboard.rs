//! A checkerboard of two sub-textures over uv (Mitsuba 3 `src/textures/checkerboard.cpp`;
//! pbrt-v4 `Checkerboard` in `textures.cpp`, point-sampled).
//!
//! heron's squares are Mitsuba 3's: at (s, t) = `to_uv`(u, v), the square is `color0`
//! where frac(s) > ½ and frac(t) > ½ agree (both or neither), `color1` otherwise; so
//! without a transform the unit square holds 2 × 2 squares, `color0` at the origin's
//! corner. (Mitsuba's `eval`, the spectral lookup; its `eval_1` for a float texture
//! swaps the two, which heron does not copy.) The edges: frac = ½ exactly counts as
//! "not above ½".
//!
//! pbrt-v4's 2D checkerboard at (s, t) = (su u + du, sv v + dv) is `tex1` where
//! ⌊s⌋ + ⌊t⌋ is even and `tex2` otherwise (its weight 0.5 − bf(s)·bf(t)/2 with no
//! filter width; heron has no ray differentials to filter by). That is this texture with
//! `color0` = tex1, `color1` = tex2 and `to_uv` = (s/2, t/2): frac(s/2) > ½ exactly when
//! ⌊s⌋ is odd, except on the lines where s (or t) is an odd integer, a set of measure
//! zero that pbrt puts in the odd square and Mitsuba's rule in the even one. Halving is
//! exact in floating point, so everywhere else the squares are pbrt's own.
use super::{NodeId, UvTransform};
use glam::Vec2;

#[derive(Clone, Debug)]
pub struct Checkerboard {
    pub to_uv: UvTransform,
    pub color0: NodeId,
    pub color1: NodeId,
}

impl Checkerboard {
    /// The sub-texture of the square `uv` falls in.
    #[inline]
    pub fn pick(&self, uv: Vec2) -> NodeId {
        let st = self.to_uv.apply(uv);
        let upper = |x: f32| x - x.floor() > 0.5;
        if upper(st.x) == upper(st.y) {
            self.color0
        } else {
            self.color1
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn squares_are_mitsubas() {
        let c = Checkerboard {
            to_uv: UvTransform::IDENTITY,
            color0: 0,
            color1: 1,
        };
        let at = |u: f32, v: f32| c.pick(Vec2::new(u, v));
        assert_eq!(at(0.1, 0.1), 0);
        assert_eq!(at(0.6, 0.1), 1);
        assert_eq!(at(0.1, 0.6), 1);
        assert_eq!(at(0.6, 0.6), 0);
        // frac = ½ is the lower half; negative coordinates repeat.
        assert_eq!(at(0.5, 0.1), 0);
        assert_eq!(at(-0.4, 0.1), 1);
    }

    #[test]
    fn halved_coordinates_give_pbrts_squares() {
        // pbrt-v4: tex1 where ⌊s⌋ + ⌊t⌋ is even; here through to_uv = (s/2, t/2).
        let c = Checkerboard {
            to_uv: UvTransform::scale_offset([4.0 / 2.0, 3.0 / 2.0], [0.3 / 2.0, -0.2 / 2.0]),
            color0: 0,
            color1: 1,
        };
        for i in 0..97 {
            for j in 0..89 {
                let (u, v) = (i as f32 / 97.0 - 0.3, j as f32 / 89.0 + 0.1);
                let (s, t) = (4.0 * u + 0.3, 3.0 * v - 0.2);
                if s.fract() == 0.0 || t.fract() == 0.0 {
                    continue;
                }
                let even = (s.floor() as i64 + t.floor() as i64).rem_euclid(2) == 0;
                assert_eq!(c.pick(Vec2::new(u, v)), if even { 0 } else { 1 }, "{s} {t}");
            }
        }
    }
}
