//! Wavefront `.obj` meshes (geometry only: `v` and `f` lines).

use std::path::Path;

use crate::cloud::{MeshData, MeshStats};
use crate::error::{ErrorKind, Format, IoError, KindResult};
use crate::limits::{Limits, times};

/// Reads the vertices (`v x y z`) and faces (`f a b c …` with `a`, `a/t`, `a//n` or
/// `a/t/n` corners, 1-based or negative indices) of an OBJ file; polygons are
/// fan-triangulated; every other statement (normals, texture coordinates, groups,
/// materials, lines) is ignored.
///
/// # Errors
/// An [`IoError`] naming the line of a malformed `v` or `f` statement, or the face whose
/// index is out of range.
pub fn read_obj(path: impl AsRef<Path>) -> Result<MeshData, IoError> {
    read_obj_with_stats(path).map(|(mesh, _)| mesh)
}

/// As [`read_obj`], also reporting faces fanned or skipped.
///
/// # Errors
/// As [`read_obj`].
pub fn read_obj_with_stats(path: impl AsRef<Path>) -> Result<(MeshData, MeshStats), IoError> {
    let path = path.as_ref();
    read_obj_with(path, &Limits::for_path(path))
}

/// As [`read_obj_with_stats`], within `limits` (counted from the `v` and `f` statements
/// before any is stored: each vertex 24 bytes and the pipeline's share, each triangle of a
/// face 12 bytes and half that share).
///
/// # Errors
/// As [`read_obj`]; [`ErrorKind::OverBudget`] past `limits`.
pub fn read_obj_with(
    path: impl AsRef<Path>,
    limits: &Limits,
) -> Result<(MeshData, MeshStats), IoError> {
    let path = path.as_ref();
    parse_obj_with(&limits.read_file(path, Format::Obj)?, limits).map_err(|e| e.at(path))
}

/// Parses OBJ bytes; see [`read_obj`].
///
/// # Errors
/// As [`read_obj`], with no file name.
pub fn parse_obj(bytes: &[u8]) -> Result<MeshData, IoError> {
    parse_obj_with_stats(bytes).map(|(mesh, _)| mesh)
}

/// Parses OBJ bytes; see [`read_obj_with_stats`].
///
/// # Errors
/// As [`read_obj`], with no file name.
pub fn parse_obj_with_stats(bytes: &[u8]) -> Result<(MeshData, MeshStats), IoError> {
    parse_obj_with(bytes, &Limits::for_input_size(bytes.len() as u64))
}

/// As [`parse_obj_with_stats`], within `limits`.
///
/// # Errors
/// As [`read_obj_with`], with no file name.
pub fn parse_obj_with(bytes: &[u8], limits: &Limits) -> Result<(MeshData, MeshStats), IoError> {
    check_budget(bytes, limits)
        .and_then(|()| parse(bytes))
        .map_err(|k| IoError::new(Format::Obj, k))
}

/// Counts the `v` and `f` statements and face corners, and checks what they will cost.
fn check_budget(bytes: &[u8], limits: &Limits) -> KindResult<()> {
    let (mut vertices, mut faces, mut corners) = (0usize, 0usize, 0usize);
    for raw in bytes.split(|&b| b == b'\n') {
        let mut words = raw.split(u8::is_ascii_whitespace).filter(|w| !w.is_empty());
        match words.next() {
            Some(b"v") => vertices += 1,
            Some(b"f") => {
                faces += 1;
                corners += words.count();
            }
            _ => {}
        }
    }
    let triangles = corners.saturating_sub(2 * faces);
    // A pending face keeps its corners (16 bytes each) until the vertices are known.
    let estimate = (bytes.len() as u64)
        .saturating_add(times(vertices, 24))
        .saturating_add(limits.pipeline(vertices as u64))
        .saturating_add(times(faces, 40))
        .saturating_add(times(corners, 16))
        .saturating_add(times(triangles, 12))
        .saturating_add(limits.pipeline(triangles as u64) / 2);
    limits.check(estimate, || {
        format!(
            "{vertices} vertices and {faces} faces ({triangles} triangles), with {} bytes per \
             vertex in the pipeline",
            limits.pipeline_bytes_per_point
        )
    })
}

/// A face corner: the index as written and its 0-based resolution.
#[derive(Clone, Copy)]
struct Corner {
    written: i64,
    resolved: i64,
}

