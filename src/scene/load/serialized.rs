//! Mitsuba's serialized meshes (`.serialized`), versions 3 and 4: the format Mitsuba 0.x
//! writes and Mitsuba 3 (through 3.9) reads, documented in Mitsuba 3's
//! `src/shapes/serialized.cpp`.
//!
//! A file is one or more shapes, one after the other, each a little-endian header (u16
//! magic 0x041C, u16 version) and then a zlib stream holding: u32 flags (0x0001 vertex
//! normals, 0x0002 texture coordinates, 0x0008 vertex colours, 0x0010 face normals,
//! 0x1000 single and 0x2000 double precision), in version 4 the shape's name (UTF-8,
//! null-terminated), u64 vertex count V, u64 triangle count F, then V positions, V
//! normals, V texture coordinates and V colours (those the flags announce; 3, 3, 2 and 3
//! floats or doubles each), and last 3F u32 vertex indices. The file ends with the byte
//! offset of each shape (u32 in version 3, u64 in version 4) and then their u32 count,
//! which is how shape `shape_index` is found.
//!
//! heron keeps the positions, the triangles and the texture coordinates (as they are:
//! Mitsuba flips an OBJ's v, not a serialized mesh's); normals and colours are read
//! past, since heron shades meshes by their face normals. Errors are one line naming the
//! shape and what was expected; the caller adds the file.
use super::obj::ObjGroup;
use glam::{Vec2, Vec3};

/// The first two bytes of every shape (Mitsuba's `MTS_FILEFORMAT_HEADER`).
const MAGIC: u16 = 0x041C;
const HAS_NORMALS: u32 = 0x0001;
const HAS_TEXCOORDS: u32 = 0x0002;
const HAS_COLORS: u32 = 0x0008;
const SINGLE_PRECISION: u32 = 0x1000;
const DOUBLE_PRECISION: u32 = 0x2000;

/// Shape `shape_index` of a serialized file as one group, named by the shape's name
/// (version 4) or, when it has none, by `name`.
pub(crate) fn parse_serialized(
    bytes: &[u8],
    shape_index: u32,
    name: &str,
) -> Result<Vec<ObjGroup>, String> {
    let version = header(bytes, 0).map_err(|e| format!("shape 0: {e}"))?;
    let at = |e: String| format!("shape {shape_index}: {e}");
    let start = if shape_index == 0 {
        // As Mitsuba: the first shape starts the file, without the table at its end.
        0
    } else {
        let start = shape_offset(bytes, version, shape_index)?;
        let v = header(bytes, start).map_err(|e| at(format!("at byte {start}: {e}")))?;
        if v != version {
            return Err(at(format!(
                "at byte {start}: expected version {version} as the file's first shape, got {v}"
            )));
        }
        start
    };
    let data = inflate(&bytes[start + 4..]).map_err(at)?;
    let shape = Shape::read(&data, version).map_err(at)?;
    let name = match shape.name {
        Some(n) if !n.is_empty() => n,
        _ => name.to_string(),
    };
    Ok(vec![ObjGroup {
        name,
        positions: shape.positions,
        indices: shape.indices,
        uvs: shape.uvs,
    }])
}

/// The version of the shape header at byte `at`.
fn header(bytes: &[u8], at: usize) -> Result<u16, String> {
    let Some(h) = bytes.get(at..at.saturating_add(4)) else {
        return Err(format!(
            "expected a 4-byte header (0x041C and the version), the file has {} bytes",
            bytes.len()
        ));
    };
    let magic = u16::from_le_bytes([h[0], h[1]]);
    let version = u16::from_le_bytes([h[2], h[3]]);
    if magic != MAGIC {
        return Err(format!(
            "expected Mitsuba's serialized-mesh magic 0x041C, got 0x{magic:04X}"
        ));
    }
    match version {
        3 | 4 => Ok(version),
        // Mitsuba 3's packed layout, after its 3.9 releases (src/render/mesh.cpp).
        5 => Err(
            "version 5 (Mitsuba 3's packed mesh records) is not supported: expected version 3 or 4"
                .into(),
        ),
        v => Err(format!("expected format version 3 or 4, got {v}")),
    }
}

