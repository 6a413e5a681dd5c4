//! Stanford `.ply` meshes and point sets: ascii, binary little- and big-endian.

use std::fmt::Write as _;
use std::path::Path;

use crate::cloud::{MeshData, MeshStats};
use crate::error::{ErrorKind, Format, IoError, KindResult, take, write_file};
use crate::limits::{Limits, times};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Ty {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Ty {
    fn parse(name: &str) -> Option<Ty> {
        Some(match name {
            "char" | "int8" => Ty::I8,
            "uchar" | "uint8" => Ty::U8,
            "short" | "int16" => Ty::I16,
            "ushort" | "uint16" => Ty::U16,
            "int" | "int32" => Ty::I32,
            "uint" | "uint32" => Ty::U32,
            "float" | "float32" => Ty::F32,
            "double" | "float64" => Ty::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Ty::I8 | Ty::U8 => 1,
            Ty::I16 | Ty::U16 => 2,
            Ty::I32 | Ty::U32 | Ty::F32 => 4,
            Ty::F64 => 8,
        }
    }
}

#[derive(Debug, Clone)]
struct Property {
    name: String,
    /// `Some(count type)` for a list property.
    list: Option<Ty>,
    ty: Ty,
}

#[derive(Debug, Clone)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
    body_start: usize,
}

fn header_error(line: usize, reason: impl Into<String>) -> ErrorKind {
    ErrorKind::Header {
        line,
        reason: reason.into(),
    }
}

fn parse_header(bytes: &[u8]) -> KindResult<Header> {
    let mut pos = 0;
    let mut line_no = 0;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        if pos >= bytes.len() {
            return Err(ErrorKind::BadHeader("no end_header line".to_owned()));
        }
        line_no += 1;
        let end = bytes[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |k| pos + k);
        let line = std::str::from_utf8(&bytes[pos..end])
            .map_err(|_| header_error(line_no, "not UTF-8 text"))?
            .trim();
        pos = (end + 1).min(bytes.len());
        let words: Vec<&str> = line.split_ascii_whitespace().collect();
        if line_no == 1 {
            if line != "ply" {
                return Err(header_error(1, "the file does not start with `ply`"));
            }
            continue;
        }
        match words.as_slice() {
            [] | ["comment", ..] | ["obj_info", ..] => {}
            ["format", kind, _version] => {
                if encoding.is_some() {
                    return Err(header_error(line_no, "a second format line"));
                }
                encoding = Some(match *kind {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::Little,
                    "binary_big_endian" => Encoding::Big,
                    other => {
                        return Err(ErrorKind::Unsupported {
                            what: "PLY format",
                            value: other.to_owned(),
                        });
                    }
                });
            }
            ["element", name, count] => {
                let count = count
                    .parse::<usize>()
                    .map_err(|_| header_error(line_no, format!("element count {count:?}")))?;
                // Which of two `vertex` elements would be the points? Neither: refused.
                if elements.iter().any(|e| e.name == *name) {
                    return Err(header_error(
                        line_no,
                        format!("element {name:?} declared a second time"),
                    ));
                }
                elements.push(Element {
                    name: (*name).to_owned(),
                    count,
                    properties: Vec::new(),
                });
            }
            ["property", rest @ ..] => {
                let element = elements
                    .last_mut()
                    .ok_or_else(|| header_error(line_no, "property before any element"))?;
                let ty = |name: &str| {
                    Ty::parse(name)
                        .ok_or_else(|| header_error(line_no, format!("unknown type {name:?}")))
                };
                let property = match rest {
                    ["list", count_ty, item_ty, name] => Property {
                        name: (*name).to_owned(),
                        list: Some(ty(count_ty)?),
                        ty: ty(item_ty)?,
                    },
                    [item_ty, name] => Property {
                        name: (*name).to_owned(),
                        list: None,
                        ty: ty(item_ty)?,
                    },
                    _ => return Err(header_error(line_no, "property needs a type and a name")),
                };
                element.properties.push(property);
            }
            ["end_header"] => {
                let encoding =
                    encoding.ok_or_else(|| ErrorKind::BadHeader("no format line".to_owned()))?;
                return Ok(Header {
                    encoding,
                    elements,
                    body_start: pos,
                });
            }
            _ => return Err(header_error(line_no, format!("cannot understand {line:?}"))),
        }
    }
}

