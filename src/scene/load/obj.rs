//! Wavefront OBJ reading for `type = "mesh"` shapes: positions and triangle indices only,
//! per OBJ object/group name.
//!
//! A light pre-scan of the `v` and `f` lines runs first: it reports the usual mistakes
//! (unreadable or non-finite coordinates, bad or out-of-range face indices) with their
//! line, which `tobj` cannot, and hands `tobj` only what heron uses: `v`, `o` and `g`
//! lines, and `f` lines reduced to their position indices (texture coordinates,
//! normals, materials, points and lines are dropped, so their indices cannot fail).
//! `tobj` then groups the faces by object and triangulates them as fans.
use glam::Vec3;

/// The triangles of one OBJ object/group (`o NAME` or `g NAME`; the later of the two
/// names when both precede a block of faces, as `tobj` does). One name may occur in
/// several groups (e.g. when `usemtl` splits an object).
#[derive(Debug)]
pub(crate) struct ObjGroup {
    pub name: String,
    pub positions: Vec<Vec3>,
    pub indices: Vec<[u32; 3]>,
}

/// Parses OBJ text. The error is one line, without the file name.
pub(crate) fn parse_obj(text: &str) -> Result<Vec<ObjGroup>, String> {
    let text = prescan(text)?;
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _materials) = tobj::load_obj_buf(&mut text.as_bytes(), &opts, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| format!("cannot parse the OBJ file: {e}"))?;
    let mut groups = Vec::with_capacity(models.len());
    for m in models {
        let p = &m.mesh.positions;
        if p.len() % 3 != 0 || m.mesh.indices.len() % 3 != 0 {
            return Err(format!(
                "object {:?}: the OBJ reader returned malformed arrays",
                m.name
            ));
        }
        let positions: Vec<Vec3> = p.chunks_exact(3).map(Vec3::from_slice).collect();
        if let Some(bad) = positions.iter().find(|v| !v.is_finite()) {
            return Err(format!(
                "object {:?}: a vertex has a non-finite coordinate ({bad})",
                m.name
            ));
        }
        let n = positions.len() as u32;
        let mut indices = Vec::with_capacity(m.mesh.indices.len() / 3);
        for t in m.mesh.indices.chunks_exact(3) {
            if t.iter().any(|&i| i >= n) {
                return Err(format!(
                    "object {:?}: a face vertex index is out of range",
                    m.name
                ));
            }
            indices.push([t[0], t[1], t[2]]);
        }
        groups.push(ObjGroup {
            name: m.name,
            positions,
            indices,
        });
    }
    Ok(groups)
}

/// Checks `v` and `f` lines so that the common errors carry a line number, and returns
/// the text `tobj` reads: `v`, `o`, `g` lines as they are, `f` lines with position
/// indices only, nothing else.
fn prescan(text: &str) -> Result<String, String> {
    let mut out = String::with_capacity(text.len());
    let total_v = text
        .lines()
        .filter(|l| l.split_whitespace().next() == Some("v"))
        .count();
    let mut seen_v = 0usize;
    for (i, line) in text.lines().enumerate() {
        let ln = i + 1;
        // A `#` starts a comment, also after data.
        let line = line.split('#').next().unwrap_or("");
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                seen_v += 1;
                let coords: Vec<Option<f32>> =
                    words.take(3).map(|w| w.parse::<f32>().ok()).collect();
                if coords.len() != 3 || coords.iter().any(Option::is_none) {
                    return Err(format!(
                        "line {ln}: expected `v x y z` with three numbers, got {:?}",
                        line.trim()
                    ));
                }
                if coords.iter().flatten().any(|c| !c.is_finite()) {
                    return Err(format!(
                        "line {ln}: vertex {seen_v} has a non-finite coordinate: {:?}",
                        line.trim()
                    ));
                }
                out.push_str(line.trim());
                out.push('\n');
            }
            Some("o") | Some("g") => {
                out.push_str(line.trim());
                out.push('\n');
            }
            Some("f") => {
                let verts: Vec<&str> = words.collect();
                if verts.len() < 3 {
                    return Err(format!(
                        "line {ln}: expected a face with at least 3 vertices, got {:?}",
                        line.trim()
                    ));
                }
                out.push('f');
                for w in verts {
                    let first = w.split('/').next().unwrap_or("");
                    out.push(' ');
                    out.push_str(first);
                    let idx: i64 = first.parse().map_err(|_| {
                        format!("line {ln}: cannot read the face vertex {w:?} (expected an integer index)")
                    })?;
                    if idx == 0 {
                        return Err(format!(
                            "line {ln}: face vertex index 0 (OBJ indices start at 1)"
                        ));
                    }
                    if idx > 0 && idx as u64 > total_v as u64 {
                        return Err(format!(
                            "line {ln}: face vertex index {idx} out of range (the file has {total_v} vertices)"
                        ));
                    }
                    if idx < 0 && idx.unsigned_abs() > seen_v as u64 {
                        return Err(format!(
                            "line {ln}: relative face vertex index {idx} reaches before the first vertex ({seen_v} vertices so far)"
                        ));
                    }
                }
                out.push('\n');
            }
            _ => {}
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_and_fans() {
        let g = parse_obj("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\no a\nf 1 2 3 4\ng b\nf -4 -3 -2\n")
            .unwrap();
        let named: Vec<_> = g.iter().filter(|g| !g.indices.is_empty()).collect();
        assert_eq!(named.len(), 2);
        assert_eq!(named[0].name, "a");
        assert_eq!(named[0].indices.len(), 2);
        assert_eq!(named[1].name, "b");
        assert_eq!(named[1].indices.len(), 1);
    }

    #[test]
    fn errors_carry_lines() {
        let e = parse_obj("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 4\n").unwrap_err();
        assert!(
            e.starts_with("line 4:") && e.contains("out of range"),
            "{e}"
        );
        let e = parse_obj("v 0 0 0\nv 1 nan 0\n").unwrap_err();
        assert!(e.starts_with("line 2:") && e.contains("non-finite"), "{e}");
        let g = parse_obj("v 0 0 0 # origin\nv 1 0 0\nv 1 1 0\nf 1 2 3 # one\n").unwrap();
        assert_eq!(g.iter().map(|g| g.indices.len()).sum::<usize>(), 1);
        let e = parse_obj("v 0 0\n").unwrap_err();
        assert!(e.starts_with("line 1:"), "{e}");
        let e = parse_obj("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 0 1 2\n").unwrap_err();
        assert!(e.contains("index 0"), "{e}");
        let e = parse_obj("v 0 0 0\nv 1 0 0\nf 1 2\n").unwrap_err();
        assert!(e.contains("at least 3"), "{e}");
    }

    #[test]
    fn texture_and_normal_indices_are_ignored() {
        // tobj would overflow on the relative texture index -5 with one `vt`.
        let g = parse_obj(
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvn 0 0 1\nusemtl x\ns 1\nf 1/-5/1 2/-5/1 3//99\nl 1 2\n",
        )
        .unwrap();
        let tris: usize = g.iter().map(|g| g.indices.len()).sum();
        assert_eq!(tris, 1);
    }
}