/// Where shape `index` (≥ 1) starts, from the table at the end of the file.
fn shape_offset(bytes: &[u8], version: u16, index: u32) -> Result<usize, String> {
    let len = bytes.len();
    let at = |e: String| format!("shape_index {index}: {e}");
    let count = len
        .checked_sub(4)
        .and_then(|k| bytes.get(k..))
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .ok_or_else(|| at("expected the file to end with its count of shapes".into()))?;
    if index >= count {
        let s = if count == 1 { "" } else { "s" };
        return Err(at(format!(
            "the file holds {count} shape{s}, expected an index below {count}"
        )));
    }
    let entry = if version == 3 { 4 } else { 8 };
    let table = (count as usize)
        .checked_mul(entry)
        .and_then(|t| (len - 4).checked_sub(t))
        .ok_or_else(|| {
            at(format!(
                "expected a table of {count} offsets of {entry} bytes before the count at the end, the file has {len} bytes"
            ))
        })?;
    let k = table + index as usize * entry;
    let b = &bytes[k..k + entry];
    let offset = if entry == 4 {
        u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as u64
    } else {
        u64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]])
    };
    match usize::try_from(offset) {
        Ok(o) if o < table => Ok(o),
        _ => Err(at(format!(
            "the table gives byte offset {offset}, expected one before the table at byte {table}"
        ))),
    }
}

/// The zlib stream at the start of `compressed` (what follows it, the next shape or the
/// table, is left alone). Deflate expands at most about 1032-fold, so the output is
/// bounded by the file's size.
fn inflate(compressed: &[u8]) -> Result<Vec<u8>, String> {
    use miniz_oxide::inflate::TINFLStatus as S;
    miniz_oxide::inflate::decompress_to_vec_zlib(compressed).map_err(|e| match e.status {
        S::FailedCannotMakeProgress | S::NeedsMoreInput => {
            "the compressed data ends early: expected a complete zlib stream".into()
        }
        S::Adler32Mismatch => "the zlib stream's checksum does not match its data".into(),
        s => format!("expected a zlib stream, cannot decompress it ({s:?})"),
    })
}

/// What heron keeps of one shape.
struct Shape {
    name: Option<String>,
    positions: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    uvs: Vec<[Vec2; 3]>,
}

