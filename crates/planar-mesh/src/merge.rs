//! All planes as one mesh, their textures packed into one atlas (or kept per plane).

use crate::simplify::PlaneMesh;
use crate::texture::Texture;

/// Empty texels between two textures of the atlas (so that filtering does not bleed
/// one plane into the next).
pub const ATLAS_GUTTER: u32 = 2;

/// How the textures of merged planes are laid out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Packing {
    /// One atlas picture; uv coordinates point into it.
    #[default]
    Atlas,
    /// One picture per plane; uv coordinates point into the plane's own.
    PerPlane,
}

/// Where one plane's part of a [`MergedMesh`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PlaneRange {
    /// Index of the plane in the input.
    pub plane: usize,
    /// First vertex.
    pub first_vertex: u32,
    /// Vertex count.
    pub vertices: u32,
    /// First triangle.
    pub first_triangle: u32,
    /// Triangle count.
    pub triangles: u32,
    /// Top-left corner of the plane's texture in the atlas ([`Packing::Atlas`] with a
    /// texture).
    pub atlas_offset: Option<[u32; 2]>,
}

/// Textures packed into one picture.
#[derive(Debug, Clone, PartialEq)]
pub struct Atlas {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Row-major RGB bytes, top row first.
    pub rgb: Vec<u8>,
}

/// Several planes' meshes as one: vertices and triangles concatenated, uv coordinates into
/// an atlas (or each plane's own texture), one normal per plane.
#[derive(Debug, Clone, PartialEq)]
pub struct MergedMesh {
    /// Vertices (3D).
    pub vertices: Vec<[f64; 3]>,
    /// Triangles, indices into `vertices`.
    pub triangles: Vec<[u32; 3]>,
    /// Texture coordinates of every vertex, when every plane has a texture (else empty).
    pub uv: Vec<[f64; 2]>,
    /// Each plane's normal.
    pub normals: Vec<[f64; 3]>,
    /// Each plane's vertex and triangle ranges.
    pub planes: Vec<PlaneRange>,
    /// How textures are laid out.
    pub packing: Packing,
    /// The atlas ([`Packing::Atlas`] with textures).
    pub atlas: Option<Atlas>,
}

/// Concatenates `planes` (the `Ok` results of `simplify_all`, each with its input index)
/// into one mesh; with textures on every plane and [`Packing::Atlas`], packs them into one
/// atlas by shelves (tallest first) and maps the uv coordinates into it.
///
/// ```
/// use planar_mesh::{merge, SimplifyOptions, Packing, Segment, simplify};
///
/// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
/// let a = simplify(&Segment::new(&points, &points, &[]), &SimplifyOptions::new())?;
/// let b = a.clone();
/// let merged = merge(&[(0, &a), (1, &b)], Packing::Atlas);
/// assert_eq!(merged.triangles.len(), 2 * a.triangles.len());
/// assert_eq!(merged.planes[1].first_vertex as usize, a.vertices.len());
/// # Ok::<(), planar_mesh::PlanarMeshError>(())
/// ```
pub fn merge(planes: &[(usize, &PlaneMesh)], packing: Packing) -> MergedMesh {
    let textured = !planes.is_empty() && planes.iter().all(|(_, p)| p.texture.is_some());
    let offsets = match (textured, packing) {
        (true, Packing::Atlas) => Some(pack(planes)),
        _ => None,
    };
    let mut out = MergedMesh {
        vertices: Vec::new(),
        triangles: Vec::new(),
        uv: Vec::new(),
        normals: Vec::new(),
        planes: Vec::new(),
        packing,
        atlas: None,
    };
    for (k, (index, plane)) in planes.iter().enumerate() {
        let first = out.vertices.len() as u32;
        let offset = offsets.as_ref().map(|(o, _)| o[k]);
        out.planes.push(PlaneRange {
            plane: *index,
            first_vertex: first,
            vertices: plane.vertices.len() as u32,
            first_triangle: out.triangles.len() as u32,
            triangles: plane.triangles.len() as u32,
            atlas_offset: offset,
        });
        out.vertices.extend_from_slice(&plane.vertices);
        out.triangles
            .extend(plane.triangles.iter().map(|t| t.map(|v| v + first)));
        out.normals.push(plane.frame.normal);
        if textured {
            match (&plane.texture, offset, &offsets) {
                (Some(t), Some(o), Some((_, size))) => out
                    .uv
                    .extend(plane.uv.iter().map(|&uv| atlas_uv(uv, t, o, *size))),
                _ => out.uv.extend_from_slice(&plane.uv),
            }
        }
    }
    if let Some((offsets, [w, h])) = offsets {
        let mut rgb = vec![0u8; 3 * w as usize * h as usize];
        for ((_, plane), o) in planes.iter().zip(&offsets) {
            if let Some(t) = &plane.texture {
                blit(&mut rgb, w, t, *o);
            }
        }
        out.atlas = Some(Atlas {
            width: w,
            height: h,
            rgb,
        });
    }
    out
}

/// Shelf packing: top-left offsets of each texture and the atlas size.
fn pack(planes: &[(usize, &PlaneMesh)]) -> (Vec<[u32; 2]>, [u32; 2]) {
    let sizes: Vec<[u32; 2]> = planes
        .iter()
        .map(|(_, p)| p.texture.as_ref().map_or([0, 0], |t| [t.width, t.height]))
        .collect();
    let area: f64 = sizes
        .iter()
        .map(|s| f64::from(s[0] + ATLAS_GUTTER) * f64::from(s[1] + ATLAS_GUTTER))
        .sum();
    let widest = sizes.iter().map(|s| s[0] + ATLAS_GUTTER).max().unwrap_or(1);
    let width = widest.max((area.sqrt() * 1.15).ceil() as u32);
    let mut order: Vec<usize> = (0..sizes.len()).collect();
    order.sort_by_key(|&k| std::cmp::Reverse(sizes[k][1]));
    let mut offsets = vec![[0u32; 2]; sizes.len()];
    let (mut x, mut y, mut shelf) = (0u32, 0u32, 0u32);
    for k in order {
        let [w, h] = sizes[k];
        if x + w + ATLAS_GUTTER > width && x > 0 {
            y += shelf;
            x = 0;
            shelf = 0;
        }
        offsets[k] = [x, y];
        x += w + ATLAS_GUTTER;
        shelf = shelf.max(h + ATLAS_GUTTER);
    }
    (offsets, [width.max(1), (y + shelf).max(1)])
}

fn atlas_uv(uv: [f64; 2], t: &Texture, o: [u32; 2], size: [u32; 2]) -> [f64; 2] {
    let x = f64::from(o[0]) + uv[0] * f64::from(t.width);
    let row = f64::from(o[1]) + (1.0 - uv[1]) * f64::from(t.height);
    [x / f64::from(size[0]), 1.0 - row / f64::from(size[1])]
}

fn blit(rgb: &mut [u8], width: u32, t: &Texture, o: [u32; 2]) {
    let line = 3 * t.width as usize;
    for row in 0..t.height as usize {
        let at = 3 * ((o[1] as usize + row) * width as usize + o[0] as usize);
        rgb[at..at + line].copy_from_slice(&t.rgb[row * line..(row + 1) * line]);
    }
}
