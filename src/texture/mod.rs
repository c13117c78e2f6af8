//! Textures: spectra that vary over a surface's uv, as a small tree of closed kinds
//! (pbrt-v4 `textures.h`, Mitsuba 3 `src/textures/`), evaluated per lane at a hit's uv.
//!
//! A [`Texture`] is its nodes stored flat, every node's children before it and the root
//! last, so that a lookup is a recursive `match` over a slice: no allocation and no
//! dynamic dispatch per lookup. The kinds:
//!
//! - a constant spectrum (a colour, or a number as a grey);
//! - an image ([`ImageTexture`]: texels uplifted once, their spectra bilinear per lane),
//!   looked up at an affine map of uv ([`UvTransform`]);
//! - a checkerboard ([`Checkerboard`]) of two sub-textures;
//! - a product of two textures (pbrt-v4's `scale`);
//! - a mix, (1 − t)·a + t·b with t a texture (pbrt-v4's `mix`).
//!
//! Float textures (a mix's amount, a scale's factor) are the same trees whose values do
//! not depend on wavelength: greys, exact through the uplift (Jakob & Hanika 2019's
//! sigmoid of a grey is flat).
//!
//! A material without a texture holds none and never reads uv: only a textured material
//! asks the scene to compute it (`Material::is_textured`).
mod checkerboard;
mod image;

pub use checkerboard::Checkerboard;
pub use image::ImageTexture;

use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use glam::Vec2;
use std::sync::Arc;

/// An affine map of texture coordinates, (u, v) → (a u + b v + c, d u + e v + f): the
/// 2D part of Mitsuba 3's `to_uv` (its last row and column dropped), and pbrt-v4's
/// `UVMapping` (su u + du, sv v + dv).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform {
    /// The rows [a, b, c] and [d, e, f].
    pub rows: [[f32; 3]; 2],
}

impl UvTransform {
    pub const IDENTITY: UvTransform = UvTransform {
        rows: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
    };

    /// pbrt-v4's `UVMapping`: (su u + du, sv v + dv).
    pub fn scale_offset(scale: [f32; 2], offset: [f32; 2]) -> UvTransform {
        UvTransform {
            rows: [[scale[0], 0.0, offset[0]], [0.0, scale[1], offset[1]]],
        }
    }

    /// `self` applied after `first`.
    pub fn after(&self, first: &UvTransform) -> UvTransform {
        let (a, b) = (self.rows, first.rows);
        let mut rows = [[0.0; 3]; 2];
        for (i, row) in rows.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                *x = a[i][0] * b[0][j] + a[i][1] * b[1][j];
            }
            row[2] += a[i][2];
        }
        UvTransform { rows }
    }

    #[inline]
    pub fn apply(&self, uv: Vec2) -> Vec2 {
        let [r0, r1] = self.rows;
        Vec2::new(
            r0[0] * uv.x + r0[1] * uv.y + r0[2],
            r1[0] * uv.x + r1[1] * uv.y + r1[2],
        )
    }
}

/// A node's index in its [`Texture`].
pub type NodeId = u32;

/// One node of a texture tree; children are indices of earlier nodes.
#[derive(Clone, Debug)]
pub enum Node {
    /// The same spectrum everywhere.
    Constant(DenseSpectrum),
    /// An image at `to_uv(uv)` (none: uv itself, with no arithmetic, so that a scene of
    /// a plain image keeps its bytes).
    Image {
        image: Arc<ImageTexture>,
        to_uv: Option<UvTransform>,
    },
    Checkerboard(Checkerboard),
    /// The product of two textures.
    Scale {
        a: NodeId,
        b: NodeId,
    },
    /// (1 − t)·a + t·b per lane, t = `amount` (pbrt-v4 `MixTexture`).
    Mix {
        a: NodeId,
        b: NodeId,
        amount: NodeId,
    },
}

/// A texture tree, its nodes in an order where every child precedes its parent; the
/// root is the last.
#[derive(Clone, Debug)]
pub struct Texture {
    nodes: Vec<Node>,
}

