#!/usr/bin/env bash
# Builds the cargo-fuzz targets of fuzz/ and runs each for SECONDS_PER_TARGET seconds
# (default 60), seeded from ../shared/fixtures, then prints a table: target, executions,
# crashes (new files under fuzz/artifacts/TARGET: crash-, oom-, timeout-, leak-).
#
#   scripts/fuzz.sh [SECONDS_PER_TARGET]
#
# Environment: FUZZ_TARGETS="pcd ply" (default: all), FUZZ_PARALLEL=N targets at once
# (default 1), FUZZ_RUNS=N: stop a target after N executions (or SECONDS_PER_TARGET,
# whichever comes first; the issue's figures: 10000000 per parser, 1000000 end to end),
# FUZZ_TIMEOUT=S: a single input running S seconds is a hang (default 20; raise it when the
# fuzzers are paused with SIGSTOP for other work, since libFuzzer measures wall time),
# FUZZ_SANITIZER=none|address (default none: the crates forbid unsafe code,
# and without a sanitizer each target runs several times more inputs), POLYLIDAR_FIXTURES
# (default ../shared/fixtures). Needs a nightly toolchain; installs cargo-fuzz from
# crates.io when it is missing. The seed corpus is copied at run time into fuzz/corpus/
# (git-ignored): small fixtures whole, big ones as their first 16 KiB.
set -euo pipefail

SECONDS_PER_TARGET=${1:-60}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
FUZZ="$ROOT/fuzz"
FIXTURES=${POLYLIDAR_FIXTURES:-$ROOT/../shared/fixtures}
SANITIZER=${FUZZ_SANITIZER:-none}
PARALLEL=${FUZZ_PARALLEL:-1}
RUNS=${FUZZ_RUNS:--1}
TIMEOUT=${FUZZ_TIMEOUT:-20}
HEAD_BYTES=16384

if ! cargo +nightly --version >/dev/null 2>&1; then
    echo "fuzz.sh: needs a nightly toolchain (rustup toolchain install nightly)" >&2
    exit 2
fi
if ! cargo fuzz --version >/dev/null 2>&1; then
    cargo install cargo-fuzz --locked
fi

cd "$FUZZ"
if [ -n "${FUZZ_TARGETS:-}" ]; then
    TARGETS=$FUZZ_TARGETS
    for target in $TARGETS; do
        cargo +nightly fuzz build -O -s "$SANITIZER" "$target"
    done
else
    TARGETS=$(cargo +nightly fuzz list)
    cargo +nightly fuzz build -O -s "$SANITIZER"
fi

BIN="$FUZZ/target/$(rustc +nightly -vV | sed -n 's/^host: //p')/release"

# Extensions whose fixtures seed each reader target.
declare -A SEEDS=(
    [pcd]="pcd" [lzf]="pcd" [npy]="npy" [las]="las laz"
    [png]="png jpg jpeg" [kitti]="bin" [intrinsics]="csv json"
)
# The pipeline target's first byte picks the format (as fuzz/src/lib.rs input_of).
declare -A FORMAT_BYTE=([pcd]=0 [ply]=1 [obj]=2 [npy]=3 [csv]=4 [las]=5 [laz]=5 [bin]=6 [png]=7)

# Copies `file` (whole, or its first HEAD_BYTES) to `dest`, after the bytes `prefix`
# given in printf notation.
seed() {
    local file=$1 dest=$2 prefix=${3:-}
    { printf "$prefix"; head -c "$HEAD_BYTES" "$file"; } > "$dest"
}