/// Sequential reader of the body's scalars, whatever the encoding.
struct Body<'a> {
    bytes: &'a [u8],
    pos: usize,
    encoding: Encoding,
}

impl Body<'_> {
    fn next_token(&mut self) -> Option<&str> {
        let b = self.bytes;
        while b.get(self.pos).is_some_and(u8::is_ascii_whitespace) {
            self.pos += 1;
        }
        let start = self.pos;
        while b.get(self.pos).is_some_and(|c| !c.is_ascii_whitespace()) {
            self.pos += 1;
        }
        (self.pos > start)
            .then(|| std::str::from_utf8(&b[start..self.pos]).ok())
            .flatten()
    }

    /// An error about the value at byte `offset`: named by its line in an ascii body, by
    /// its byte offset in a binary one.
    fn error_at(&self, offset: usize, reason: String) -> ErrorKind {
        if self.encoding == Encoding::Ascii {
            let upto = &self.bytes[..offset.min(self.bytes.len())];
            let line = upto.iter().filter(|&&b| b == b'\n').count() + 1;
            ErrorKind::Line { line, reason }
        } else {
            ErrorKind::Value { offset, reason }
        }
    }

    /// Where the next value starts (after the whitespace of an ascii body).
    fn value_start(&self) -> usize {
        let mut pos = self.pos;
        if self.encoding == Encoding::Ascii {
            while self.bytes.get(pos).is_some_and(u8::is_ascii_whitespace) {
                pos += 1;
            }
        }
        pos
    }

    fn scalar(&mut self, ty: Ty, what: &'static str) -> KindResult<f64> {
        if self.encoding == Encoding::Ascii {
            let offset = self.value_start();
            return match self.next_token() {
                Some(t) => match t.parse::<f64>() {
                    Ok(v) => Ok(v),
                    Err(_) => {
                        let reason = format!("{what} {t:?} is not a number");
                        Err(self.error_at(offset, reason))
                    }
                },
                None => Err(ErrorKind::Truncated {
                    what,
                    offset,
                    needed: 1,
                    available: 0,
                }),
            };
        }
        let raw = take(self.bytes, self.pos, ty.size(), what)?;
        self.pos += ty.size();
        let big = self.encoding == Encoding::Big;
        macro_rules! num {
            ($t:ty, $n:literal) => {{
                let mut a = [0u8; $n];
                a.copy_from_slice(raw);
                if big {
                    <$t>::from_be_bytes(a) as f64
                } else {
                    <$t>::from_le_bytes(a) as f64
                }
            }};
        }
        Ok(match ty {
            Ty::I8 => num!(i8, 1),
            Ty::U8 => num!(u8, 1),
            Ty::I16 => num!(i16, 2),
            Ty::U16 => num!(u16, 2),
            Ty::I32 => num!(i32, 4),
            Ty::U32 => num!(u32, 4),
            Ty::F32 => num!(f32, 4),
            Ty::F64 => num!(f64, 8),
        })
    }

    fn list_len(&mut self, ty: Ty) -> KindResult<usize> {
        let offset = self.value_start();
        let n = self.scalar(ty, "list length")?;
        if n.fract() != 0.0 || !(0.0..=f64::from(u32::MAX)).contains(&n) {
            return Err(self.error_at(offset, format!("list length {n} is not a count")));
        }
        Ok(n as usize)
    }

    /// A face's vertex index: a whole number (its range is checked once all vertices are
    /// known).
    fn index(&mut self, ty: Ty, face: usize) -> KindResult<f64> {
        let offset = self.value_start();
        let v = self.scalar(ty, "face vertex index")?;
        if v.fract() != 0.0 || !v.is_finite() {
            return Err(self.error_at(
                offset,
                format!("face {face}: vertex index {v} is not a whole number"),
            ));
        }
        Ok(v)
    }
}

