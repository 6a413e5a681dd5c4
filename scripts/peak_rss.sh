#!/usr/bin/env bash
# Peak RSS of `polylidar extract` on hostile and real inputs (issue 22), with the default
# memory budget unless MAX_MEMORY is set: generates the decompression bombs of the issue
# (nothing binary is committed), runs each input once under `/usr/bin/time` and prints a
# Markdown table: input, bytes, exit code, peak RSS (MB), wall seconds, the first line of
# the error.
#
#   scripts/peak_rss.sh [BIN]            # BIN default: target/release/polylidar
#
# Environment: MAX_MEMORY (e.g. 512M: passed as --max-memory), POLYLIDAR_FIXTURES (default
# ../shared/fixtures; its real inputs are measured too when present). The inputs are
# generated in a temporary directory, removed at the end.
set -euo pipefail

ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=${1:-$ROOT/target/release/polylidar}
FIXTURES=${POLYLIDAR_FIXTURES:-$ROOT/../shared/fixtures}
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
[ -x "$BIN" ] || { echo "peak_rss.sh: no binary $BIN (cargo build --release -p polylidar-cli)" >&2; exit 2; }
[ -x /usr/bin/time ] || { echo "peak_rss.sh: needs GNU time (/usr/bin/time)" >&2; exit 2; }

python3 - "$WORK" <<'EOF'
import struct, sys, zlib

work = sys.argv[1]

def png16(path, width, height, row):
    """A 16-bit greyscale PNG whose every row is `row(y)` (a list of depths), and the
    RealSense metadata CSV beside it (its intrinsics)."""
    raw = bytearray()
    for y in range(height):
        raw.append(0)
        raw += b"".join(struct.pack(">H", v) for v in row(y))
    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    ihdr = struct.pack(">IIBBBBB", width, height, 16, 0, 0, 0, 0)
    with open(path[:-4] + "_metadata.csv", "w") as f:
        f.write(f"Resolution x,{width}\nResolution y,{height}\nFx,600\nFy,600\n"
                f"PPx,{width / 2}\nPPy,{height / 2}\nDepth Units,0.001000\n")
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr)
                + chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b""))

def constant(width, value):
    line = [value] * width
    return lambda y: line

# The issue's bombs: constant depth 6000 x 6000 and 4000 x 4000, zeros 4000 x 4000.
png16(f"{work}/bomb_6000.png", 6000, 6000, constant(6000, 1000))
png16(f"{work}/bomb_4000.png", 4000, 4000, constant(4000, 1000))
png16(f"{work}/zeros_4000.png", 4000, 4000, constant(4000, 0))
# About the largest depth image a kilobyte-sized file may claim within the default budget
# (760 x 750 pixels, 401 MB estimated): a tilted plane, so the whole pipeline runs;
# and one past it (800 x 800).
png16(f"{work}/ramp_760x750.png", 760, 750, lambda y: [1000 + y] * 760)
png16(f"{work}/ramp_800x800.png", 800, 800, lambda y: [1000 + y] * 800)

def lzf_pcd(path, points):
    """A binary_compressed PCD of `points` zero points whose LZF block is back-references."""
    size = points * 12
    stream = bytearray([0, 0])
    left = size - 1
    while left >= 264:
        stream += bytes([7 << 5, 255, 0])
        left -= 264
    stream += b"\x00\x00" * left
    header = (f"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
              f"WIDTH {points}\nHEIGHT 1\nPOINTS {points}\nDATA binary_compressed\n")
    with open(path, "wb") as f:
        f.write(header.encode() + struct.pack("<II", len(stream), size) + stream)

lzf_pcd(f"{work}/lzf_7500000.pcd", 7_500_000)
with open(f"{work}/count.pcd", "wb") as f:
    f.write(b"FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 100000000 1 1\n"
            b"WIDTH 1\nHEIGHT 1\nDATA ascii\n")
EOF

inputs=("$WORK"/bomb_6000.png "$WORK"/bomb_4000.png "$WORK"/zeros_4000.png
    "$WORK"/ramp_760x750.png "$WORK"/ramp_800x800.png "$WORK"/lzf_7500000.pcd
    "$WORK"/count.pcd /dev/zero)
for f in lidar/simple.las lidar/unreal_lidar.npy lidar/autzen_trim.laz realsense/001_small_depth.png \
    realsense/001_big_depth.png realsense/rgbd_opc.npy rgbd/icl_living_depth_00000.png \
    rgbd/tum_depth.png kitti/000000.bin synpeb/pc_01.pcd rgbd/living_fragment.pcd; do
    [ -f "$FIXTURES/$f" ] && inputs+=("$FIXTURES/$f")
done

extra=()
[ -n "${MAX_MEMORY:-}" ] && extra=(--max-memory "$MAX_MEMORY")
printf '| input | bytes | exit | peak RSS MB | s | message |\n| --- | ---: | ---: | ---: | ---: | --- |\n'
for input in "${inputs[@]}"; do
    args=("$input")
    case $input in
        /dev/zero) args=(/dev/zero) ;;
        */tum_depth.png | */icl_living_depth_*.png)
            args+=(--intrinsics "$FIXTURES/rgbd/camera_primesense.json" --depth-scale 5000) ;;
    esac
    # /dev/zero is read as a CSV stream: name it so through a link.
    if [ "$input" = /dev/zero ]; then
        ln -sf /dev/zero "$WORK/zero.csv"
        args=("$WORK/zero.csv")
    fi
    bytes=$( [ -f "$input" ] && stat -c %s "$input" || echo '∞')
    set +e
    /usr/bin/time -f '%M %e' -o "$WORK/time" "$BIN" extract "${args[@]}" "${extra[@]}" \
        -o "$WORK/out.geojson" --json > /dev/null 2> "$WORK/err"
    rc=$?
    set -e
    read -r kib secs < <(tail -1 "$WORK/time")
    message=$(grep -m1 '^error' "$WORK/err" | sed "s#$WORK/##; s#$FIXTURES/##" | cut -c1-160 || true)
    printf '| %s | %s | %s | %s | %s | %s |\n' "$(basename "$(dirname "$input")")/$(basename "$input")" "$bytes" "$rc" \
        $((kib / 1024)) "$secs" "${message//|/\\|}"
done
