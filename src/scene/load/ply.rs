//! A PLY reader for triangle meshes (Turk 1994, "The PLY polygon file format"; the
//! variant Mitsuba 3 and pbrt-v4 write): `ascii`, `binary_little_endian` and
//! `binary_big_endian`; the `vertex` element's `x`, `y`, `z` (float or double, other
//! properties skipped) and the `face` element's `vertex_indices` (or `vertex_index`)
//! list, polygons split into fans. Other elements are read past. Errors name the
//! header line or the element and index.
use super::obj::ObjGroup;
use glam::Vec3;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Scalar> {
        Some(match s {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

#[derive(Clone, Debug)]
struct Property {
    name: String,
    /// `Some(count type)` for a list.
    list: Option<Scalar>,
    ty: Scalar,
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: usize,
    props: Vec<Property>,
}

#[derive(Clone, Copy, PartialEq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

/// The mesh of a PLY file as one group (named by `name`).
pub(crate) fn parse_ply(bytes: &[u8], name: &str) -> Result<Vec<ObjGroup>, String> {
    let (encoding, elements, body) = parse_header(bytes)?;
    let mut reader = Reader {
        bytes,
        pos: body,
        encoding,
    };
    let mut mesh = Mesh::default();
    let mut seen_vertex = false;
    for el in &elements {
        mesh.read_element(&mut reader, el)?;
        seen_vertex |= el.name == "vertex";
        if el.name == "face" && !seen_vertex {
            return Err("the face element comes before the vertex element".into());
        }
    }
    Ok(vec![mesh.into_group(name)])
}

/// The header's encoding and elements, and where the body starts. The header is ASCII
/// up to and including "end_header\n".
fn parse_header(bytes: &[u8]) -> Result<(Encoding, Vec<Element>, usize), String> {
    let end = find(bytes, b"end_header")
        .ok_or("expected a PLY header ending in end_header, found none")?;
    let mut body = end + "end_header".len();
    if bytes.get(body) == Some(&b'\r') {
        body += 1;
    }
    if bytes.get(body) == Some(&b'\n') {
        body += 1;
    }
    let header = std::str::from_utf8(&bytes[..end]).map_err(|_| "the PLY header is not ASCII")?;
    let mut lines = header.lines().enumerate();
    match lines.next() {
        Some((_, l)) if l.trim() == "ply" => {}
        _ => return Err("line 1: expected \"ply\", the PLY magic".into()),
    }
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    for (i, line) in lines {
        header_line(i + 1, line, &mut encoding, &mut elements)?;
    }
    let encoding = encoding.ok_or("expected a format line in the PLY header")?;
    Ok((encoding, elements, body))
}

/// One header line (number `n`) into the encoding or the elements.
fn header_line(
    n: usize,
    line: &str,
    encoding: &mut Option<Encoding>,
    elements: &mut Vec<Element>,
) -> Result<(), String> {
    let w: Vec<&str> = line.split_whitespace().collect();
    let (list, ty, name) = match w.as_slice() {
        [] | ["comment", ..] | ["obj_info", ..] => return Ok(()),
        ["format", f, _version] => {
            *encoding = Some(match *f {
                "ascii" => Encoding::Ascii,
                "binary_little_endian" => Encoding::Little,
                "binary_big_endian" => Encoding::Big,
                other => return Err(format!("line {n}: unknown PLY format {other:?}")),
            });
            return Ok(());
        }
        ["element", name, count] => {
            elements.push(Element {
                name: name.to_string(),
                count: count
                    .parse()
                    .map_err(|_| format!("line {n}: expected an element count, got {count:?}"))?,
                props: Vec::new(),
            });
            return Ok(());
        }
        ["property", "list", ct, ty, name] => {
            let (Some(ct), Some(ty)) = (Scalar::parse(ct), Scalar::parse(ty)) else {
                return Err(format!("line {n}: unknown property types in {line:?}"));
            };
            (Some(ct), ty, name)
        }
        ["property", ty, name] => {
            let ty = Scalar::parse(ty).ok_or(format!("line {n}: unknown property type {ty:?}"))?;
            (None, ty, name)
        }
        _ => {
            return Err(format!(
                "line {n}: expected a PLY header line, got {line:?}"
            ))
        }
    };
    let el = elements
        .last_mut()
        .ok_or(format!("line {n}: a property before any element"))?;
    el.props.push(Property {
        name: name.to_string(),
        list,
        ty,
    });
    Ok(())
}

/// The mesh as it is read.
#[derive(Default)]
struct Mesh {
    positions: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    /// Texture coordinates per vertex, under the names Mitsuba 3's PLY reader accepts.
    vertex_uvs: Vec<glam::Vec2>,
}

/// Where a vertex element keeps its position and texture coordinates, and a face element
/// its vertex indices.
struct Layout {
    xyz: [Option<usize>; 3],
    uv: Option<[usize; 2]>,
    list: Option<usize>,
}

impl Layout {
    fn of(el: &Element) -> Result<Layout, String> {
        let xyz = ["x", "y", "z"].map(|c| el.props.iter().position(|p| p.name == c));
        let scalar = |name: &str| {
            el.props
                .iter()
                .position(|p| p.name == name && p.list.is_none())
        };
        let uv = [
            ("u", "v"),
            ("texture_u", "texture_v"),
            ("s", "t"),
            ("texture_s", "texture_t"),
        ]
        .iter()
        .find_map(|(a, b)| Some([scalar(a)?, scalar(b)?]))
        .filter(|_| el.name == "vertex");
        let list = el.props.iter().position(|p| {
            p.list.is_some() && (p.name == "vertex_indices" || p.name == "vertex_index")
        });
        if el.name == "vertex" && xyz.iter().any(Option::is_none) {
            return Err("the vertex element lacks one of the properties x, y, z".into());
        }
        if el.name == "face" && list.is_none() {
            return Err("the face element lacks the list property vertex_indices".into());
        }
        Ok(Layout { xyz, uv, list })
    }
}

impl Mesh {
    /// Reads element `el`'s rows, keeping the vertices and the faces.
    fn read_element(&mut self, reader: &mut Reader, el: &Element) -> Result<(), String> {
        let layout = Layout::of(el)?;
        if el.name == "vertex" {
            self.positions.reserve(el.count.min(1 << 24));
        }
        let mut face = Vec::new();
        for k in 0..el.count {
            let mut p = [0.0f64; 3];
            let mut uv = [0.0f64; 2];
            for (j, prop) in el.props.iter().enumerate() {
                let at = || format!("{} {k}, property {}", el.name, prop.name);
                let Some(ct) = prop.list else {
                    let v = reader
                        .scalar(prop.ty)
                        .map_err(|e| format!("{}: {e}", at()))?;
                    if el.name == "vertex" {
                        if let Some(c) = layout.xyz.iter().position(|x| *x == Some(j)) {
                            p[c] = v;
                        }
                        if let Some(c) = layout.uv.and_then(|t| t.iter().position(|x| *x == j)) {
                            uv[c] = v;
                        }
                    }
                    continue;
                };
                let count = reader.scalar(ct).map_err(|e| format!("{}: {e}", at()))?;
                if !(0.0..=1e6).contains(&count) {
                    return Err(format!("{}: expected a list length, got {count}", at()));
                }
                face.clear();
                for _ in 0..count as usize {
                    face.push(
                        reader
                            .scalar(prop.ty)
                            .map_err(|e| format!("{}: {e}", at()))?,
                    );
                }
                if el.name == "face" && Some(j) == layout.list {
                    self.add_polygon(&face, &at())?;
                }
            }
            if el.name == "vertex" {
                self.add_vertex(k, p, layout.uv.map(|_| uv))?;
            }
        }
        Ok(())
    }

    /// A polygon of vertex indices (as read), split into a fan of triangles.
    fn add_polygon(&mut self, face: &[f64], at: &str) -> Result<(), String> {
        if face.len() < 3 {
            return Err(format!(
                "{at}: expected a polygon of at least 3 vertices, got {}",
                face.len()
            ));
        }
        let read = self.positions.len();
        let idx = |v: f64| -> Result<u32, String> {
            if v >= 0.0 && v.fract() == 0.0 && (v as usize) < read {
                Ok(v as u32)
            } else {
                Err(format!(
                    "{at}: expected vertex indices below the {read} vertices read, got {v}"
                ))
            }
        };
        let a = idx(face[0])?;
        for w in face[1..].windows(2) {
            self.indices.push([a, idx(w[0])?, idx(w[1])?]);
        }
        Ok(())
    }

    /// Vertex `k`'s position and, if the element has them, its texture coordinates.
    fn add_vertex(&mut self, k: usize, p: [f64; 3], uv: Option<[f64; 2]>) -> Result<(), String> {
        let v = Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32);
        if !v.is_finite() {
            return Err(format!(
                "vertex {k}: expected finite coordinates in f32, got {p:?}"
            ));
        }
        self.positions.push(v);
        if let Some(uv) = uv {
            let t = glam::Vec2::new(uv[0] as f32, uv[1] as f32);
            if !t.is_finite() {
                return Err(format!(
                    "vertex {k}: expected finite texture coordinates in f32, got {uv:?}"
                ));
            }
            self.vertex_uvs.push(t);
        }
        Ok(())
    }

    /// The mesh as one group, with per-corner texture coordinates when every vertex
    /// has them.
    fn into_group(self, name: &str) -> ObjGroup {
        let uvs = if self.vertex_uvs.len() == self.positions.len() && !self.vertex_uvs.is_empty() {
            self.indices
                .iter()
                .map(|t| t.map(|i| self.vertex_uvs[i as usize]))
                .collect()
        } else {
            Vec::new()
        };
        ObjGroup {
            name: name.to_string(),
            positions: self.positions,
            indices: self.indices,
            uvs,
        }
    }
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
    encoding: Encoding,
}

impl Reader<'_> {
    fn scalar(&mut self, ty: Scalar) -> Result<f64, String> {
        if self.encoding == Encoding::Ascii {
            let rest = &self.bytes[self.pos..];
            let start = rest
                .iter()
                .position(|b| !b.is_ascii_whitespace())
                .ok_or("the file ends early")?;
            let len = rest[start..]
                .iter()
                .position(|b| b.is_ascii_whitespace())
                .unwrap_or(rest.len() - start);
            let word = std::str::from_utf8(&rest[start..start + len]).map_err(|_| "not ASCII")?;
            self.pos += start + len;
            return word
                .parse::<f64>()
                .map_err(|_| format!("expected a number, got {word:?}"));
        }
        let n = ty.size();
        let b = self
            .bytes
            .get(self.pos..self.pos + n)
            .ok_or("the file ends early")?;
        self.pos += n;
        let mut a = [0u8; 8];
        a[..n].copy_from_slice(b);
        if self.encoding == Encoding::Big {
            a[..n].reverse();
        }
        Ok(match ty {
            Scalar::I8 => a[0] as i8 as f64,
            Scalar::U8 => a[0] as f64,
            Scalar::I16 => i16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::U16 => u16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::I32 => i32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::U32 => u32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F32 => f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F64 => f64::from_le_bytes(a),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII: &str = "ply\nformat ascii 1.0\ncomment a unit square\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 9\n1 0 0 9\n1 1 0 9\n0 1 0 9\n4 0 1 2 3\n";

    #[test]
    fn ascii_quad_is_two_triangles_of_a_fan() {
        let g = parse_ply(ASCII.as_bytes(), "m").unwrap();
        assert_eq!(g[0].positions.len(), 4);
        assert_eq!(g[0].positions[2], Vec3::new(1.0, 1.0, 0.0));
        assert_eq!(g[0].indices, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn binary_little_and_big_endian_read_the_same_mesh() {
        for (fmt, big) in [("binary_little_endian", false), ("binary_big_endian", true)] {
            let mut b = format!("ply\nformat {fmt} 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n").into_bytes();
            for v in [[0.0f64, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 3.0, 0.5]] {
                for c in v {
                    b.extend(if big {
                        c.to_be_bytes()
                    } else {
                        c.to_le_bytes()
                    });
                }
            }
            b.push(3);
            for i in [0u32, 1, 2] {
                b.extend(if big {
                    i.to_be_bytes()
                } else {
                    i.to_le_bytes()
                });
            }
            let g = parse_ply(&b, "m").unwrap();
            assert_eq!(g[0].positions[2], Vec3::new(0.0, 3.0, 0.5), "{fmt}");
            assert_eq!(g[0].indices, vec![[0, 1, 2]], "{fmt}");
        }
    }

    #[test]
    fn bad_files_are_errors_that_say_where() {
        let e = parse_ply(b"plx\nformat ascii 1.0\nend_header\n", "m").unwrap_err();
        assert!(e.contains("line 1"), "{e}");
        let bad_index = ASCII.replace("4 0 1 2 3", "3 0 1 7");
        let e = parse_ply(bad_index.as_bytes(), "m").unwrap_err();
        assert!(
            e.contains("face 0") && e.contains("below the 4 vertices"),
            "{e}"
        );
        let short = &ASCII.as_bytes()[..ASCII.len() - 6];
        let e = parse_ply(short, "m").unwrap_err();
        assert!(e.contains("ends early"), "{e}");
        let e = parse_ply(
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float q\nend_header\n0\n",
            "m",
        )
        .unwrap_err();
        assert!(e.contains("x, y, z"), "{e}");
    }
}
