//! Textures: the `[textures.NAME]` tables a material names, each built into a flat
//! [`Texture`] tree (children first, the root last), with one-line errors naming the key:
//! an unknown name, a cycle among the tables, a bad encoding or transform. An image file
//! is read once however many trees use its table.
use super::errors::key;
use super::image::{read_rgb_encoded, Encoding};
use crate::scene::file::{Reflectance, TextureFile, Textured, UvMatrix};
use crate::spectrum::DenseSpectrum;
use crate::texture::{Checkerboard, ImageTexture, Node, NodeId, Texture, UvTransform};
use std::collections::{BTreeMap, HashMap};
use std::path::Path;
use std::sync::Arc;

/// Builds the trees of the scene's textures on demand.
pub(super) struct Textures<'a> {
    tables: &'a BTreeMap<String, TextureFile>,
    base_dir: &'a Path,
    images: HashMap<String, Arc<ImageTexture>>,
    trees: HashMap<String, Arc<Texture>>,
}

/// One tree being built: its nodes, the tables already in it, and the chain of tables
/// being expanded (for the cycle check).
struct Tree {
    nodes: Vec<Node>,
    /// The constant nodes given as RGB, with it (for a number read from the tree).
    rgb: Vec<(NodeId, [f32; 3])>,
    done: HashMap<String, NodeId>,
    chain: Vec<String>,
}

impl<'a> Textures<'a> {
    pub fn new(tables: &'a BTreeMap<String, TextureFile>, base_dir: &'a Path) -> Self {
        Textures {
            tables,
            base_dir,
            images: HashMap::new(),
            trees: HashMap::new(),
        }
    }

    pub fn has(&self, name: &str) -> bool {
        self.tables.contains_key(name)
    }

    /// The tree of the table `name`, named at key path `at`.
    pub fn tree(
        &mut self,
        at: &str,
        name: &str,
        inputs: &mut Vec<String>,
    ) -> Result<Arc<Texture>, String> {
        if let Some(t) = self.trees.get(name) {
            return Ok(t.clone());
        }
        let mut tree = Tree {
            nodes: Vec::new(),
            rgb: Vec::new(),
            done: HashMap::new(),
            chain: Vec::new(),
        };
        self.table(&mut tree, at, name, inputs)?;
        let t = Texture::new(tree.nodes).map_err(|e| format!("{at}: {e}"))?;
        let t = Arc::new(t.with_constant_rgb(&tree.rgb));
        self.trees.insert(name.to_string(), t.clone());
        Ok(t)
    }

    /// The tree of one image `file` at key path `at` (a lambertian's `texture` naming a
    /// file rather than a table).
    pub fn image_file(
        &mut self,
        at: &str,
        file: &str,
        inputs: &mut Vec<String>,
    ) -> Result<Arc<Texture>, String> {
        let image = self.image(at, file, Encoding::Srgb, 1.0, false)?;
        // Listed once per material naming it, as before textures had tables, so that
        // the provenance of those scenes keeps its bytes.
        inputs.push(file.to_string());
        Ok(Arc::new(Texture::image(image)))
    }