fn parse(bytes: &[u8]) -> KindResult<(MeshData, MeshStats)> {
    let mut vertices: Vec<[f64; 3]> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut stats = MeshStats::default();
    let mut corners: Vec<Corner> = Vec::new();
    let mut pending: Vec<(usize, Vec<Corner>)> = Vec::new();
    for (k, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let line_no = k + 1;
        let bad = |reason: String| ErrorKind::Line {
            line: line_no,
            reason,
        };
        let Ok(line) = std::str::from_utf8(raw) else {
            // Only `v` and `f` statements matter; they are ASCII.
            if raw.starts_with(b"v ") || raw.starts_with(b"f ") {
                return Err(bad("not UTF-8 text".to_owned()));
            }
            continue;
        };
        let mut words = line.split_ascii_whitespace();
        match words.next() {
            Some("v") => {
                let mut v = [0.0; 3];
                for (axis, slot) in v.iter_mut().enumerate() {
                    let word = words
                        .next()
                        .ok_or_else(|| bad(format!("vertex has {axis} coordinates, needs 3")))?;
                    *slot = word
                        .parse::<f64>()
                        .map_err(|_| bad(format!("coordinate {word:?} is not a number")))?;
                }
                vertices.push(v);
            }
            Some("f") => {
                corners.clear();
                for word in words {
                    let index = word.split('/').next().unwrap_or_default();
                    let written = index
                        .parse::<i64>()
                        .map_err(|_| bad(format!("face corner {word:?} has no vertex index")))?;
                    let resolved = match written {
                        0 => return Err(bad("face index 0 (OBJ indices start at 1)".to_owned())),
                        w if w < 0 => (vertices.len() as i64).saturating_add(w),
                        w => w - 1,
                    };
                    corners.push(Corner { written, resolved });
                }
                let face = stats.faces;
                stats.faces += 1;
                if corners.len() < 3 {
                    stats.faces_skipped += 1;
                    continue;
                }
                if corners.len() > 3 {
                    stats.polygons_fanned += 1;
                }
                // Positive indices may refer to vertices defined later: check at the end.
                pending.push((face, corners.clone()));
            }
            _ => {}
        }
    }
    let nv = vertices.len();
    if u32::try_from(nv).is_err() {
        return Err(ErrorKind::Unusable(format!(
            "{nv} vertices exceed u32 indices"
        )));
    }
    for (face, face_corners) in &pending {
        let mut ids = Vec::with_capacity(face_corners.len());
        for c in face_corners {
            if c.resolved < 0 || c.resolved >= nv as i64 {
                return Err(ErrorKind::FaceIndex {
                    face: *face,
                    index: c.written,
                    vertices: nv,
                });
            }
            ids.push(c.resolved as u32);
        }
        for w in ids[1..].windows(2) {
            triangles.push([ids[0], w[0], w[1]]);
        }
    }
    Ok((
        MeshData {
            vertices,
            triangles,
        },
        stats,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_faces_in_all_forms() {
        let text = b"# cube corner\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0 1.0\nvn 0 0 1\nvt 0 0\n\
                     g top\nf 1/1/1 2/2/1 3/3/1 4/4/1\nf -4//1 -2//1 -1//1\nl 1 2\nf 1 2\n";
        let (m, s) = parse_obj_with_stats(text).unwrap();
        assert_eq!(m.vertices.len(), 4);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 2, 3]]);
        assert_eq!((s.faces, s.polygons_fanned, s.faces_skipped), (3, 1, 1));
    }

    #[test]
    fn errors_name_line_or_face() {
        let e = parse_obj(b"v 0 0 0\nv 1 x 0\n").unwrap_err();
        assert!(matches!(e.kind, ErrorKind::Line { line: 2, .. }), "{e}");
        let e = parse_obj(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n").unwrap_err();
        assert!(
            matches!(
                e.kind,
                ErrorKind::FaceIndex {
                    face: 1,
                    index: 4,
                    ..
                }
            ),
            "{e}"
        );
        let e = parse_obj(b"v 0 0 0\nf -2 1 1\n").unwrap_err();
        assert!(
            matches!(e.kind, ErrorKind::FaceIndex { index: -2, .. }),
            "{e}"
        );
        assert!(parse_obj(b"v 0 0 0\nf 0 1 1\n").is_err());
    }
}