/// Reads a PLY file: vertices (`x`, `y`, `z` of any numeric type) and faces
/// (`vertex_indices` or `vertex_index` lists of any count and index type, polygons
/// fan-triangulated). A file without faces gives an empty `triangles`.
///
/// # Errors
/// An [`IoError`] naming the file and the problem: malformed header line, missing `x`/`y`/
/// `z`, truncated body, a face index out of range (naming the face).
pub fn read_ply(path: impl AsRef<Path>) -> Result<MeshData, IoError> {
    read_ply_with_stats(path).map(|(mesh, _)| mesh)
}

/// As [`read_ply`], also reporting faces fanned or skipped.
///
/// # Errors
/// As [`read_ply`].
pub fn read_ply_with_stats(path: impl AsRef<Path>) -> Result<(MeshData, MeshStats), IoError> {
    let path = path.as_ref();
    read_ply_with(path, &Limits::for_path(path))
}

/// As [`read_ply_with_stats`], within `limits` (counted from the header's element counts
/// before anything is read: each vertex 24 bytes and the pipeline's share, each face its
/// indices, its triangle and half that share).
///
/// # Errors
/// As [`read_ply`]; [`ErrorKind::OverBudget`] past `limits`.
pub fn read_ply_with(
    path: impl AsRef<Path>,
    limits: &Limits,
) -> Result<(MeshData, MeshStats), IoError> {
    let path = path.as_ref();
    parse_ply_with(&limits.read_file(path, Format::Ply)?, limits).map_err(|e| e.at(path))
}

/// Parses PLY bytes; see [`read_ply`].
///
/// # Errors
/// As [`read_ply`], with no file name.
pub fn parse_ply(bytes: &[u8]) -> Result<MeshData, IoError> {
    parse_ply_with_stats(bytes).map(|(mesh, _)| mesh)
}

/// Parses PLY bytes; see [`read_ply_with_stats`].
///
/// # Errors
/// As [`read_ply`], with no file name.
pub fn parse_ply_with_stats(bytes: &[u8]) -> Result<(MeshData, MeshStats), IoError> {
    parse_ply_with(bytes, &Limits::for_input_size(bytes.len() as u64))
}

/// As [`parse_ply_with_stats`], within `limits`.
///
/// # Errors
/// As [`read_ply_with`], with no file name.
pub fn parse_ply_with(bytes: &[u8], limits: &Limits) -> Result<(MeshData, MeshStats), IoError> {
    parse(bytes, limits).map_err(|k| IoError::new(Format::Ply, k))
}

/// Fewest bytes one record of `element` takes in the body: its scalars (binary) or a digit
/// and a separator per scalar (ascii); lists count their length alone.
fn min_record_bytes(element: &Element, encoding: Encoding) -> usize {
    element
        .properties
        .iter()
        .map(|p| match encoding {
            Encoding::Ascii => 2,
            _ => p.list.unwrap_or(p.ty).size(),
        })
        .sum()
}

/// Checks that the body can hold the records the header declares, then that they fit the
/// budget, before anything is allocated.
fn check_counts(header: &Header, bytes: &[u8], limits: &Limits) -> KindResult<()> {
    let room = bytes.len() - header.body_start;
    let mut needed = 0usize;
    for element in &header.elements {
        let per = min_record_bytes(element, header.encoding);
        needed = needed.saturating_add(element.count.saturating_mul(per));
        if needed > room + 1 {
            return Err(ErrorKind::Truncated {
                what: "the records the header declares",
                offset: header.body_start,
                needed,
                available: room,
            });
        }
    }
    let count = |name: &str| {
        header
            .elements
            .iter()
            .filter(|e| e.name == name)
            .map(|e| e.count)
            .sum::<usize>()
    };
    let (vertices, faces) = (count("vertex"), count("face"));
    // Per face: three f64 indices, where it starts, its triangle.
    let estimate = (bytes.len() as u64)
        .saturating_add(times(vertices, 24))
        .saturating_add(limits.pipeline(vertices as u64))
        .saturating_add(times(faces, 44))
        .saturating_add(limits.pipeline(faces as u64) / 2);
    limits.check(estimate, || {
        format!(
            "{vertices} vertices and {faces} faces, with {} bytes per vertex in the pipeline",
            limits.pipeline_bytes_per_point
        )
    })
}

