//! Writing a [`MergedMesh`] for mesh viewers: Wavefront OBJ + MTL with PNG textures, and
//! binary PLY with vertex colours and texture coordinates. Everything is encoded in memory;
//! the caller writes the files.

use std::fmt::Write as _;

use crate::PlanarMeshError;
use crate::merge::{MergedMesh, Packing};
use crate::texture::Texture;

/// The OBJ text of `mesh`: one object per plane with its normal, texture coordinates when
/// the mesh has them, and `usemtl` lines naming the materials of [`mtl_text`]
/// (`atlas` for one atlas, `plane_<k>` per plane, `untextured` without textures).
///
/// ```
/// use planar_mesh::{export, merge, SimplifyOptions, Packing, Segment, simplify};
///
/// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
/// let plane = simplify(&Segment::new(&points, &points, &[]), &SimplifyOptions::new())?;
/// let obj = export::obj_text(&merge(&[(0, &plane)], Packing::Atlas), Some("out.mtl"));
/// assert!(obj.starts_with("# planar-mesh"));
/// assert_eq!(obj.lines().filter(|l| l.starts_with("f ")).count(), plane.triangles.len());
/// # Ok::<(), planar_mesh::PlanarMeshError>(())
/// ```
pub fn obj_text(mesh: &MergedMesh, mtl_file: Option<&str>) -> String {
    let mut s = String::with_capacity(64 * mesh.vertices.len() + 48 * mesh.triangles.len());
    let _ = writeln!(
        s,
        "# planar-mesh: {} planes, {} vertices, {} triangles",
        mesh.planes.len(),
        mesh.vertices.len(),
        mesh.triangles.len()
    );
    if let Some(mtl) = mtl_file {
        let _ = writeln!(s, "mtllib {mtl}");
    }
    for v in &mesh.vertices {
        let _ = writeln!(s, "v {} {} {}", v[0], v[1], v[2]);
    }
    let textured = !mesh.uv.is_empty();
    for uv in &mesh.uv {
        let _ = writeln!(s, "vt {} {}", uv[0], uv[1]);
    }
    for n in &mesh.normals {
        let _ = writeln!(s, "vn {} {} {}", n[0], n[1], n[2]);
    }
    for (k, range) in mesh.planes.iter().enumerate() {
        let _ = writeln!(s, "o plane_{}", range.plane);
        if mtl_file.is_some() {
            let _ = writeln!(s, "usemtl {}", material_name(mesh, range.plane));
        }
        let first = range.first_triangle as usize;
        for t in &mesh.triangles[first..first + range.triangles as usize] {
            let [a, b, c] = t.map(|v| v + 1);
            let n = k + 1;
            if textured {
                let _ = writeln!(s, "f {a}/{a}/{n} {b}/{b}/{n} {c}/{c}/{n}");
            } else {
                let _ = writeln!(s, "f {a}//{n} {b}//{n} {c}//{n}");
            }
        }
    }
    s
}

/// The material of plane `plane` in the OBJ and MTL text.
pub fn material_name(mesh: &MergedMesh, plane: usize) -> String {
    match (mesh.uv.is_empty(), mesh.packing) {
        (true, _) => "untextured".to_owned(),
        (false, Packing::Atlas) => "atlas".to_owned(),
        (false, Packing::PerPlane) => format!("plane_{plane}"),
    }
}

/// The MTL text for [`obj_text`]: `texture_file(plane)` names each plane's picture
/// ([`Packing::PerPlane`]), `texture_file(0)` the atlas.
pub fn mtl_text(mesh: &MergedMesh, texture_file: impl Fn(usize) -> String) -> String {
    let mut s = String::from("# planar-mesh materials\n");
    let mut material = |name: &str, map: Option<String>| {
        let _ = writeln!(
            s,
            "newmtl {name}\nKa 1 1 1\nKd 1 1 1\nKs 0 0 0\nd 1\nillum 1"
        );
        if let Some(map) = map {
            let _ = writeln!(s, "map_Kd {map}");
        }
        s.push('\n');
    };
    match (mesh.uv.is_empty(), mesh.packing) {
        (true, _) => material("untextured", None),
        (false, Packing::Atlas) => material("atlas", Some(texture_file(0))),
        (false, Packing::PerPlane) => {
            for range in &mesh.planes {
                material(
                    &format!("plane_{}", range.plane),
                    Some(texture_file(range.plane)),
                );
            }
        }
    }
    s
}

