#!/usr/bin/env bash
# Runs the test command it is given (the README's: `bash .ci/test.sh cargo test --workspace
# --all-features --locked`; .ci/run runs exactly it) for any user on any Linux with Rust:
# 1. installs Mesa's software Vulkan driver for the GPU tests when it can (root or
#    passwordless sudo on Debian/Ubuntu); otherwise prints a note and goes on, and the GPU
#    tests skip (under CI=true a missing driver or GPU adapter is a failure);
# 2. runs the command, its output shown as it comes;
# 3. builds the Python package's wheel (crates/polylidar-py, maturin) into a fresh virtual
#    environment under the target folder and runs its pytest suite (.ci/python-tests.sh);
#    when Python, venv or pip cannot be set up it prints a note and skips them (under
#    CI=true that is a failure);
# 4. runs the static checks of .ci/checks.sh, each a visible step with its own ok/FAILED
#    line: rustfmt, clippy with warnings denied, rustdoc with warnings denied, a build of the
#    benches, the crates without default features, the declared MSRV;
# 5. prints the checks' verdicts, how many tests skipped and why (from
#    target/test-skips.log, written by the test-fixtures crate and the pytest suite), then
#    one line adding up cargo's and pytest's results ("tests: 812 passed, 0 failed, 3 ignored"; pytest's skips count as
#    ignored), and exits with the first failing status.
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

python_output="$target/python-test-output.log"
: > "$python_output"
CARGO_TARGET_DIR="$target" bash .ci/python-tests.sh "$python_output"
python_status=$?
[[ $status -eq 0 ]] && status=$python_status

checks_output="$target/checks-output.log"
: > "$checks_output"
bash .ci/checks.sh "$checks_output"
checks_status=$?
[[ $status -eq 0 ]] && status=$checks_status
echo
cat "$checks_output"

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
    END { printf "%d %d %d\n", passed, failed, ignored }' "$output" > "$target/test-counts"
# pytest's last line: "31 passed, 2 skipped in 12.3s".
python_counts=$(awk '/^(=+ )?[0-9]+ (passed|failed|skipped|errors?|deselected).* in [0-9.]+s/ {
        line = $0; p = f = s = 0
        if (match(line, /[0-9]+ passed/)) p = substr(line, RSTART, RLENGTH) + 0
        if (match(line, /[0-9]+ failed/)) f = substr(line, RSTART, RLENGTH) + 0
        if (match(line, /[0-9]+ errors?/)) f += substr(line, RSTART, RLENGTH) + 0
        if (match(line, /[0-9]+ skipped/)) s = substr(line, RSTART, RLENGTH) + 0
    }
    END { printf "%d %d %d\n", p, f, s }' "$python_output")
read -r rp rf ri < "$target/test-counts"
read -r pp pf ps <<< "$python_counts"
if [[ -s "$python_output" ]]; then
    echo "python: $pp passed, $pf failed, $ps skipped (pytest crates/polylidar-py/tests)"
fi
echo "tests: $((rp + pp)) passed, $((rf + pf)) failed, $((ri + ps)) ignored"
exit "$status"
