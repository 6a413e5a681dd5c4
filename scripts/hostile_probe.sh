#!/usr/bin/env bash
# The hostile-input probe of issue 22: generates each class of bad input and flag the
# issue lists (decompression and header bombs, endless streams, outputs that clash with
# inputs or cannot be written, out-of-range parameters, corrupt LAS/LAZ, misleading-message
# cases) and, for every reader, empty, truncated, bit-flipped and random files, then runs
# `polylidar` on each and checks:
#   - exit code 0 (a result) or 1/2 (an error), never a signal or a timeout;
#   - no panic text (`panicked`, a backtrace) on stderr;
#   - on error, exactly one `error:` line, naming the file (or the flag) at fault;
#   - on error, no output written: a new output absent, an existing one unchanged, and no
#     temporary file left in the folder.
# Prints one line per failed case and the counts per class; exits 1 if any case fails.
#
#   scripts/hostile_probe.sh [BIN]       # BIN default: target/release/polylidar
#
# Environment: POLYLIDAR_FIXTURES (default ../shared/fixtures: real files to corrupt,
# used when present), PROBE_SEED (default 22), PROBE_VERBOSE=1 (print every case),
# PROBE_KEEP=DIR (copy the input of each failed case there).
set -euo pipefail

ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=${1:-$ROOT/target/release/polylidar}
[ -x "$BIN" ] || { echo "hostile_probe.sh: no binary $BIN (cargo build --release -p polylidar-cli)" >&2; exit 2; }
export PROBE_BIN=$BIN
export PROBE_FIXTURES=${POLYLIDAR_FIXTURES:-$ROOT/../shared/fixtures}
exec python3 - <<'EOF'
import os, random, re, shutil, signal, struct, subprocess, sys, tempfile, zlib

BIN = os.environ["PROBE_BIN"]
FIX = os.environ["PROBE_FIXTURES"]
VERBOSE = os.environ.get("PROBE_VERBOSE") == "1"
KEEP = os.environ.get("PROBE_KEEP")
rng = random.Random(int(os.environ.get("PROBE_SEED", "22")))
work = tempfile.mkdtemp(prefix="hostile-probe-")
results = {}  # class -> [passed, failed]
failures = []


def path(name):
    return os.path.join(work, name)


def write(name, data):
    p = path(name)
    os.makedirs(os.path.dirname(p), exist_ok=True)
    with open(p, "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())
    return p


def run(cls, name, args, expect="either", names=None, outputs=(), limit=60, prep=None, extra_check=None,
        per_frame=False):
    """Runs BIN with `args`; `expect` 'error', 'ok' or 'either'; `names`: text the error
    must contain (the file or flag at fault); `outputs`: files the run may write;
    `per_frame`: a stream, whose failing frames each get their own `error: frame` line."""
    before = {o: (open(o, "rb").read() if os.path.isfile(o) else None) for o in outputs}
    try:
        p = subprocess.run([BIN] + args, cwd=work, capture_output=True, timeout=limit, preexec_fn=prep)
        rc, err = p.returncode, p.stderr.decode(errors="replace")
    except subprocess.TimeoutExpired:
        rc, err = "timeout", ""
    problems = []
    if rc == "timeout":
        problems.append(f"no answer within {limit} s")
    elif rc < 0:
        problems.append(f"killed by signal {-rc}")
    elif rc not in (0, 1, 2):
        problems.append(f"exit code {rc}")
    if re.search(r"panicked|stack backtrace|RUST_BACKTRACE", err):
        problems.append("panic text on stderr")
    if rc != 0 and rc != "timeout":
        errors = [l for l in err.splitlines() if l.startswith("error")
                  and not (per_frame and l.startswith("error: frame "))]
        if len(errors) != 1:
            problems.append(f"{len(errors)} error lines")
        if names and names not in err:
            problems.append(f"the message does not name {names!r}")
        for o, old in before.items():
            now = open(o, "rb").read() if os.path.isfile(o) else None
            if now != old:
                problems.append(f"{os.path.basename(o)} changed by a failed run")
    if expect == "error" and rc == 0:
        problems.append("succeeded where an error was expected")
    if expect == "ok" and rc != 0:
        problems.append("failed where a result was expected")
    for dirpath, _, files in os.walk(work):
        for f in files:
            if f.startswith(".") and f.endswith(".tmp"):
                problems.append(f"temporary file {f} left")
                os.remove(os.path.join(dirpath, f))
    if extra_check and not problems:
        problems += extra_check(rc, err)
    ok = not problems
    results.setdefault(cls, [0, 0])[0 if ok else 1] += 1
    first = next((l for l in err.splitlines() if l.strip()), "")
    if not ok and KEEP and len(args) > 1 and os.path.isfile(path(args[1])):
        os.makedirs(KEEP, exist_ok=True)
        shutil.copy(path(args[1]), os.path.join(KEEP, f"{len(failures)}_{os.path.basename(args[1])}"))
    if not ok:
        failures.append(f"FAIL [{cls}] {name}: {'; '.join(problems)} (rc {rc}): {first[:200]}")
    if VERBOSE:
        print(f"{'ok  ' if ok else 'FAIL'} [{cls}] {name}: rc {rc}: {first[:160]}")


# ---- inputs ---------------------------------------------------------------------------

def png16(name, width, height, row, meta=True):
    raw = bytearray()
    for y in range(height):
        raw.append(0)
        raw += b"".join(struct.pack(">H", v) for v in row(y))
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    ihdr = struct.pack(">IIBBBBB", width, height, 16, 0, 0, 0, 0)
    p = write(name, b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b""))
    if meta:
        write(name[:-4] + "_metadata.csv", f"Resolution x,{width}\nResolution y,{height}\nFx,600\nFy,600\n"
              f"PPx,{width / 2}\nPPy,{height / 2}\nDepth Units,0.001000\n")
    return p