impl Shape {
    /// Reads the decompressed stream of a shape of `version`.
    fn read(data: &[u8], version: u16) -> Result<Shape, String> {
        let mut r = Cursor { data, pos: 0 };
        let flags = r.u32("the flags")?;
        if flags & SINGLE_PRECISION != 0 && flags & DOUBLE_PRECISION != 0 {
            return Err(format!(
                "flags 0x{flags:04X}: expected single (0x1000) or double (0x2000) precision, not both"
            ));
        }
        let name = if version >= 4 {
            Some(r.c_string()?)
        } else {
            None
        };
        let vertices = r.u64("the vertex count")?;
        let triangles = r.u64("the triangle count")?;
        // heron indexes vertices in 32 bits (as Mitsuba 3 does).
        let v = u32::try_from(vertices)
            .map_err(|_| format!("expected at most {} vertices, got {vertices}", u32::MAX))?
            as usize;
        let double = flags & DOUBLE_PRECISION != 0;
        let size = if double { 8 } else { 4 };
        let dims = [
            (true, 3),
            (flags & HAS_NORMALS != 0, 3),
            (flags & HAS_TEXCOORDS != 0, 2),
            (flags & HAS_COLORS != 0, 3),
        ];
        let per_vertex: usize = dims.iter().filter(|d| d.0).map(|d| d.1 * size).sum();
        // Checked before anything is allocated, so that a short file claiming a large
        // mesh is an error and not an allocation.
        let need = (v as u64)
            .checked_mul(per_vertex as u64)
            .zip(triangles.checked_mul(12))
            .and_then(|(a, b)| a.checked_add(b));
        let left = r.left() as u64;
        if !matches!(need, Some(n) if n <= left) {
            return Err(format!(
                "the data ends early: {vertices} vertices and {triangles} triangles (flags 0x{flags:04X}) need {} bytes after the header, the stream holds {left}",
                need.map_or("more than 2^64".into(), |n| n.to_string())
            ));
        }
        let f = triangles as usize;
        let positions = r.points::<3>(v, double)?;
        let positions: Vec<Vec3> = positions.into_iter().map(Vec3::from_array).collect();
        if let Some(k) = positions.iter().position(|p| !p.is_finite()) {
            return Err(format!(
                "vertex {k}: expected finite coordinates in f32, got {}",
                positions[k]
            ));
        }
        if flags & HAS_NORMALS != 0 {
            r.skip(v * 3 * size);
        }
        let texcoords = if flags & HAS_TEXCOORDS != 0 {
            let t: Vec<Vec2> = r
                .points::<2>(v, double)?
                .into_iter()
                .map(Vec2::from_array)
                .collect();
            if let Some(k) = t.iter().position(|p| !p.is_finite()) {
                return Err(format!(
                    "vertex {k}: expected finite texture coordinates in f32, got {}",
                    t[k]
                ));
            }
            t
        } else {
            Vec::new()
        };
        if flags & HAS_COLORS != 0 {
            r.skip(v * 3 * size);
        }
        let mut indices = Vec::with_capacity(f);
        for t in 0..f {
            let mut tri = [0u32; 3];
            for c in &mut tri {
                *c = r.u32("the triangles")?;
                if *c as usize >= v {
                    return Err(format!(
                        "triangle {t}: expected vertex indices below the {v} vertices, got {c}"
                    ));
                }
            }
            indices.push(tri);
        }
        let uvs = if texcoords.is_empty() {
            Vec::new()
        } else {
            indices
                .iter()
                .map(|t| t.map(|i| texcoords[i as usize]))
                .collect()
        };
        Ok(Shape {
            name,
            positions,
            indices,
            uvs,
        })
    }
}

/// Little-endian reading of the decompressed stream.
struct Cursor<'a> {
    data: &'a [u8],
    pos: usize,
}

