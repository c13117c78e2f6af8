//! Mitsuba 3's XML scene format as a tree of [`Node`]s with their file and line, after
//! the document-level rules of Mitsuba's loader (`src/core/xml.cpp`): `<default>`
//! parameters and `$name` substitution in attribute values, `<include filename=…>`
//! spliced in place, and every element's `id` collected so that `<ref id=…>` can be
//! resolved by the converter. The format is documented in Mitsuba 3's "File format"
//! chapter (mitsuba.readthedocs.io, "Scene XML file format").
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Includes nested deeper than this are taken for a cycle.
const MAX_INCLUDE_DEPTH: usize = 16;

/// One XML element: its tag, attributes (after `$name` substitution), the file and line
/// it was read from, and its element children (includes already spliced in).
#[derive(Clone, Debug)]
pub struct Node {
    pub tag: String,
    pub attrs: Vec<(String, String)>,
    pub file: Arc<PathBuf>,
    pub line: u32,
    pub children: Vec<Node>,
}

/// A problem at a place in a file: errors and warnings alike.
#[derive(Clone, Debug, PartialEq)]
pub struct Diagnostic {
    pub file: PathBuf,
    pub line: u32,
    pub message: String,
}

impl std::fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: line {}: {}",
            self.file.display(),
            self.line,
            self.message
        )
    }
}

impl Node {
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    /// A diagnostic at this element, its message prefixed by how the element reads
    /// (`<bsdf type="diffuse">`).
    pub fn diag(&self, message: impl std::fmt::Display) -> Diagnostic {
        Diagnostic {
            file: self.file.as_ref().clone(),
            line: self.line,
            message: format!("{}: {message}", self.describe()),
        }
    }

    /// `<tag type="…" name="…">` with the attributes that identify the element.
    pub fn describe(&self) -> String {
        let mut s = format!("<{}", self.tag);
        for key in ["type", "name", "id"] {
            if let Some(v) = self.attr(key) {
                s.push_str(&format!(" {key}=\"{}\"", v.escape_debug()));
            }
        }
        s.push('>');
        s
    }
}

/// The document of `path`: its root `<scene>` element with includes spliced in and
/// defaults substituted; `defines` override `<default>` values (as Mitsuba's `-D`).
pub fn read_document(path: &Path, defines: &BTreeMap<String, String>) -> Result<Node, Diagnostic> {
    let mut params = defines.clone();
    read_file(path, &mut Reading::new(&mut params, defines, path), 0, None)
}

/// What reading a document carries from file to file: the `<default>`s seen so far
/// (includes share their parent's), the caller's overrides, the `<path>` folders
/// declared so far and the main scene's folder.
struct Reading<'r> {
    params: &'r mut BTreeMap<String, String>,
    defines: &'r BTreeMap<String, String>,
    folders: Vec<PathBuf>,
    main: PathBuf,
}

impl<'r> Reading<'r> {
    /// The start of reading the document at `path` (its folder is the main one).
    fn new(
        params: &'r mut BTreeMap<String, String>,
        defines: &'r BTreeMap<String, String>,
        path: &Path,
    ) -> Self {
        let main = path.parent().unwrap_or(Path::new("")).to_path_buf();
        Reading {
            params,
            defines,
            folders: Vec::new(),
            main,
        }
    }
}

/// Where a relative file name is looked for, as Mitsuba 3's file resolver does
/// (src/core/parser.cpp, `fresolver.cpp`): the `<path>` folders, the one declared last
/// first, then the main scene's folder; heron then tries the folder of the file that
/// names it (an included file's own folder), which Mitsuba does not. The first
/// candidate that exists, or the first candidate when none does (its error names it).
pub fn find_file(name: &str, folders: &[PathBuf], main: &Path, own: &Path) -> PathBuf {
    let name = Path::new(name);
    if name.is_absolute() {
        return name.to_path_buf();
    }
    let candidates: Vec<PathBuf> = folders
        .iter()
        .rev()
        .map(|f| f.join(name))
        .chain([main.join(name), own.join(name)])
        .collect();
    candidates
        .iter()
        .find(|c| c.exists())
        .unwrap_or(&candidates[0])
        .clone()
}

/// The `<path value="…">` folders of a document read by [`read_document`], in the order
/// they were declared, each already resolved.
pub fn path_folders(root: &Node) -> Vec<PathBuf> {
    root.children
        .iter()
        .filter(|c| c.tag == "path")
        .filter_map(|c| c.attr("value").map(PathBuf::from))
        .collect()
}

/// Reads one file; `params` holds the `<default>`s seen so far (includes share their
/// parent's), `defines` the caller's overrides, `from` the including element.
fn read_file(
    path: &Path,
    r: &mut Reading,
    depth: usize,
    from: Option<&Node>,
) -> Result<Node, Diagnostic> {
    let at_from = |message: String| match from {
        Some(n) => n.diag(message),
        None => Diagnostic {
            file: path.to_path_buf(),
            line: 1,
            message,
        },
    };
    if depth > MAX_INCLUDE_DEPTH {
        return Err(at_from(format!(
            "includes nested more than {MAX_INCLUDE_DEPTH} deep (does {} include itself?)",
            path.display()
        )));
    }
    let text = std::fs::read_to_string(path)
        .map_err(|e| at_from(format!("cannot read {}: {e}", path.display())))?;
    parse_text(&text, path, r, depth)
}

