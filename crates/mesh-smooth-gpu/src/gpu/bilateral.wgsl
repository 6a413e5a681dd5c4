// Bilateral normal filter on the implicit right-cut mesh of an organized cloud.
// Triangles are stored per slot 2 * (r * (cols - 1) + c) + k as vec4: xyz and w = 1 when the
// triangle exists, all zero when it does not. `prepare_triangles` computes normals and centroids
// (one invocation per cell), `filter_normals` runs one pass (one invocation per cell, both of its
// triangles). Mirrors the CPU kernels operation for operation.

struct Params {
    rows: u32,
    cols: u32,
    half: u32,
    pad0: u32,
    inv_var_length: f32,
    inv_var_angle: f32,
    pad1: f32,
    pad2: f32,
}

// exp(-e) is taken as 0 beyond this, as on the CPU (`cpu::fast_exp::EXP_NEG_CUTOFF`): smaller
// weights give subnormal products, which GPUs flush to zero.
const EXP_NEG_CUTOFF: f32 = 50.0;

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> points: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> centroids_out: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> normals_out: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> centroids: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> normals_in: array<vec4<f32>>;

fn write_triangle(slot: u32, a: vec4<f32>, b: vec4<f32>, c: vec4<f32>) {
    if (a.w * b.w * c.w > 0.0) {
        let ux = b.x - a.x;
        let uy = b.y - a.y;
        let uz = b.z - a.z;
        let vx = c.x - a.x;
        let vy = c.y - a.y;
        let vz = c.z - a.z;
        let px = uy * vz - uz * vy;
        let py = uz * vx - ux * vz;
        let pz = ux * vy - uy * vx;
        let len = sqrt(px * px + py * py + pz * pz);
        var n = vec3<f32>(0.0, 0.0, 0.0);
        if (len > 0.0) {
            n = vec3<f32>(px / len, py / len, pz / len);
        }
        normals_out[slot] = vec4<f32>(n, 1.0);
        centroids_out[slot] = vec4<f32>(
            (a.x + b.x + c.x) / 3.0,
            (a.y + b.y + c.y) / 3.0,
            (a.z + b.z + c.z) / 3.0,
            1.0,
        );
    } else {
        normals_out[slot] = vec4<f32>(0.0, 0.0, 0.0, 0.0);
        centroids_out[slot] = vec4<f32>(0.0, 0.0, 0.0, 0.0);
    }
}

@compute @workgroup_size(16, 16, 1)
fn prepare_triangles(@builtin(global_invocation_id) id: vec3<u32>) {
    let c = id.x;
    let r = id.y;
    let cols = params.cols;
    let cell_cols = cols - 1u;
    if (r + 1u >= params.rows || c >= cell_cols) {
        return;
    }
    let p1 = points[r * cols + c];
    let p2 = points[r * cols + c + 1u];
    let p4 = points[(r + 1u) * cols + c];
    let p3 = points[(r + 1u) * cols + c + 1u];
    let slot = 2u * (r * cell_cols + c);
    write_triangle(slot, p3, p2, p1);
    write_triangle(slot + 1u, p1, p4, p3);
}

@compute @workgroup_size(16, 16, 1)
fn filter_normals(@builtin(global_invocation_id) id: vec3<u32>) {
    let c = id.x;
    let r = id.y;
    let cell_rows = params.rows - 1u;
    let cell_cols = params.cols - 1u;
    if (r >= cell_rows || c >= cell_cols) {
        return;
    }
    let h = params.half;
    let border = r < h || c < h || r + h >= cell_rows || c + h >= cell_cols;
    let k = 2u * h + 1u;
    for (var ko = 0u; ko < 2u; ko++) {
        let slot = 2u * (r * cell_cols + c) + ko;
        let own = normals_in[slot];
        if (border || own.w == 0.0) {
            normals_out[slot] = own;
            continue;
        }
        let oc = centroids[slot];
        var ax = 0.0;
        var ay = 0.0;
        var az = 0.0;
        for (var dr = 0u; dr < k; dr++) {
            let row_start = 2u * ((r + dr - h) * cell_cols + c - h);
            for (var dc = 0u; dc < k; dc++) {
                if (dr == h && dc == h) {
                    continue;
                }
                for (var kn = 0u; kn < 2u; kn++) {
                    let j = row_start + 2u * dc + kn;
                    let q = normals_in[j];
                    let qc = centroids[j];
                    let ex = oc.x - qc.x;
                    let ey = oc.y - qc.y;
                    let ez = oc.z - qc.z;
                    // |own − q|² as 2 − 2 own · q, the CPU's form: equal for unit normals,
                    // and a missing neighbour's weight is zeroed by q.w below.
                    let length = fma(ez, ez, fma(ey, ey, ex * ex));
                    let cosine = fma(own.z, q.z, fma(own.y, q.y, own.x * q.x));
                    let two_iva = 2.0 * params.inv_var_angle;
                    let e = fma(cosine, -two_iva, fma(length, params.inv_var_length, two_iva));
                    var w = 0.0;
                    if (e <= EXP_NEG_CUTOFF) {
                        w = q.w * exp(-e);
                    }
                    ax += w * q.x;
                    ay += w * q.y;
                    az += w * q.z;
                }
            }
        }
        // Scaled by the largest component first, so that the squares of small sums do
        // not flush to zero (as `normalize` on the CPU).
        let m = max(abs(ax), max(abs(ay), abs(az)));
        if (m > 0.0) {
            let b = vec3<f32>(ax, ay, az) / m;
            normals_out[slot] = vec4<f32>(b / sqrt(dot(b, b)), 1.0);
        } else {
            normals_out[slot] = own;
        }
    }
}