def npy_f64(name, shape, values):
    header = "{'descr': '<f8', 'fortran_order': False, 'shape': (%s), }" % "".join(f"{s}, " for s in shape)
    header += " " * ((64 - (10 + len(header) + 1) % 64) % 64) + "\n"
    return write(name, b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode()
                 + struct.pack(f"<{len(values)}d", *values))


def ply(name, vertices, faces, fmt="{:r}"):
    text = (f"ply\nformat ascii 1.0\nelement vertex {len(vertices)}\nproperty double x\nproperty double y\n"
            f"property double z\nelement face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
    text += "".join(" ".join(str(c) for c in v) + "\n" for v in vertices)
    text += "".join("3 " + " ".join(str(i) for i in f) + "\n" for f in faces)
    return write(name, text)


grid = "x,y\n" + "".join(f"{i},{j}\n" for i in range(20) for j in range(20))
write("grid.csv", grid)
plane = [c for r in range(30) for k in range(30) for c in (k * 0.05, r * 0.05, 1.0 + 0.01 * r)]
npy_f64("plane.npy", (30, 30, 3), plane)
square = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 0]]
ply("square.ply", square, [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
write("square.obj", "".join(f"v {x} {y} {z}\n" for x, y, z in square) + "f 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n")
pcd_points = [(i % 20 * 0.1, i // 20 * 0.1, 1.0) for i in range(400)]
write("cloud.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 400\nHEIGHT 1\n"
      "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 400\nDATA binary\n")
with open(path("cloud.pcd"), "ab") as f:
    f.write(b"".join(struct.pack("<3f", *p) for p in pcd_points))
write("scan.bin", b"".join(struct.pack("<4f", i % 30 * 0.2, i // 30 * 0.2, -1.7, 0.5) for i in range(900)))
png16("ramp.png", 64, 48, lambda y: [1000 + 4 * y] * 64)

seeds = {"csv": path("grid.csv"), "npy": path("plane.npy"), "ply": path("square.ply"),
         "obj": path("square.obj"), "pcd": path("cloud.pcd"), "bin": path("scan.bin"),
         "png": path("ramp.png")}
for rel, ext in [("lidar/simple.las", "las"), ("lidar/autzen_trim.laz", "laz"),
                 ("rgbd/living_fragment.pcd", "pcd2"), ("lidar/unreal_lidar.npy", "npy2"),
                 ("rgbd/icl_living_depth_00000.png", "png2"), ("kitti/000000.bin", "bin2")]:
    if os.path.isfile(os.path.join(FIX, rel)):
        seeds[ext] = os.path.join(FIX, rel)

# ---- 1. bombs and endless streams -------------------------------------------------------
for name, w, h, v in [("bomb_6000.png", 6000, 6000, 1000), ("bomb_4000.png", 4000, 4000, 1000),
                      ("zeros_4000.png", 4000, 4000, 0), ("ramp_800.png", 800, 800, 1000)]:
    png16(name, w, h, lambda y, w=w, v=v: [v] * w)
    run("bombs", name, ["extract", name, "-o", "bomb.geojson"], "error", name, [path("bomb.geojson")])
# LZF block of back-references: 7.5 M points of zeros from 1 MB.
points = 7_500_000
size = points * 12
stream = bytearray([0, 0]); left = size - 1
stream += bytes([7 << 5, 255, 0]) * (left // 264); left %= 264
stream += b"\x00\x00" * left
write("lzf.pcd", f"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH {points}\nHEIGHT 1\n"
      f"POINTS {points}\nDATA binary_compressed\n".encode() + struct.pack("<II", len(stream), size) + bytes(stream))
run("bombs", "lzf.pcd", ["extract", "lzf.pcd"], "error", "lzf.pcd")
# 300,000 copies of one point with its normal in a 80 kB LZF block (within the budget:
# 217 MB estimated): the pipeline must answer within a minute, not in quadratic time.
same = 300_000
block = bytearray()
for value in (1.0, 2.0, 3.0, 0.0, 0.0, 1.0):
    column = same * 4
    block += bytes([3]) + struct.pack("<f", value)
    left = column - 4
    block += bytes([7 << 5, 255, 3]) * (left // 264)
    left %= 264
    while left >= 3:
        n = min(left, 8)
        block += bytes([(n - 2) << 5, 3])
        left -= n
    if left:
        block += bytes([left - 1]) + struct.pack("<f", value)[4 - left:]
write("same.pcd", f"VERSION 0.7\nFIELDS x y z normal_x normal_y normal_z\nSIZE 4 4 4 4 4 4\nTYPE F F F F F F\n"
      f"COUNT 1 1 1 1 1 1\nWIDTH {same}\nHEIGHT 1\nPOINTS {same}\nDATA binary_compressed\n".encode()
      + struct.pack("<II", len(block), same * 24) + bytes(block))
run("bombs", "LZF PCD of 300000 identical points", ["extract", "same.pcd"], "either", "same.pcd")
for count in ["100000000 1 1", "1 1 4294967295", "1 1 -3"]:
    write("count.pcd", f"FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT {count}\nWIDTH 1\nHEIGHT 1\nDATA ascii\n")
    run("bombs", f"COUNT {count}", ["extract", "count.pcd"], "error", "count.pcd")
for header in ["WIDTH 4000000000\nHEIGHT 4000000000\nPOINTS 16\nDATA binary\n",
               "WIDTH 100000000\nHEIGHT 1\nPOINTS 100000000\nDATA ascii\n"]:
    write("huge.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n" + header)
    run("bombs", "PCD " + header.split("\n")[0], ["extract", "huge.pcd"], "error", "huge.pcd")
write("huge.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n")
run("bombs", "PLY 4e9 vertices", ["extract", "huge.ply"], "error", "huge.ply")
npy_header = "{'descr': '<f8', 'fortran_order': False, 'shape': (100000, 100000, 3), }"
write("huge.npy", b"\x93NUMPY\x01\x00" + struct.pack("<H", len(npy_header) + 1) + npy_header.encode() + b"\n")
run("bombs", "NPY 1e10 values", ["extract", "huge.npy"], "error", "huge.npy")
os.symlink("/dev/zero", path("zero.csv"))
run("streams", "/dev/zero as CSV", ["extract", "zero.csv"], "error", "zero.csv")
os.symlink("/dev/zero", path("zero.pcd"))
run("streams", "/dev/zero as PCD", ["extract", "zero.pcd"], "error", "zero.pcd")
os.mkfifo(path("fifo.csv"))
feeder = subprocess.Popen(["sh", "-c", f"head -c 3000000000 /dev/zero > {path('fifo.csv')}"],
                          stderr=subprocess.DEVNULL)
run("streams", "FIFO of 3 GB of zeros", ["extract", "fifo.csv"], "error", "fifo.csv")
feeder.kill(); feeder.wait()
os.remove(path("fifo.csv"))
os.mkdir(path("folder.csv"))
run("streams", "a folder as input", ["extract", "folder.csv"], "error", "folder.csv")
run("streams", "a missing file", ["extract", "missing.csv"], "error", "missing.csv")
write("unknown.xyzw", "1 2 3\n")
run("streams", "an unknown extension", ["extract", "unknown.xyzw"], "error", "unknown.xyzw")

# ---- 2. outputs ---------------------------------------------------------------------------
g = path("grid.csv")
run("outputs", "-o the input", ["extract", "grid.csv", "-o", "grid.csv"], "error", "grid.csv", [g])
run("outputs", "-o the input through ..", ["extract", "grid.csv", "-o", "./folder.csv/../grid.csv"], "error", "grid.csv", [g])
os.symlink("grid.csv", path("link.geojson"))
run("outputs", "-o a link to the input", ["extract", "grid.csv", "-o", "link.geojson"], "error", "link.geojson", [g])
os.link(g, path("hard.geojson"))
run("outputs", "-o a hard link to the input", ["extract", "grid.csv", "-o", "hard.geojson"], "error", "hard.geojson", [g])
run("outputs", "--plot equal to -o", ["extract", "grid.csv", "-o", "o.geojson", "--plot", "o.geojson"], "error", "o.geojson", [path("o.geojson")])
run("outputs", "--plot under a file", ["extract", "grid.csv", "-o", "o.geojson", "--plot", "grid.csv/plot.png"], "error", "plot.png", [path("o.geojson")])
run("outputs", "-o a directory", ["extract", "grid.csv", "-o", "folder.csv"], "error", "folder.csv")
run("outputs", "--labels-out of unorganized input", ["extract", "grid.csv", "-o", "o.geojson", "--labels-out", "l.npy"], "error", "grid.csv", [path("o.geojson"), path("l.npy")])
write("cfg.toml", "min_triangles = 10\n")
run("outputs", "-o the --config file", ["extract", "grid.csv", "--config", "cfg.toml", "-o", "cfg.toml"], "error", "cfg.toml",
    [path("cfg.toml")])
write("old.geojson", "{}" * 200000)
limit_files = lambda: (signal.signal(signal.SIGXFSZ, signal.SIG_DFL), __import__("resource").setrlimit(
    __import__("resource").RLIMIT_FSIZE, (64 << 10, 64 << 10)))
run("outputs", "a write past ulimit -f", ["extract", "--demo", "scene", "-o", "old.geojson"], "error", "old.geojson",
    [path("old.geojson")], prep=limit_files)
run("outputs", "a later output past ulimit -f", ["extract", "--demo", "scene", "-o", "old.geojson", "--labels-out", "lab.npy"],
    "error", None, [path("old.geojson"), path("lab.npy")], prep=limit_files)
os.makedirs(path("ro"), exist_ok=True)
write("ro/out.geojson", "old")
os.chmod(path("ro/out.geojson"), 0o444)
run("outputs", "a read-only output", ["extract", "grid.csv", "-o", "ro/out.geojson"], "error", "out.geojson", [path("ro/out.geojson")])
frames = os.path.join(work, "frames"); os.makedirs(frames)
for k in range(2):
    shutil.copy(path("plane.npy"), os.path.join(frames, f"f_{k}.npy"))
run("outputs", "stream -o a frame", ["stream", "frames/f_*.npy", "-o", "frames/f_1.npy"], "error", "f_1.npy", [os.path.join(frames, "f_1.npy")])
write("frames/f_2.npy", b"\x93NUMPY broken")
write("lines.geojsonl", "previous\n")
run("outputs", "stream with a corrupt frame", ["stream", "frames/f_*.npy", "-o", "lines.geojsonl", "--no-smoothing"], "error", "f_2.npy", [path("lines.geojsonl")], per_frame=True)
os.remove(os.path.join(frames, "f_2.npy"))

# ---- 3. flags and parameters ----------------------------------------------------------
for t in ["4000", "100000", "-1", "1e9"]:
    run("flags", f"--threads {t}", ["extract", "grid.csv", "--threads", t], "error", "thread" if t not in ("-1", "1e9") else t)
configs = {
    "lambda 1e30": "[laplacian]\nlambda = 1e30\n", "lambda -1e30": "[laplacian]\nlambda = -1e30\n",
    "lambda 2": "[laplacian]\nlambda = 2\n", "lambda 10": "[laplacian]\nlambda = 10\n",
    "lambda -1": "[laplacian]\nlambda = -1\n", "lambda 0": "[laplacian]\nlambda = 0\n",
    "lambda nan": "[laplacian]\nlambda = nan\n",
    "iterations 4294967295": "[laplacian]\niterations = 4294967295\n",
    "iterations -1": "[laplacian]\niterations = -1\n",
    "kernel 4": "[laplacian]\nkernel = 4\n", "kernel 17": "[laplacian]\nkernel = 17\n",
    "kernel 4001": "[bilateral]\nkernel = 4001\n",
    "bilateral iterations 1e9": "[bilateral]\niterations = 1000000000\n",
    "sigma 0": "[bilateral]\nsigma_length = 0\n", "sigma nan": "[bilateral]\nsigma_angle = nan\n",
    "sample_fraction 0": "[fastga]\nsample_fraction = 0\n", "sample_fraction 2": "[fastga]\nsample_fraction = 2\n",
    "lmax -1": "lmax = -1\n", "lmax inf": "lmax = inf\n", "norm_thresh 2": "norm_thresh = 2\n",
    "z_thresh nan": "z_thresh = nan\n", "unknown key": "no_such_key = 1\n", "not TOML": "[[[\n",
    "threads 100000": "threads = 100000\n", "min_triangles -5": "min_triangles = -5\n",
}
for name, text in configs.items():
    write("bad.toml", text)
    run("flags", f"config {name}", ["extract", "plane.npy", "--config", "bad.toml", "-o", "flags.geojson"], "error",
        None, [path("flags.geojson")])
for flag, value in [("--z-thresh", "-1"), ("--min-area", "-1"), ("--min-triangles", "-1"), ("--lmax", "nan"),
                    ("--norm-thresh", "1.5"), ("--stride", "0"), ("--max-memory", "lots"), ("--max-memory", "0")]:
    # The error names the flag, or the parameter it sets (`min_area = -1 (must be ...)`).
    key = {"--min-area": "min_area", "--lmax": "lmax", "--z-thresh": "z_thresh"}.get(flag, flag)
    run("flags", f"{flag} {value}", ["extract", "grid.csv", flag, value], "error",
        "lots" if value == "lots" else None if flag == "--max-memory" else key)
npy_f64("tiny.npy", (4, 4, 3), [c for i in range(16) for c in (i % 4, i // 4, 1.0)])
run("flags", "kernel wider than the image", ["extract", "tiny.npy", "--preset", "synpeb"], "error", "tiny.npy")

# ---- 5. misleading-message cases ------------------------------------------------------
npy_f64("zeros.npy", (3, 3, 3), [0.0] * 27)
run("messages", "all-zero organized cloud", ["extract", "zeros.npy"], "error", "zeros.npy")
npy_f64("overflow.npy", (3, 3, 3), [c for i in range(9) for c in (1e300 * (i % 3), 1e300 * (i // 3), 1e300)])
run("messages", "overflowing organized cloud", ["extract", "overflow.npy"], "error", "overflow.npy")
write("word.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\n"
      "end_header\n0 0 0\n1 zero 0\n0 1 0\n")
run("messages", "ASCII PLY word", ["extract", "word.ply"], "error", "word.ply",
    extra_check=lambda rc, err: ["says compressed"] if "compressed" in err else [])
write("frac.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\n"
      "element face 1\nproperty list uchar float vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n")
run("messages", "PLY index 1.5", ["extract", "frac.ply"], "error", "frac.ply",
    extra_check=lambda rc, err: [] if "1.5" in err else ["1.5 not reported"])
ply("flat.ply", [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 0]])
run("messages", "degenerate triangle", ["extract", "flat.ply"], "error", "flat.ply",
    extra_check=lambda rc, err: ["mentions DegeneratePolicy"] if "DegeneratePolicy" in err else [])
ply("huge_tri.ply", [[0, 0, 0], [1e300, 0, 0], [0, 1e300, 0], [1, 1, 0]], [[0, 1, 2], [1, 3, 2]])
run("messages", "overflowing triangle", ["extract", "huge_tri.ply"], "error", "huge_tri.ply",
    extra_check=lambda rc, err: ["called zero area"] if "zero area" in err else [])
write("two.csv", "0,0\n1,1\n")
run("messages", "two points", ["extract", "two.csv"], "error", "two.csv")
write("typo.csv", "1.5,2,3x\n1,2,3\n4,5,6\n")
run("messages", "CSV typo in the first row", ["extract", "typo.csv"], "error", "typo.csv")
write("nan.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 403\nHEIGHT 1\n"
      "POINTS 403\nDATA ascii\n" + "".join(f"{x} {y} {z}\n" for x, y, z in pcd_points) + "nan nan nan\nnan 0 0\n0 nan 1\n")
run("messages", "NaN points in an unorganized PCD", ["extract", "nan.pcd"], "ok",
    extra_check=lambda rc, err: [] if "3 invalid points skipped" in err else ["NaN points not counted"])
run("messages", "error printed once", ["extract", "missing.csv"], "error", "missing.csv",
    extra_check=lambda rc, err: [] if err.count("No such file") == 1 else ["OS error repeated"])

# ---- 4 and 6. every reader: empty, truncated, bit-flipped, random -------------------------
def ext_of(key):
    return {"pcd2": "pcd", "npy2": "npy", "png2": "png", "bin2": "bin"}.get(key, key)

for key, src in seeds.items():
    ext = ext_of(key)
    data = open(src, "rb").read()
    extra = []
    if ext == "png":
        extra = ["--intrinsics", "600,600,32,24"]
    cases = [("empty", b"")]
    for frac in [0.001, 0.01, 0.05, 0.1, 0.25, 0.5, 0.75, 0.9, 0.99]:
        cases.append((f"truncated at {frac:g}", data[: max(1, int(len(data) * frac))]))
    for k in range(8):
        flipped = bytearray(data)
        for _ in range(1 + k):
            # Mostly in the first kilobytes (headers), some anywhere.
            i = rng.randrange(min(len(data), 2048) if k % 2 == 0 else len(data))
            flipped[i] ^= 1 << rng.randrange(8)
        cases.append((f"bit flips {k + 1}", bytes(flipped)))
    cases.append(("random bytes", bytes(rng.randrange(256) for _ in range(4096))))
    cases.append(("header then random", data[:128] + bytes(rng.randrange(256) for _ in range(4096))))
    for name, body in cases:
        stem = f"c_{key}"
        f = write(f"{stem}.{ext}", body)
        if ext == "png":
            write(f"{stem}_metadata.csv", "")
        run(f"corrupt {key}", f"{key} {name}", ["extract", f"{stem}.{ext}", "-o", "corrupt.geojson"] + extra,
            "either", f"{stem}.{ext}", [path("corrupt.geojson")], limit=120)
        if os.path.exists(path("corrupt.geojson")):
            os.remove(path("corrupt.geojson"))

shutil.rmtree(work, ignore_errors=True)
total = sum(p + f for p, f in results.values())
failed = sum(f for _, f in results.values())
print(f"\n| class | cases | passed | failed |\n| --- | ---: | ---: | ---: |")
for cls, (p, f) in results.items():
    print(f"| {cls} | {p + f} | {p} | {f} |")
print(f"| all | {total} | {total - failed} | {failed} |")
for line in failures:
    print(line)
sys.exit(1 if failed else 0)
EOF