impl Texture {
    /// The tree of `nodes` (root last); an error when a node names a child that is not
    /// before it (which also rules out cycles).
    pub fn new(nodes: Vec<Node>) -> Result<Texture, String> {
        if nodes.is_empty() {
            return Err("a texture needs at least one node".into());
        }
        for (i, n) in nodes.iter().enumerate() {
            let ok = |c: &NodeId| (*c as usize) < i;
            let children_ok = match n {
                Node::Constant(_) | Node::Image { .. } => true,
                Node::Checkerboard(c) => ok(&c.color0) && ok(&c.color1),
                Node::Scale { a, b } => ok(a) && ok(b),
                Node::Mix { a, b, amount } => ok(a) && ok(b) && ok(amount),
            };
            if !children_ok {
                return Err(format!(
                    "texture node {i} names a child that is not before it"
                ));
            }
        }
        Ok(Texture { nodes })
    }

    /// One image at uv itself.
    pub fn image(image: Arc<ImageTexture>) -> Texture {
        Texture {
            nodes: vec![Node::Image { image, to_uv: None }],
        }
    }

    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// The texture's value at `uv`, per lane.
    #[inline]
    pub fn eval<const N: usize>(&self, uv: Vec2, wl: &SampledWavelengths<N>) -> SampledSpectrum<N> {
        self.eval_node(self.nodes.len() as NodeId - 1, uv, wl)
    }

    fn eval_node<const N: usize>(
        &self,
        id: NodeId,
        uv: Vec2,
        wl: &SampledWavelengths<N>,
    ) -> SampledSpectrum<N> {
        match &self.nodes[id as usize] {
            Node::Constant(s) => wl.eval(s),
            Node::Image { image, to_uv } => match to_uv {
                None => image.eval(uv, wl),
                Some(m) => image.eval(m.apply(uv), wl),
            },
            Node::Checkerboard(c) => self.eval_node(c.pick(uv), uv, wl),
            Node::Scale { a, b } => self.eval_node(*a, uv, wl) * self.eval_node(*b, uv, wl),
            Node::Mix { a, b, amount } => {
                let t = self.eval_node(*amount, uv, wl);
                // As pbrt-v4's MixTexture, a side whose weight is zero is not looked up.
                if t.0.iter().all(|&x| x == 0.0) {
                    return self.eval_node(*a, uv, wl);
                }
                if t.0.iter().all(|&x| x == 1.0) {
                    return self.eval_node(*b, uv, wl);
                }
                let (va, vb) = (self.eval_node(*a, uv, wl), self.eval_node(*b, uv, wl));
                let mut out = SampledSpectrum::<N>::zero();
                for k in 0..N {
                    out.0[k] = (1.0 - t.0[k]) * va.0[k] + t.0[k] * vb.0[k];
                }
                out
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grey(x: f32) -> Node {
        Node::Constant(DenseSpectrum::constant(x))
    }

    #[test]
    fn scale_and_mix_combine_their_children() {
        let wl = SampledWavelengths::<4>::sample_uniform(0.3);
        let t = Texture::new(vec![
            grey(0.5),
            grey(0.8),
            Node::Scale { a: 0, b: 1 },
            grey(0.25),
            Node::Mix {
                a: 2,
                b: 1,
                amount: 3,
            },
        ])
        .unwrap();
        let v = t.eval(Vec2::ZERO, &wl).0[0];
        assert!((v - (0.75 * 0.4 + 0.25 * 0.8)).abs() < 1e-6, "{v}");
        // A child after its parent is refused (and with it every cycle).
        assert!(Texture::new(vec![Node::Scale { a: 0, b: 0 }]).is_err());
    }

    #[test]
    fn uv_transforms_compose() {
        let a = UvTransform::scale_offset([2.0, 3.0], [0.5, 0.25]);
        let b = UvTransform {
            rows: [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0]],
        };
        let uv = Vec2::new(0.3, 0.7);
        let c = a.after(&b);
        assert!((c.apply(uv) - a.apply(b.apply(uv))).length() < 1e-6);
    }
}