/// Binary little-endian PLY of `mesh`: float `x y z`, `red green blue` (the texture's
/// colour at each vertex, grey without texture), float `texture_u texture_v` with a
/// `TextureFile` comment when there is one texture file, and the triangles.
pub fn ply_bytes(mesh: &MergedMesh, texture_file: Option<&str>, colors: &[[u8; 3]]) -> Vec<u8> {
    let uv = !mesh.uv.is_empty();
    let mut header = String::from("ply\nformat binary_little_endian 1.0\ncomment planar-mesh\n");
    if let (true, Some(file)) = (uv, texture_file) {
        let _ = writeln!(header, "comment TextureFile {file}");
    }
    let _ = writeln!(
        header,
        "element vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue",
        mesh.vertices.len()
    );
    if uv {
        header.push_str("property float texture_u\nproperty float texture_v\n");
    }
    let _ = writeln!(
        header,
        "element face {}\nproperty list uchar int vertex_indices\nend_header",
        mesh.triangles.len()
    );
    let mut out = header.into_bytes();
    for (k, v) in mesh.vertices.iter().enumerate() {
        for c in v {
            out.extend_from_slice(&(*c as f32).to_le_bytes());
        }
        out.extend_from_slice(colors.get(k).unwrap_or(&[200, 200, 200]));
        if let Some(t) = mesh.uv.get(k) {
            out.extend_from_slice(&(t[0] as f32).to_le_bytes());
            out.extend_from_slice(&(t[1] as f32).to_le_bytes());
        }
    }
    for t in &mesh.triangles {
        out.push(3);
        for v in t {
            out.extend_from_slice(&(*v as i32).to_le_bytes());
        }
    }
    out
}

/// The colour of every vertex of `mesh` read from its textures (atlas or per plane;
/// nearest texel); empty without textures.
pub fn vertex_colors(mesh: &MergedMesh, textures: &[Option<&Texture>]) -> Vec<[u8; 3]> {
    if mesh.uv.is_empty() {
        return Vec::new();
    }
    let mut colors = vec![[200u8; 3]; mesh.vertices.len()];
    for range in &mesh.planes {
        let first = range.first_vertex as usize;
        let plane_uv = &mesh.uv[first..first + range.vertices as usize];
        for (color, &uv) in colors[first..].iter_mut().zip(plane_uv) {
            *color = match (&mesh.atlas, textures.get(range.plane).copied().flatten()) {
                (Some(atlas), _) => {
                    let col = (uv[0] * f64::from(atlas.width)).floor();
                    let row = ((1.0 - uv[1]) * f64::from(atlas.height)).floor();
                    let clamp =
                        |x: f64, n: u32| x.clamp(0.0, f64::from(n.saturating_sub(1))) as usize;
                    let i = 3
                        * (clamp(row, atlas.height) * atlas.width as usize
                            + clamp(col, atlas.width));
                    [atlas.rgb[i], atlas.rgb[i + 1], atlas.rgb[i + 2]]
                }
                (None, Some(t)) => t.sample(uv),
                (None, None) => [200; 3],
            };
        }
    }
    colors
}

/// PNG bytes of an RGB picture, row-major, top row first.
///
/// # Errors
/// [`PlanarMeshError::Png`] when `rgb` is not `3 × width × height` bytes or encoding fails.
pub fn png_bytes(width: u32, height: u32, rgb: &[u8]) -> Result<Vec<u8>, PlanarMeshError> {
    if rgb.len() != 3 * width as usize * height as usize {
        return Err(PlanarMeshError::Png(format!(
            "{} bytes for a {width} × {height} RGB picture",
            rgb.len()
        )));
    }
    let mut out = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut out, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder
            .write_header()
            .map_err(|e| PlanarMeshError::Png(e.to_string()))?;
        writer
            .write_image_data(rgb)
            .map_err(|e| PlanarMeshError::Png(e.to_string()))?;
    }
    Ok(out)
}