impl Cursor<'_> {
    fn left(&self) -> usize {
        self.data.len() - self.pos
    }

    fn take<const N: usize>(&mut self, what: &str) -> Result<[u8; N], String> {
        let b = self
            .data
            .get(self.pos..self.pos + N)
            .ok_or_else(|| format!("the data ends early, in {what}"))?;
        self.pos += N;
        Ok(b.try_into().expect("N bytes"))
    }

    fn u32(&mut self, what: &str) -> Result<u32, String> {
        self.take::<4>(what).map(u32::from_le_bytes)
    }

    fn u64(&mut self, what: &str) -> Result<u64, String> {
        self.take::<8>(what).map(u64::from_le_bytes)
    }

    /// `n` points of `D` floats or doubles, as f32 (as Mitsuba 3 keeps them).
    fn points<const D: usize>(&mut self, n: usize, double: bool) -> Result<Vec<[f32; D]>, String> {
        let mut out = Vec::with_capacity(n);
        for _ in 0..n {
            let mut p = [0f32; D];
            for c in &mut p {
                *c = if double {
                    f64::from_le_bytes(self.take::<8>("the vertex data")?) as f32
                } else {
                    f32::from_le_bytes(self.take::<4>("the vertex data")?)
                };
            }
            out.push(p);
        }
        Ok(out)
    }

    /// Skips `n` bytes the caller has checked are there.
    fn skip(&mut self, n: usize) {
        self.pos = (self.pos + n).min(self.data.len());
    }

    /// A null-terminated UTF-8 string (version 4's shape name).
    fn c_string(&mut self) -> Result<String, String> {
        let rest = &self.data[self.pos..];
        let end = rest
            .iter()
            .position(|&b| b == 0)
            .ok_or("expected the shape's name to end with a null byte, found none")?;
        let s =
            std::str::from_utf8(&rest[..end]).map_err(|_| "expected the shape's name in UTF-8")?;
        self.pos += end + 1;
        Ok(s.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One shape's stream: flags, name (version 4), counts, positions, indices.
    fn shape(version: u16, flags: u32, p: &[[f32; 3]], t: &[[u32; 3]]) -> Vec<u8> {
        let mut s = flags.to_le_bytes().to_vec();
        if version == 4 {
            s.extend(b"tri\0");
        }
        s.extend((p.len() as u64).to_le_bytes());
        s.extend((t.len() as u64).to_le_bytes());
        for c in p.iter().flatten() {
            s.extend(c.to_le_bytes());
        }
        for i in t.iter().flatten() {
            s.extend(i.to_le_bytes());
        }
        let mut out = MAGIC.to_le_bytes().to_vec();
        out.extend(version.to_le_bytes());
        out.extend(miniz_oxide::deflate::compress_to_vec_zlib(&s, 6));
        out
    }

    const P: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

    #[test]
    fn one_shape_reads_without_the_table() {
        for v in [3, 4] {
            let b = shape(v, SINGLE_PRECISION, &P, &[[0, 1, 2]]);
            let g = parse_serialized(&b, 0, "stem").unwrap();
            assert_eq!(g[0].positions[1], Vec3::X);
            assert_eq!(g[0].indices, vec![[0, 1, 2]]);
            assert_eq!(g[0].name, if v == 4 { "tri" } else { "stem" });
        }
    }

    #[test]
    fn bad_streams_are_errors_naming_the_shape() {
        let b = shape(4, SINGLE_PRECISION, &P, &[[0, 1, 3]]);
        let e = parse_serialized(&b, 0, "m").unwrap_err();
        assert!(
            e.starts_with("shape 0: triangle 0") && e.contains("below the 3"),
            "{e}"
        );
        let b = shape(4, SINGLE_PRECISION, &[[0.0, f32::NAN, 0.0]], &[]);
        let e = parse_serialized(&b, 0, "m").unwrap_err();
        assert!(e.contains("vertex 0: expected finite"), "{e}");
        let b = shape(3, SINGLE_PRECISION | DOUBLE_PRECISION, &P, &[]);
        let e = parse_serialized(&b, 0, "m").unwrap_err();
        assert!(e.contains("not both"), "{e}");
        // Counts beyond the data: an error before anything is allocated.
        let mut b = shape(3, SINGLE_PRECISION, &P, &[[0, 1, 2]]);
        let s = miniz_oxide::inflate::decompress_to_vec_zlib(&b[4..]).unwrap();
        let mut s2 = s.clone();
        s2[4..12].copy_from_slice(&u64::MAX.to_le_bytes());
        b.truncate(4);
        b.extend(miniz_oxide::deflate::compress_to_vec_zlib(&s2, 6));
        let e = parse_serialized(&b, 0, "m").unwrap_err();
        assert!(e.contains("at most 4294967295 vertices"), "{e}");
        s2[4..12].copy_from_slice(&1000u64.to_le_bytes());
        b.truncate(4);
        b.extend(miniz_oxide::deflate::compress_to_vec_zlib(&s2, 6));
        let e = parse_serialized(&b, 0, "m").unwrap_err();
        assert!(e.contains("the data ends early: 1000 vertices"), "{e}");
        let e = parse_serialized(&[0x1C, 0x04, 6, 0], 0, "m").unwrap_err();
        assert!(e.contains("version 3 or 4, got 6"), "{e}");
        let e = parse_serialized(&[0x1C, 0x04, 3, 0, 1, 2], 0, "m").unwrap_err();
        assert!(e.contains("expected a zlib stream"), "{e}");
    }
}
