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
    /// The texture coordinates of each triangle's corners as the file gives them (`vt`
    /// u v, or a PLY's u, v), or empty when not every face has them.
    pub uvs: Vec<[glam::Vec2; 3]>,
}

/// Parses OBJ text. The error is one line, without the file name.
pub(crate) fn parse_obj(text: &str) -> Result<Vec<ObjGroup>, String> {
    let (text, every_face_textured) = prescan(text)?;
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
        let texcoords: Vec<glam::Vec2> = m
            .mesh
            .texcoords
            .chunks_exact(2)
            .map(|c| glam::Vec2::new(c[0], c[1]))
            .collect();
        let ti = &m.mesh.texcoord_indices;
        let uvs: Vec<[glam::Vec2; 3]> = if every_face_textured
            && !ti.is_empty()
            && ti.len() == m.mesh.indices.len()
            && ti.iter().all(|&i| (i as usize) < texcoords.len())
        {
            ti.chunks_exact(3)
                .map(|t| [0, 1, 2].map(|k| texcoords[t[k] as usize]))
                .collect()
        } else {
            Vec::new()
        };
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
            uvs,
        });
    }
    Ok(groups)
}

/// Checks `v` and `f` lines so that the common errors carry a line number, and returns
/// the text `tobj` reads: `v`, `o`, `g` lines as they are, `f` lines with position
/// indices only, nothing else.
/// Also whether every face has texture coordinates (else the file has none for heron:
/// `tobj` would pair the others with made-up indices).
fn prescan(text: &str) -> Result<(String, bool), String> {
    let mut out = String::with_capacity(text.len());
    let total_v = text
        .lines()
        .filter(|l| l.split_whitespace().next() == Some("v"))
        .count();
    let mut seen_v = 0usize;
    let total_vt = text
        .lines()
        .filter(|l| l.split_whitespace().next() == Some("vt"))
        .count();
    let mut seen_vt = 0usize;
    let mut every_face_textured = true;
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
            Some("vt") => {
                seen_vt += 1;
                let uv: Vec<Option<f32>> = words.take(2).map(|w| w.parse::<f32>().ok()).collect();
                match uv.as_slice() {
                    [Some(u), Some(v)] if u.is_finite() && v.is_finite() => {
                        out.push_str(&format!("vt {u} {v}\n"));
                    }
                    _ => {
                        return Err(format!(
                            "line {ln}: expected `vt u v` with finite numbers, got {:?}",
                            line.trim()
                        ))
                    }
                }
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
                // Texture coordinates are kept when every vertex of the face has one.
                let tex: Vec<Option<&str>> = verts
                    .iter()
                    .map(|w| w.split('/').nth(1).filter(|t| !t.is_empty()))
                    .collect();
                let keep_tex = tex.iter().all(Option::is_some);
                every_face_textured &= keep_tex;
                for (w, t) in verts.iter().zip(&tex) {
                    let first = w.split('/').next().unwrap_or("");
                    out.push(' ');
                    out.push_str(first);
                    if let (true, Some(t)) = (keep_tex, t) {
                        let ti: i64 = t.parse().map_err(|_| {
                            format!("line {ln}: cannot read the texture index of {w:?} (expected an integer)")
                        })?;
                        let ok = (ti > 0 && ti as u64 <= total_vt as u64)
                            || (ti < 0 && ti.unsigned_abs() <= seen_vt as u64);
                        if !ok {
                            return Err(format!(
                                "line {ln}: texture coordinate index {ti} out of range ({total_vt} vt lines in the file, {seen_vt} so far)"
                            ));
                        }
                        out.push('/');
                        out.push_str(t);
                    }
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
    Ok((out, every_face_textured))
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