fn parse(bytes: &[u8], limits: &Limits) -> KindResult<(MeshData, MeshStats)> {
    let header = parse_header(bytes)?;
    check_counts(&header, bytes, limits)?;
    let mut body = Body {
        bytes,
        pos: header.body_start,
        encoding: header.encoding,
    };
    let room = bytes.len() - header.body_start;
    let mut vertices: Vec<[f64; 3]> = Vec::new();
    // Flat vertex indices of all faces and where each face starts.
    let mut corners: Vec<f64> = Vec::new();
    let mut face_starts: Vec<usize> = Vec::new();
    if !header.elements.iter().any(|e| e.name == "vertex") {
        return Err(ErrorKind::MissingField("element vertex".to_owned()));
    }
    for element in &header.elements {
        if element.count == 0 {
            continue;
        }
        match element.name.as_str() {
            "vertex" => read_vertices(&mut body, element, room, &mut vertices)?,
            "face" => read_faces(&mut body, element, room, &mut corners, &mut face_starts)?,
            // Records without properties occupy no bytes.
            _ if element.properties.is_empty() => {}
            _ => skip_element(&mut body, element)?,
        }
    }
    fan(vertices, &corners, &face_starts)
}

/// The colour of every vertex of a PLY file from its `red`, `green` and `blue` properties
/// (`diffuse_` prefixed or `r g b` also taken; integer types scaled from their range,
/// floats from 0–1), or `None` when it has none.
///
/// # Errors
/// As [`read_ply`].
pub fn read_ply_colors(path: impl AsRef<Path>) -> Result<Option<Vec<[u8; 3]>>, IoError> {
    let path = path.as_ref();
    let limits = Limits::for_path(path);
    vertex_colors(
        &limits.read_file(path, Format::Ply)?,
        &limits.reading_only(),
    )
    .map_err(|k| IoError::new(Format::Ply, k).at(path))
}

/// Parses the vertex colours of PLY bytes; see [`read_ply_colors`].
///
/// # Errors
/// As [`parse_ply`].
pub fn parse_ply_colors(bytes: &[u8]) -> Result<Option<Vec<[u8; 3]>>, IoError> {
    vertex_colors(
        bytes,
        &Limits::for_input_size(bytes.len() as u64).reading_only(),
    )
    .map_err(|k| IoError::new(Format::Ply, k))
}

fn vertex_colors(bytes: &[u8], limits: &Limits) -> KindResult<Option<Vec<[u8; 3]>>> {
    let header = parse_header(bytes)?;
    check_counts(&header, bytes, limits)?;
    let mut body = Body {
        bytes,
        pos: header.body_start,
        encoding: header.encoding,
    };
    let room = bytes.len() - header.body_start;
    for element in &header.elements {
        if element.name != "vertex" {
            if !element.properties.is_empty() && element.count > 0 {
                skip_element(&mut body, element)?;
            }
            continue;
        }
        let find = |names: [&str; 3]| {
            names.iter().find_map(|n| {
                element
                    .properties
                    .iter()
                    .position(|p| p.name == *n && p.list.is_none())
            })
        };
        let slots = [
            find(["red", "diffuse_red", "r"]),
            find(["green", "diffuse_green", "g"]),
            find(["blue", "diffuse_blue", "b"]),
        ];
        let [Some(r), Some(g), Some(b)] = slots else {
            return Ok(None);
        };
        let slots = [r, g, b];
        let mut colors = Vec::with_capacity(element.count.min(room));
        for _ in 0..element.count {
            let mut c = [0u8; 3];
            for (k, p) in element.properties.iter().enumerate() {
                let value = read_property(&mut body, p)?;
                if let Some(channel) = slots.iter().position(|&s| s == k) {
                    c[channel] = channel_byte(value, p.ty);
                }
            }
            colors.push(c);
        }
        return Ok(Some(colors));
    }
    Ok(None)
}