/// The document of `text`, read as if from `path` (includes resolve from its folder).
pub fn read_document_from_str(
    text: &str,
    path: &Path,
    defines: &BTreeMap<String, String>,
) -> Result<Node, Diagnostic> {
    let mut params = defines.clone();
    parse_text(text, path, &mut Reading::new(&mut params, defines, path), 0)
}

fn parse_text(text: &str, path: &Path, r: &mut Reading, depth: usize) -> Result<Node, Diagnostic> {
    let file = Arc::new(path.to_path_buf());
    let doc = roxmltree::Document::parse(text).map_err(|e| {
        let pos = e.pos();
        Diagnostic {
            file: file.as_ref().clone(),
            line: pos.row,
            // roxmltree's message quotes the offending character as is (a newline
            // too): escaped, so the error stays on one line.
            message: format!("malformed XML: {}", e.to_string().escape_debug()),
        }
    })?;
    let root = doc.root_element();
    if root.tag_name().name() != "scene" {
        return Err(Diagnostic {
            file: file.as_ref().clone(),
            line: doc.text_pos_at(root.range().start).row,
            message: format!(
                "expected the root element <scene> of a Mitsuba 3 scene, got <{}>",
                root.tag_name().name()
            ),
        });
    }
    let base = path.parent().unwrap_or(Path::new("")).to_path_buf();
    convert(&doc, root, &file, &base, r, depth)
}

fn convert(
    doc: &roxmltree::Document,
    el: roxmltree::Node,
    file: &Arc<PathBuf>,
    base: &Path,
    r: &mut Reading,
    depth: usize,
) -> Result<Node, Diagnostic> {
    let line = doc.text_pos_at(el.range().start).row;
    let tag = el.tag_name().name().to_string();
    let mut node = Node {
        tag,
        attrs: Vec::new(),
        file: file.clone(),
        line,
        children: Vec::new(),
    };
    for a in el.attributes() {
        let value = substitute(a.value(), r.params).map_err(|m| node.diag(m))?;
        node.attrs.push((a.name().to_string(), value));
    }
    for child in el.children().filter(|c| c.is_element()) {
        let mut c = convert(doc, child, file, base, r, depth)?;
        match c.tag.as_str() {
            "default" => {
                let (Some(name), Some(value)) = (c.attr("name"), c.attr("value")) else {
                    return Err(c.diag("expected the attributes name and value"));
                };
                // A define given by the caller wins over the file's default.
                if !r.defines.contains_key(name) {
                    r.params.insert(name.to_string(), value.to_string());
                }
            }
            "include" => {
                let Some(f) = c.attr("filename") else {
                    return Err(c.diag("expected the attribute filename"));
                };
                // Mitsuba looks in the including file's folder first, then where every
                // other file is looked for.
                let own = base.join(f);
                let found = if own.exists() {
                    own
                } else {
                    find_file(f, &r.folders, &r.main, base)
                };
                let included = read_file(&found, r, depth + 1, Some(&c))?;
                node.children.extend(included.children);
            }
            // A resource folder (Mitsuba's <path>, a child of the root only): relative to
            // the declaring file's folder, else looked up as files are; it must exist.
            // Its value becomes the resolved folder.
            "path" if el == doc.root_element() => {
                let Some(v) = c.attr("value").map(str::to_string) else {
                    return Err(c.diag("expected the attribute value"));
                };
                let own = base.join(&v);
                let found = if own.is_dir() {
                    own
                } else {
                    find_file(&v, &r.folders, &r.main, base)
                };
                if !found.is_dir() {
                    return Err(c.diag(format!(
                        "<path>: folder {v:?} not found (looked in {})",
                        base.display()
                    )));
                }
                c.attrs.retain(|(k, _)| k != "value");
                c.attrs
                    .push(("value".into(), found.to_string_lossy().into_owned()));
                r.folders.push(found);
                node.children.push(c);
            }
            "path" => return Err(c.diag("<path> must be a child of the root <scene>")),
            _ => node.children.push(c),
        }
    }
    Ok(node)
}

/// `value` with each `$name` replaced by its parameter; an unknown one is an error.
fn substitute(value: &str, params: &BTreeMap<String, String>) -> Result<String, String> {
    if !value.contains('$') {
        return Ok(value.to_string());
    }
    let mut out = String::new();
    let mut rest = value;
    while let Some(i) = rest.find('$') {
        out.push_str(&rest[..i]);
        let tail = &rest[i + 1..];
        let end = tail
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(tail.len());
        let name = &tail[..end];
        match params.get(name) {
            Some(v) => out.push_str(v),
            None => {
                return Err(format!(
                    "${name} is not defined (expected a <default name=\"{name}\" value=\"…\"/> before it, or -D {name}=…)"
                ))
            }
        }
        rest = &tail[end..];
    }
    out.push_str(rest);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn substitution_replaces_every_parameter_and_names_an_unknown_one() {
        let mut p = BTreeMap::new();
        p.insert("spp".to_string(), "64".to_string());
        p.insert("res".to_string(), "256".to_string());
        assert_eq!(substitute("$spp", &p).unwrap(), "64");
        assert_eq!(substitute("$res, $res", &p).unwrap(), "256, 256");
        let e = substitute("$nope", &p).unwrap_err();
        assert!(e.contains("$nope is not defined"), "{e}");
    }
}
