// Laplacian vertex filter on an organized cloud, one invocation per pixel.
// Points are vec4: xyz and w = 0 (invalid; xyz = 0), or, for a valid point, 1 + the passes it
// has left, plus MOVED once a pass has moved it. A pass moves the valid interior points with
// passes left and valid neighbours; the others keep their place (and w) and still weigh in
// their neighbours' means. Mirrors the CPU row kernel operation for operation.

struct Params {
    rows: u32,
    cols: u32,
    half: u32,
    pad0: u32,
    lambda: f32,
    epsilon: f32,
    pad1: f32,
    pad2: f32,
}

// Matches `MOVED` in gpu/mod.rs.
const MOVED: f32 = 1024.0;

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> src: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> dst: array<vec4<f32>>;

@compute @workgroup_size(16, 16, 1)
fn laplacian(@builtin(global_invocation_id) id: vec3<u32>) {
    let c = id.x;
    let r = id.y;
    let rows = params.rows;
    let cols = params.cols;
    if (r >= rows || c >= cols) {
        return;
    }
    let i = r * cols + c;
    let v = src[i];
    let h = params.half;
    let left = v.w - select(0.0, MOVED, v.w >= MOVED) - 1.0;
    if (v.w == 0.0 || left < 1.0 || r < h || c < h || r + h >= rows || c + h >= cols) {
        dst[i] = v;
        return;
    }
    var sx = 0.0;
    var sy = 0.0;
    var sz = 0.0;
    var sw = 0.0;
    let k = 2u * h + 1u;
    for (var dr = 0u; dr < k; dr++) {
        let row_start = (r + dr - h) * cols + c - h;
        for (var dc = 0u; dc < k; dc++) {
            if (dr == h && dc == h) {
                continue;
            }
            let q = src[row_start + dc];
            let dx = v.x - q.x;
            let dy = v.y - q.y;
            let dz = v.z - q.z;
            let d = sqrt(dx * dx + dy * dy + dz * dz);
            let w = min(q.w, 1.0) / (d + params.epsilon);
            sw += w;
            sx += w * q.x;
            sy += w * q.y;
            sz += w * q.z;
        }
    }
    if (sw > 0.0) {
        let lambda = params.lambda;
        dst[i] = vec4<f32>(
            v.x + lambda * (sx / sw - v.x),
            v.y + lambda * (sy / sw - v.y),
            v.z + lambda * (sz / sw - v.z),
            MOVED + left,
        );
    } else {
        dst[i] = v;
    }
}