/// A colour channel value of type `ty` as a byte.
fn channel_byte(value: f64, ty: Ty) -> u8 {
    let scaled = match ty {
        Ty::F32 | Ty::F64 => value * 255.0,
        Ty::U16 | Ty::I16 => value / 257.0,
        Ty::U32 | Ty::I32 => value / 16_843_009.0,
        Ty::U8 | Ty::I8 => value,
    };
    scaled.round().clamp(0.0, 255.0) as u8
}

fn read_vertices(
    body: &mut Body<'_>,
    element: &Element,
    room: usize,
    vertices: &mut Vec<[f64; 3]>,
) -> KindResult<()> {
    let mut slots = [usize::MAX; 3];
    for (slot, name) in slots.iter_mut().zip(["x", "y", "z"]) {
        *slot = element
            .properties
            .iter()
            .position(|p| p.name == name && p.list.is_none())
            .ok_or_else(|| ErrorKind::MissingField(format!("vertex property {name}")))?;
    }
    vertices.reserve(element.count.min(room));
    for _ in 0..element.count {
        let mut v = [0.0; 3];
        for (k, p) in element.properties.iter().enumerate() {
            let value = read_property(body, p)?;
            if let Some(axis) = slots.iter().position(|&s| s == k) {
                v[axis] = value;
            }
        }
        vertices.push(v);
    }
    Ok(())
}

/// Reads one property, returning its value (0 for lists, whose items are skipped).
fn read_property(body: &mut Body<'_>, p: &Property) -> KindResult<f64> {
    match p.list {
        None => body.scalar(p.ty, "vertex property"),
        Some(count_ty) => {
            let n = body.list_len(count_ty)?;
            for _ in 0..n {
                body.scalar(p.ty, "list item")?;
            }
            Ok(0.0)
        }
    }
}

fn read_faces(
    body: &mut Body<'_>,
    element: &Element,
    room: usize,
    corners: &mut Vec<f64>,
    face_starts: &mut Vec<usize>,
) -> KindResult<()> {
    let index_prop = element
        .properties
        .iter()
        .position(|p| p.list.is_some() && (p.name == "vertex_indices" || p.name == "vertex_index"))
        .ok_or_else(|| ErrorKind::MissingField("face list vertex_indices".to_owned()))?;
    face_starts.reserve(element.count.min(room));
    for face in 0..element.count {
        for (k, p) in element.properties.iter().enumerate() {
            match p.list {
                Some(count_ty) if k == index_prop => {
                    let n = body.list_len(count_ty)?;
                    face_starts.push(corners.len());
                    for _ in 0..n {
                        corners.push(body.index(p.ty, face)?);
                    }
                }
                _ => {
                    read_property(body, p)?;
                }
            }
        }
    }
    Ok(())
}

fn skip_element(body: &mut Body<'_>, element: &Element) -> KindResult<()> {
    for _ in 0..element.count {
        for p in &element.properties {
            read_property(body, p)?;
        }
    }
    Ok(())
}