make_corpus() {
    local target=$1 dir="$FUZZ/corpus/$1"
    mkdir -p "$dir"
    [ -d "$FIXTURES" ] || return 0
    local k=0
    case $target in
        pipeline)
            while IFS= read -r -d '' f; do
                local ext=${f##*.}
                ext=${ext,,}
                [ -n "${FORMAT_BYTE[$ext]:-}" ] || continue
                local byte
                byte=$(printf '\\%03o\\%03o' "${FORMAT_BYTE[$ext]}" $((k % 12)))
                # Small inputs only: one pipeline run per input must stay short.
                { printf "$byte"; head -c 4096 "$f"; } > "$dir/seed-$k"
                k=$((k + 1))
            done < <(find "$FIXTURES" -type f -print0 | sort -z)
            ;;
        config)
            printf '\000min_triangles = 10\nlmax = 0.5\n' > "$dir/seed-0"
            printf '\001[laplacian]\niterations = 2\nlambda = 0.5\n[postprocess]\nalpha = 0.1\n' > "$dir/seed-1"
            printf '\002threads = 2\nnorm_thresh = 0.95\nz_thresh = 0.1\nup = [0, 0, 1]\n' > "$dir/seed-2"
            ;;
        ply)
            # No PLY among the fixtures: without seeds the fuzzer never gets past the
            # magic line. An ascii mesh with colours and both binary byte orders.
            printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 255 0 0\n1 0 0 0 255 0\n0 1 0 0 0 255\n3 0 1 2\n' > "$dir/seed-ascii"
            { printf 'ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n'
              python3 -c 'import struct, sys; sys.stdout.buffer.write(struct.pack("<9d", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<B3I", 3, 0, 1, 2))'
            } > "$dir/seed-le"
            { printf 'ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n'
              python3 -c 'import struct, sys; sys.stdout.buffer.write(struct.pack(">9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack(">B3i", 3, 0, 1, 2))'
            } > "$dir/seed-be"
            ;;
        csv)
            # The fixtures' CSVs are camera metadata; point tables with and without a
            # header, 2 and 3 columns, other separators.
            printf 'x,y,z\n0,0,0\n1,0,0.5\n0,1,-0.5\n' > "$dir/seed-header"
            printf '0 0\n1 0\n0 1\n1 1\n' > "$dir/seed-2d"
            printf '0.5;1.5;2.5\n-1e3;2E-2;3\n' > "$dir/seed-semicolon"
            for f in "$FIXTURES"/realsense/*.csv; do
                [ -f "$f" ] && seed "$f" "$dir/seed-$((k++))"
            done
            ;;
        obj)
            # No OBJ among the fixtures either.
            printf '# a square\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0 0.5 0.5 0.5\nvn 0 0 1\nf 1//1 2//1 3//1\nf 1/1 3/1 4/1\nf -4 -2 -1\n' > "$dir/seed-square"
            ;;
        *)
            for ext in ${SEEDS[$target]:-}; do
                while IFS= read -r -d '' f; do
                    seed "$f" "$dir/seed-$k"
                    k=$((k + 1))
                done < <(find "$FIXTURES" -type f -iname "*.$ext" -print0 | sort -z)
            done
            ;;
    esac
}

run_target() {
    local target=$1 log="$FUZZ/artifacts/$1.log"
    mkdir -p "$FUZZ/artifacts/$target"
    make_corpus "$target"
    local before
    before=$(find "$FUZZ/artifacts/$target" -type f | wc -l)
    local max_len=$HEAD_BYTES
    [ "$target" = pipeline ] && max_len=4100
    # The binary built above, run directly: `cargo fuzz run` would rebuild first.
    (cd "$FUZZ/artifacts/$target" && "$BIN/$target" "$FUZZ/corpus/$target" \
        -artifact_prefix="$FUZZ/artifacts/$target/" \
        -max_total_time="$SECONDS_PER_TARGET" -runs="$RUNS" -rss_limit_mb=512 -timeout="$TIMEOUT" \
        -max_len="$max_len" -print_final_stats=1 > "$log" 2>&1) || true
    local execs after
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1)
    after=$(find "$FUZZ/artifacts/$target" -type f | wc -l)
    local seconds
    seconds=$(grep -o 'Done [0-9]* runs in [0-9]* second' "$log" | grep -o 'in [0-9]*' | grep -o '[0-9]*' | tail -1)
    printf '%s %s %s %s\n' "$target" "${execs:-0}" $((after - before)) "${seconds:-?}" \
        > "$FUZZ/artifacts/$target.result"
}

running=0
for target in $TARGETS; do
    run_target "$target" &
    running=$((running + 1))
    if [ "$running" -ge "$PARALLEL" ]; then
        wait -n
        running=$((running - 1))
    fi
done
wait

printf '\n| target | executions | seconds | crashes |\n| --- | ---: | ---: | ---: |\n'
total_crashes=0
for target in $TARGETS; do
    read -r name execs crashes seconds < "$FUZZ/artifacts/$target.result"
    printf '| %s | %s | %s | %s |\n' "$name" "$execs" "$seconds" "$crashes"
    total_crashes=$((total_crashes + crashes))
done
echo "seconds per target: $SECONDS_PER_TARGET; logs and crash inputs: fuzz/artifacts/"
[ "$total_crashes" -eq 0 ]
