//! Dominant plane normals of a mesh's triangle normals.
//!
//! Builds a small synthetic mesh (a room corner: floor, two walls and a ramp, each a slightly
//! rough triangulated grid, plus a bumpy patch as clutter), computes its triangle normals,
//! and finds the dominant normals with the paper's mesh preset. Writes the unwrapped
//! accumulator image to `fastga_unwrapped.png` in the temporary directory.
//!
//! `cargo run -p fastga --features png --example mesh_normals`

use fastga::{FastGa, FastGaConfig};

/// A triangle mesh: vertices and counter-clockwise triangles.
struct Mesh {
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
}

impl Mesh {
    /// Adds a `k × k` grid spanning `origin + a·u + b·v` (a, b in [0, 1]) whose points are
    /// displaced along `u × v` by `bump(a, b)`.
    fn add_grid(
        &mut self,
        origin: [f64; 3],
        u: [f64; 3],
        v: [f64; 3],
        k: u32,
        bump: impl Fn(f64, f64) -> f64,
    ) {
        let n = normalize(cross(u, v));
        let first = self.vertices.len() as u32;
        for i in 0..=k {
            for j in 0..=k {
                let (a, b) = (f64::from(i) / f64::from(k), f64::from(j) / f64::from(k));
                let h = bump(a, b);
                self.vertices.push(std::array::from_fn(|d| {
                    origin[d] + a * u[d] + b * v[d] + h * n[d]
                }));
            }
        }
        let at = |i: u32, j: u32| first + i * (k + 1) + j;
        for i in 0..k {
            for j in 0..k {
                self.triangles
                    .push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                self.triangles
                    .push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
    }

    fn triangle_normals(&self) -> Vec<[f64; 3]> {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.vertices[i as usize]);
                normalize(cross(sub(b, a), sub(c, a)))
            })
            .collect()
    }
}

fn main() -> Result<(), fastga::FastGaError> {
    // Small deterministic roughness, like sensor noise on flat surfaces.
    let rough =
        |a: f64, b: f64| 0.0004 * ((a * 91.0).sin() * (b * 57.0).cos() + (a * b * 313.0).sin());
    let mut mesh = Mesh {
        vertices: Vec::new(),
        triangles: Vec::new(),
    };
    let o = [0.0, 0.0, 0.0];
    mesh.add_grid(o, [4.0, 0.0, 0.0], [0.0, 3.0, 0.0], 80, rough); // floor, normal +z
    mesh.add_grid(o, [0.0, 0.0, 2.5], [4.0, 0.0, 0.0], 60, rough); // wall, normal +y
    mesh.add_grid(o, [0.0, 3.0, 0.0], [0.0, 0.0, 2.5], 50, rough); // wall, normal +x
    mesh.add_grid([2.0, 1.0, 0.0], [1.5, 0.0, 0.4], [0.0, 1.0, 0.0], 30, rough); // ramp, 15° from the floor
    // Clutter: a bumpy sphere-like patch whose normals point everywhere.
    mesh.add_grid(
        [1.0, 2.0, 1.0],
        [0.5, 0.0, 0.0],
        [0.0, 0.5, 0.0],
        40,
        |a, b| 0.3 * ((a * 12.0).sin() * (b * 9.0).cos()),
    );
    let normals = mesh.triangle_normals();

    let mut fastga = FastGa::new(FastGaConfig::mesh())?;
    let found = fastga.detect(&normals)?;
    println!(
        "{} triangle normals: {} integrated (12 % sample), {} invalid, {} peaks",
        normals.len(),
        found.stats.integrated,
        found.stats.skipped_invalid,
        found.peaks.len()
    );
    for (k, d) in found.normals.iter().enumerate() {
        let [x, y, z] = d.normal;
        println!(
            "dominant normal {k}: [{x:+.4}, {y:+.4}, {z:+.4}]  weight {:.3}",
            d.weight
        );
    }

    let path = std::env::temp_dir().join("fastga_unwrapped.png");
    fastga.accumulator().unwrapped_image().write_png(&path)?;
    println!("unwrapped accumulator image: {}", path.display());
    Ok(())
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn normalize(a: [f64; 3]) -> [f64; 3] {
    let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    a.map(|x| x / l)
}