fn fan(
    vertices: Vec<[f64; 3]>,
    corners: &[f64],
    face_starts: &[usize],
) -> KindResult<(MeshData, MeshStats)> {
    let nv = vertices.len();
    if u32::try_from(nv).is_err() {
        return Err(ErrorKind::Unusable(format!(
            "{nv} vertices exceed u32 indices"
        )));
    }
    let mut stats = MeshStats {
        faces: face_starts.len(),
        ..MeshStats::default()
    };
    let mut triangles = Vec::with_capacity(face_starts.len());
    for (face, &start) in face_starts.iter().enumerate() {
        let end = face_starts.get(face + 1).copied().unwrap_or(corners.len());
        let ids = &corners[start..end];
        let mut checked = Vec::with_capacity(ids.len());
        for &raw in ids {
            if raw.fract() != 0.0 || raw < 0.0 || raw >= nv as f64 {
                return Err(ErrorKind::FaceIndex {
                    face,
                    index: raw as i64,
                    vertices: nv,
                });
            }
            checked.push(raw as u32);
        }
        match checked.len() {
            0..=2 => stats.faces_skipped += 1,
            3 => triangles.push([checked[0], checked[1], checked[2]]),
            _ => {
                stats.polygons_fanned += 1;
                for w in checked[1..].windows(2) {
                    triangles.push([checked[0], w[0], w[1]]);
                }
            }
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

/// Writes `mesh` as binary little-endian PLY (`double` coordinates, `uchar`/`uint` face
/// lists).
///
/// # Errors
/// A triangle index out of range, or a file system error.
pub fn write_ply(path: impl AsRef<Path>, mesh: &MeshData) -> Result<(), IoError> {
    let path = path.as_ref();
    let bytes = encode_ply(mesh).map_err(|e| e.at(path))?;
    write_file(path, Format::Ply, &bytes)
}

/// Encodes `mesh` as binary little-endian PLY bytes; see [`write_ply`].
///
/// # Errors
/// A triangle index out of range.
pub fn encode_ply(mesh: &MeshData) -> Result<Vec<u8>, IoError> {
    let nv = mesh.vertices.len();
    for (face, t) in mesh.triangles.iter().enumerate() {
        if let Some(&bad) = t.iter().find(|&&i| i as usize >= nv) {
            return Err(IoError::new(
                Format::Ply,
                ErrorKind::FaceIndex {
                    face,
                    index: i64::from(bad),
                    vertices: nv,
                },
            ));
        }
    }
    let mut header = String::from("ply\nformat binary_little_endian 1.0\ncomment polylidar-rs\n");
    let _ = write!(
        header,
        "element vertex {nv}\nproperty double x\nproperty double y\nproperty double z\n\
         element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        mesh.triangles.len()
    );
    let mut out = header.into_bytes();
    out.reserve(nv * 24 + mesh.triangles.len() * 13);
    for v in &mesh.vertices {
        for c in v {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    for t in &mesh.triangles {
        out.push(3);
        for i in t {
            out.extend_from_slice(&i.to_le_bytes());
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII: &[u8] = b"ply\nformat ascii 1.0\ncomment quad and triangle\n\
element vertex 5\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n\
element face 2\nproperty list uchar int vertex_index\nproperty uchar flags\nend_header\n\
0 0 0 1\n1 0 0 2\n1 1 0 3\n0 1 0 4\n2 2 2 5\n4 0 1 2 3 7\n3 1 4 2 0\n";

    #[test]
    fn ascii_quad_is_fanned() {
        let (m, s) = parse_ply_with_stats(ASCII).unwrap();
        assert_eq!(m.vertices.len(), 5);
        assert_eq!(m.vertices[4], [2.0, 2.0, 2.0]);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [1, 4, 2]]);
        assert_eq!(s.polygons_fanned, 1);
        assert_eq!(s.faces, 2);
    }

    #[test]
    fn big_endian_binary_with_short_indices() {
        let mut b = b"ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty short x\n\
property double y\nproperty int z\nelement face 1\nproperty list uint ushort vertex_indices\nend_header\n"
            .to_vec();
        for (x, y, z) in [(1i16, 2.5f64, 3i32), (-4, 5.0, 6), (7, 8.0, -9)] {
            b.extend_from_slice(&x.to_be_bytes());
            b.extend_from_slice(&y.to_be_bytes());
            b.extend_from_slice(&z.to_be_bytes());
        }
        b.extend_from_slice(&3u32.to_be_bytes());
        for i in [2u16, 1, 0] {
            b.extend_from_slice(&i.to_be_bytes());
        }
        let m = parse_ply(&b).unwrap();
        assert_eq!(
            m.vertices,
            vec![[1.0, 2.5, 3.0], [-4.0, 5.0, 6.0], [7.0, 8.0, -9.0]]
        );
        assert_eq!(m.triangles, vec![[2, 1, 0]]);
        assert!(parse_ply(&b[..b.len() - 1]).is_err());
    }

    #[test]
    fn round_trip_and_errors() {
        let mesh = MeshData {
            vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.5], [0.0, 1.0, -0.5]],
            triangles: vec![[0, 1, 2]],
        };
        assert_eq!(parse_ply(&encode_ply(&mesh).unwrap()).unwrap(), mesh);
        let bad = MeshData {
            triangles: vec![[0, 1, 3]],
            ..mesh
        };
        assert!(encode_ply(&bad).is_err());
        let text = String::from_utf8_lossy(ASCII).replace("3 1 4 2", "3 1 9 2");
        let e = parse_ply(text.as_bytes()).unwrap_err();
        assert!(
            matches!(
                e.kind,
                ErrorKind::FaceIndex {
                    face: 1,
                    index: 9,
                    ..
                }
            ),
            "{e}"
        );
        let text = String::from_utf8_lossy(ASCII).replace("property float y\n", "");
        assert!(parse_ply(text.as_bytes()).is_err());
        assert!(parse_ply(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n").is_err());
    }

    #[test]
    fn ascii_errors_name_the_line_and_indices_must_be_whole() {
        let text = String::from_utf8_lossy(ASCII).replace("1 1 0 3", "1 x 0 3");
        let e = parse_ply(text.as_bytes()).unwrap_err();
        assert!(matches!(e.kind, ErrorKind::Line { line: 15, .. }), "{e}");
        assert!(!e.to_string().contains("compressed"), "{e}");
        let text = String::from_utf8_lossy(ASCII).replace("3 1 4 2", "3 1.5 4 2");
        let e = parse_ply(text.as_bytes()).unwrap_err();
        assert!(
            e.to_string()
                .contains("vertex index 1.5 is not a whole number"),
            "{e}"
        );
        assert!(matches!(e.kind, ErrorKind::Line { line: 19, .. }), "{e}");
    }

    #[test]
    fn claimed_counts_are_checked_before_reading() {
        let e = parse_ply(b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n").unwrap_err();
        assert!(matches!(e.kind, ErrorKind::Truncated { .. }), "{e}");
    }

    /// Found by the `ply` fuzz target: a header with two `vertex` elements (and two format
    /// lines) was read as three points by the mesh reader and six colours by the colour
    /// reader.
    #[test]
    fn repeated_elements_and_format_lines_are_refused() {
        let text = String::from_utf8_lossy(ASCII).replace(
            "element face 2\n",
            "element vertex 1\nproperty float x\nelement face 2\n",
        );
        let e = parse_ply(text.as_bytes()).unwrap_err();
        assert!(
            e.to_string().contains("\"vertex\" declared a second time"),
            "{e}"
        );
        assert!(parse_ply_colors(text.as_bytes()).is_err());
        let text = String::from_utf8_lossy(ASCII).replace(
            "comment quad and triangle\n",
            "format binary_big_endian 1.0\n",
        );
        let e = parse_ply(text.as_bytes()).unwrap_err();
        assert!(e.to_string().contains("a second format line"), "{e}");
        let crash =
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n\
element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n\
0 0 0 1 2 3\n4 5 6\n";
        assert!(parse_ply(crash).is_err());
        assert!(parse_ply_colors(crash).is_err());
    }

    #[test]
    fn vertices_only() {
        let m = parse_ply(b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n4 5 6\n").unwrap();
        assert_eq!(m.vertices.len(), 2);
        assert!(m.triangles.is_empty());
    }
}
