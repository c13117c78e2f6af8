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
//! A float-valued *material parameter* (a GGX roughness, a Phong ρs) reads a tree as a
//! number with [`Texture::eval_scalar`]: the same tree with every leaf taken as its
//! luminance Y (an image texel's Rec. 709 luminance of its linear RGB, a constant's of
//! its RGB when it was given as one — a grey's own value — and otherwise its
//! spectrum's CIE 1931 Y under the film's convention), so that the value does not depend on
//! the path's wavelengths (a roughness that changed with the hero wavelength would blur
//! the lobe by colour noise). It is Mitsuba 3's `eval_1` (the luminance of a `bitmap`);
//! pbrt-v4's float textures read a grey image, where both agree (pbrt-v4 averages the
//! channels of a colour image instead).
//!
//! A material without a texture holds none and never reads uv: only a textured material
//! asks the scene to compute it (`Material::is_textured`).
mod checkerboard;
mod image;

pub use checkerboard::Checkerboard;
pub use image::{luminance, ImageTexture};

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
    /// The luminance Y of each constant node (0 for the other kinds), for
    /// [`Texture::eval_scalar`].
    grey: Vec<f32>,
}

/// The luminance of each constant node.
fn greys(nodes: &[Node]) -> Vec<f32> {
    nodes
        .iter()
        .map(|n| match n {
            // A flat spectrum's own value, exactly (its Y could miss it by a rounding).
            Node::Constant(s) if s.values().iter().all(|&x| x == s.values()[0]) => s.values()[0],
            Node::Constant(s) => crate::spectrum::cie::spectrum_to_xyz(s)[1],
            _ => 0.0,
        })
        .collect()
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
        let grey = greys(&nodes);
        Ok(Texture { nodes, grey })
    }

    /// One image at uv itself.
    pub fn image(image: Arc<ImageTexture>) -> Texture {
        Texture {
            nodes: vec![Node::Image { image, to_uv: None }],
            grey: vec![0.0],
        }
    }

    /// The tree with the luminance of constant nodes given as RGB set from that RGB
    /// ([`luminance`]) rather than from their uplifted spectra: a grey number is then
    /// read back exactly. Each pair is (node, linear sRGB); other nodes are left.
    pub fn with_constant_rgb(mut self, rgb: &[(NodeId, [f32; 3])]) -> Texture {
        for &(id, c) in rgb {
            if let Some(Node::Constant(_)) = self.nodes.get(id as usize) {
                self.grey[id as usize] = luminance(c);
            }
        }
        self
    }

    fn root(&self) -> NodeId {
        self.nodes.len() as NodeId - 1
    }

    /// The texture's value at `uv` as a number: the tree with every leaf read as its
    /// luminance (module doc).
    #[inline]
    pub fn eval_scalar(&self, uv: Vec2) -> f32 {
        self.scalar_node(self.root(), uv)
    }

    fn scalar_node(&self, id: NodeId, uv: Vec2) -> f32 {
        match &self.nodes[id as usize] {
            Node::Constant(_) => self.grey[id as usize],
            Node::Image { image, to_uv } => match to_uv {
                None => image.eval_scalar(uv),
                Some(m) => image.eval_scalar(m.apply(uv)),
            },
            Node::Checkerboard(c) => self.scalar_node(c.pick(uv), uv),
            Node::Scale { a, b } => self.scalar_node(*a, uv) * self.scalar_node(*b, uv),
            Node::Mix { a, b, amount } => {
                let t = self.scalar_node(*amount, uv);
                (1.0 - t) * self.scalar_node(*a, uv) + t * self.scalar_node(*b, uv)
            }
        }
    }

    /// Bounds [lo, hi] of [`Texture::eval_scalar`] over the whole surface (exact for
    /// constants and images, conservative for products and mixes).
    pub fn scalar_range(&self) -> (f32, f32) {
        self.range_node(self.root())
    }

    fn range_node(&self, id: NodeId) -> (f32, f32) {
        match &self.nodes[id as usize] {
            Node::Constant(_) => (self.grey[id as usize], self.grey[id as usize]),
            Node::Image { image, .. } => image.grey_range(),
            Node::Checkerboard(c) => {
                let (a, b) = (self.range_node(c.color0), self.range_node(c.color1));
                (a.0.min(b.0), a.1.max(b.1))
            }
            Node::Scale { a, b } => {
                let (a, b) = (self.range_node(*a), self.range_node(*b));
                let p = [a.0 * b.0, a.0 * b.1, a.1 * b.0, a.1 * b.1];
                (
                    p.iter().copied().fold(f32::INFINITY, f32::min),
                    p.iter().copied().fold(f32::NEG_INFINITY, f32::max),
                )
            }
            // A mix stays between its two sides when its amount is in [0, 1].
            Node::Mix { a, b, .. } => {
                let (a, b) = (self.range_node(*a), self.range_node(*b));
                (a.0.min(b.0), a.1.max(b.1))
            }
        }
    }

    /// Every value [`Texture::eval_scalar`] can take, when they are few (at most `max`)
    /// and known at load: a tree of constants, checkerboards and products; None with an
    /// image or a mix.
    pub fn scalar_values(&self, max: usize) -> Option<Vec<f32>> {
        let mut v = self.values_node(self.root(), max)?;
        v.sort_by(f32::total_cmp);
        v.dedup();
        Some(v)
    }

    fn values_node(&self, id: NodeId, max: usize) -> Option<Vec<f32>> {
        let v = match &self.nodes[id as usize] {
            Node::Constant(_) => vec![self.grey[id as usize]],
            Node::Image { .. } | Node::Mix { .. } => return None,
            Node::Checkerboard(c) => {
                let mut v = self.values_node(c.color0, max)?;
                v.extend(self.values_node(c.color1, max)?);
                v
            }
            Node::Scale { a, b } => {
                let (a, b) = (self.values_node(*a, max)?, self.values_node(*b, max)?);
                a.iter()
                    .flat_map(|x| b.iter().map(move |y| x * y))
                    .collect()
            }
        };
        (v.len() <= max).then_some(v)
    }

    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// The texture's value at `uv`, per lane.
    #[inline]
    pub fn eval<const N: usize>(&self, uv: Vec2, wl: &SampledWavelengths<N>) -> SampledSpectrum<N> {
        self.eval_node(self.root(), uv, wl)
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
