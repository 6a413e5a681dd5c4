#!/usr/bin/env bash
# Runs the test command it is given (the README's: `bash .ci/test.sh cargo test --workspace
# --all-features --locked`; .ci/run runs exactly it) for any user on any Linux with Rust:
# 1. installs Mesa's software Vulkan driver for the GPU tests when it can (root or
#    passwordless sudo on Debian/Ubuntu); otherwise prints a note and goes on, and the GPU
#    tests skip (under CI=true a missing driver or GPU adapter is a failure);
# 2. runs the command, its output shown as it comes;
# 3. prints how many tests skipped and why (from target/test-skips.log, written by the
#    test-fixtures crate), then one line adding up cargo's results
#    ("tests: 812 passed, 0 failed, 3 ignored"), and exits with the command's status.
set -uo pipefail
cd "$(dirname "$0")/.."

in_ci() { [[ -n "${CI:-}" && "${CI}" != "false" && "${CI}" != "0" ]]; }

if ! bash .ci/install-gpu-deps.sh; then
    if in_ci; then
        echo "test: the GPU test dependencies could not be installed; CI=true, so this is a failure" >&2
        exit 1
    fi
    echo "note: Mesa's software Vulkan driver is not installed (needs root or passwordless sudo on Debian/Ubuntu); GPU tests will be skipped" >&2
fi

target=${CARGO_TARGET_DIR:-target}
[[ "$target" = /* ]] || target="$PWD/$target"
mkdir -p "$target"
export POLYLIDAR_SKIP_LOG="$target/test-skips.log"
: > "$POLYLIDAR_SKIP_LOG"

if [[ $# -eq 0 ]]; then
    echo "usage: bash .ci/test.sh cargo test --workspace --all-features --locked" >&2
    exit 2
fi
output="$target/test-output.log"
"$@" 2>&1 | tee "$output"
status=${PIPESTATUS[0]}

if [[ -s "$POLYLIDAR_SKIP_LOG" ]]; then
    echo
    awk -F '\t' '
        { reason = $2 ~ /^fixture / ? "fixtures not found at ../shared/fixtures" : \
                   $2 ~ /^no GPU adapter/ ? "no GPU adapter (install Mesa lavapipe: .ci/install-gpu-deps.sh as root)" : $2
          if (!seen[$1 SUBSEP reason]++) count[reason]++ }
        END { for (r in count) printf "%d test%s skipped: %s\n", count[r], count[r] == 1 ? "" : "s", r }
    ' "$POLYLIDAR_SKIP_LOG"
else
    echo
    echo "no test skipped"
fi
awk '/^test result: / {
        for (i = 1; i <= NF; i++) {
            if ($(i + 1) ~ /^passed/) passed += $i
            if ($(i + 1) ~ /^failed/) failed += $i
            if ($(i + 1) ~ /^ignored/) ignored += $i
        }
    }
    END { printf "tests: %d passed, %d failed, %d ignored\n", passed, failed, ignored }' "$output"
exit "$status"
