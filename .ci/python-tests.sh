#!/usr/bin/env bash
# The Python package's tests, run by .ci/test.sh after the cargo tests: builds the
# polylidar_rs wheel with maturin (dev profile, --locked) into a fresh virtual environment
# under the cargo target folder ($CARGO_TARGET_DIR or target/py-venv), installs it with
# numpy, pytest, shapely and dask[distributed] from PyPI, and runs pytest on
# crates/polylidar-py/tests with the `polylidar` command built by cargo (for the CLI
# comparison tests). Its output is
# also written to the file named by $1, for the summary.
#
# No Python ≥ 3.9, no venv module or no package index: a note, and the tests are skipped
# (exit 0); under CI=true that is a failure (exit 1). A failing build or test: exit 1.
set -uo pipefail
cd "$(dirname "$0")/.."
log=${1:-/dev/null}

in_ci() { [[ -n "${CI:-}" && "${CI}" != "false" && "${CI}" != "0" ]]; }

target=${CARGO_TARGET_DIR:-target}
[[ "$target" = /* ]] || target="$PWD/$target"
venv="$target/py-venv"

skip() {
    if in_ci; then
        echo "python tests: $1; CI=true, so this is a failure" | tee -a "$log" >&2
        exit 1
    fi
    echo "note: Python tests skipped: $1" | tee -a "$log" >&2
    exit 0
}

echo
echo "== Python package (crates/polylidar-py): wheel into a fresh venv, then pytest =="
python=""
for candidate in "${PYTHON:-}" python3 python; do
    [[ -n "$candidate" ]] || continue
    if command -v "$candidate" >/dev/null 2>&1 &&
        "$candidate" -c 'import sys; sys.exit(sys.version_info < (3, 9))' 2>/dev/null; then
        python=$candidate
        break
    fi
done
[[ -n "$python" ]] || skip "no Python 3.9 or newer found (set PYTHON=/path/to/python3)"

rm -rf "$venv"
"$python" -m venv "$venv" >/dev/null 2>&1 ||
    skip "$python -m venv failed (on Debian/Ubuntu install python3-venv)"
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
    "maturin>=1.9.4,<2" numpy pytest shapely "dask[distributed]" >/dev/null 2>&1 ||
    skip "pip could not install maturin, numpy, pytest, shapely and dask[distributed] (no package index?)"

wheels="$target/py-wheels"
rm -rf "$wheels"
if ! "$venv/bin/maturin" build --locked -m crates/polylidar-py/Cargo.toml -o "$wheels" \
    -i "$venv/bin/python" 2>&1 | tail -n 3; then
    echo "python tests: the wheel did not build" | tee -a "$log" >&2
    exit 1
fi
wheel=$(ls "$wheels"/polylidar_rs-*.whl 2>/dev/null | head -n 1)
[[ -n "$wheel" ]] || { echo "python tests: no wheel in $wheels" | tee -a "$log" >&2; exit 1; }
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check --no-deps "$wheel" || exit 1

cli="$target/debug/polylidar"
[[ -x "$cli" ]] || cli=""
# Run from the tests' folder so that `import polylidar_rs` is the installed wheel.
(cd crates/polylidar-py/tests &&
    POLYLIDAR_CLI="$cli" "$venv/bin/python" -m pytest -q -p no:cacheprovider .) 2>&1 | tee -a "$log"
exit "${PIPESTATUS[0]}"