    /// Adds the nodes of table `name` (named at `at`) and returns its root.
    fn table(
        &mut self,
        tree: &mut Tree,
        at: &str,
        name: &str,
        inputs: &mut Vec<String>,
    ) -> Result<NodeId, String> {
        if let Some(&id) = tree.done.get(name) {
            return Ok(id);
        }
        let Some(t) = self.tables.get(name) else {
            let known: Vec<&str> = self.tables.keys().map(String::as_str).collect();
            return Err(format!(
                "{at}: no texture is named {name:?} (expected one of the [textures] tables: {})",
                if known.is_empty() {
                    "there are none".to_string()
                } else {
                    known.join(", ")
                }
            ));
        };
        if let Some(k) = tree.chain.iter().position(|c| c == name) {
            let mut cycle = tree.chain[k..].to_vec();
            cycle.push(name.to_string());
            return Err(format!(
                "{at}: the textures {} name each other in a cycle",
                cycle.join(" → ")
            ));
        }
        tree.chain.push(name.to_string());
        let here = key("textures", name);
        let node = match t {
            TextureFile::Image(i) => {
                let enc = match &i.encoding {
                    Some(e) => Encoding::parse(e).map_err(|m| format!("{here}.encoding: {m}"))?,
                    None => Encoding::Srgb,
                };
                let scale = i.scale.map_or(1.0, |s| s.get());
                let image = self.image(
                    &format!("{here}.file"),
                    &i.file,
                    enc,
                    scale,
                    i.invert.unwrap_or(false),
                )?;
                if !inputs.contains(&i.file) {
                    inputs.push(i.file.clone());
                }
                let to_uv = i
                    .to_uv
                    .map(|m| uv_transform(&format!("{here}.to_uv"), &m))
                    .transpose()?;
                Node::Image { image, to_uv }
            }
            TextureFile::Checkerboard(c) => {
                let color0 = self.input(
                    tree,
                    &format!("{here}.color0"),
                    c.color0.as_ref(),
                    0.4,
                    inputs,
                )?;
                let color1 = self.input(
                    tree,
                    &format!("{here}.color1"),
                    c.color1.as_ref(),
                    0.2,
                    inputs,
                )?;
                let to_uv = match &c.to_uv {
                    Some(m) => uv_transform(&format!("{here}.to_uv"), m)?,
                    None => UvTransform::IDENTITY,
                };
                Node::Checkerboard(Checkerboard {
                    to_uv,
                    color0,
                    color1,
                })
            }
            TextureFile::Scale(s) => {
                let a = self.input(tree, &format!("{here}.tex"), Some(&s.tex), 1.0, inputs)?;
                let b = match &s.scale {
                    Textured::Value(x) => {
                        push(tree, Node::Constant(DenseSpectrum::constant(x.get())))
                    }
                    Textured::Texture(n) => {
                        self.table(tree, &format!("{here}.scale"), n, inputs)?
                    }
                };
                Node::Scale { a, b }
            }
            TextureFile::Mix(m) => {
                let a = self.input(tree, &format!("{here}.tex1"), Some(&m.tex1), 0.0, inputs)?;
                let b = self.input(tree, &format!("{here}.tex2"), Some(&m.tex2), 1.0, inputs)?;
                let amount = match &m.amount {
                    None => push(tree, Node::Constant(DenseSpectrum::constant(0.5))),
                    Some(Textured::Value(x)) => {
                        push(tree, Node::Constant(DenseSpectrum::constant(x.get())))
                    }
                    Some(Textured::Texture(n)) => {
                        self.table(tree, &format!("{here}.amount"), n, inputs)?
                    }
                };
                Node::Mix { a, b, amount }
            }
        };
        tree.chain.pop();
        let id = push(tree, node);
        tree.done.insert(name.to_string(), id);
        Ok(id)
    }

    /// A colour-or-texture key (`default` grey when absent).
    fn input(
        &mut self,
        tree: &mut Tree,
        at: &str,
        v: Option<&Textured<Reflectance>>,
        default: f32,
        inputs: &mut Vec<String>,
    ) -> Result<NodeId, String> {
        match v {
            None => Ok(push(tree, Node::Constant(DenseSpectrum::constant(default)))),
            Some(Textured::Value(r)) => {
                let id = push(tree, Node::Constant(r.spectrum()));
                if let Some(c) = r.0.rgb() {
                    tree.rgb.push((id, c));
                }
                Ok(id)
            }
            Some(Textured::Texture(n)) => self.table(tree, at, n, inputs),
        }
    }

    /// The image `file` (relative to the scene) decoded by `enc`, each texel times
    /// `scale` and inverted if asked; read once per distinct request.
    fn image(
        &mut self,
        at: &str,
        file: &str,
        enc: Encoding,
        scale: f32,
        invert: bool,
    ) -> Result<Arc<ImageTexture>, String> {
        let id = format!("{file}\u{0}{enc:?}\u{0}{scale}\u{0}{invert}");
        if let Some(i) = self.images.get(&id) {
            return Ok(i.clone());
        }
        let mut img =
            read_rgb_encoded(&self.base_dir.join(file), enc).map_err(|e| format!("{at}: {e}"))?;
        if scale != 1.0 || invert {
            for p in &mut img.pixels {
                *p = p.map(|v| if invert { 1.0 - scale * v } else { scale * v });
            }
        }
        let t = Arc::new(ImageTexture::new(img.width, img.height, &img.pixels));
        self.images.insert(id, t.clone());
        Ok(t)
    }
}

fn push(tree: &mut Tree, n: Node) -> NodeId {
    tree.nodes.push(n);
    tree.nodes.len() as NodeId - 1
}

/// `to_uv` in f32, every entry finite.
fn uv_transform(at: &str, m: &UvMatrix) -> Result<UvTransform, String> {
    let rows = m.map(|r| r.map(|x| x as f32));
    if rows.iter().flatten().any(|x| !x.is_finite()) {
        return Err(format!(
            "{at}: expected [[a, b, c], [d, e, f]] with six finite numbers, got {m:?}"
        ));
    }
    Ok(UvTransform { rows })
}
