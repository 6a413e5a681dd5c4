#!/usr/bin/env bash
# The static checks of CI, run by .ci/test.sh after the tests (or alone: `bash .ci/checks.sh`).
# Each check is a visible step that ends with one line, "check NAME: ok (Ns)" or
# "check NAME: FAILED (exit N, Ns)"; those lines are also appended to the file named by $1,
# for the summary. Exit 1 when any check failed, after running all of them.
#
#   fmt                  cargo fmt --all -- --check
#   clippy               cargo clippy --workspace --all-targets --all-features --locked -- -D warnings
#                        (the workspace lints of Cargo.toml, clippy.toml)
#   doc                  cargo doc --workspace --no-deps --all-features --locked, RUSTDOCFLAGS=-D warnings
#   doc-private          the same with --document-private-items (the docs of private items, which
#                        contributors read, keep their links too)
#   benches              cargo build --workspace --bench '*' --all-features --locked (dev profile: it
#                        compiles the criterion benches against the test build's dependencies; run
#                        them with `cargo bench`)
#   no-default-features  for each workspace crate that has features: cargo check -p CRATE
#                        --no-default-features --all-targets --locked; fastga's tests also run so
#                        (its k-d tree baseline and PNG export are optional)
#   fuzz-targets         cargo check --manifest-path fuzz/Cargo.toml --bins --locked: the cargo-fuzz
#                        targets (outside the workspace, run by scripts/fuzz.sh on nightly) still
#                        compile against the crates' current API
#   msrv                 the workspace's `rust-version`: when the active rustc is that version the
#                        steps above were built with it; otherwise `cargo +VERSION check` with that
#                        toolchain when rustup has it, and a failure under CI=true when it has not
set -uo pipefail
cd "$(dirname "$0")/.."
log=${1:-/dev/null}

in_ci() { [[ -n "${CI:-}" && "${CI}" != "false" && "${CI}" != "0" ]]; }

failed=0
# check NAME COMMAND...: runs COMMAND with its output shown, then the one-line verdict.
check() {
    local name=$1 start=$SECONDS rc
    shift
    echo
    echo "=== check $name: $*"
    "$@"
    rc=$?
    local line
    if [[ $rc -eq 0 ]]; then
        line="check $name: ok ($((SECONDS - start)) s)"
    else
        line="check $name: FAILED (exit $rc, $((SECONDS - start)) s)"
        failed=1
    fi
    echo "$line"
    echo "$line" >> "$log"
}

# Workspace crates that declare features, one per line.
featured_crates() {
    cargo metadata --no-deps --format-version 1 --locked |
        python3 -c 'import json, sys
for p in json.load(sys.stdin)["packages"]:
    if p["features"]:
        print(p["name"])'
}

no_default_features() {
    local crates crate rc=0
    crates=$(featured_crates) || return 1
    for crate in $crates; do
        echo "--- $crate"
        cargo check -p "$crate" --no-default-features --all-targets --locked || rc=1
    done
    echo "--- fastga tests without default features"
    cargo test -p fastga --no-default-features --locked || rc=1
    return $rc
}

msrv() {
    local msrv active
    msrv=$(sed -n 's/^rust-version *= *"\([0-9.]*\)".*/\1/p' Cargo.toml | head -n 1)
    active=$(rustc --version | awk '{ print $2 }')
    if [[ -z "$msrv" ]]; then
        echo "no rust-version in the workspace Cargo.toml" >&2
        return 1
    fi
    # "1.95" is "1.95.0".
    [[ "$msrv" =~ ^[0-9]+\.[0-9]+$ ]] && msrv="$msrv.0"
    if [[ "$active" == "$msrv" ]]; then
        echo "rust-version $msrv is the active rustc ($active): the steps above built the workspace with it"
        return 0
    fi
    if rustup toolchain list 2> /dev/null | grep -q "^$msrv"; then
        cargo "+$msrv" check --workspace --all-targets --all-features --locked
        return $?
    fi
    if in_ci; then
        echo "rustc $msrv (rust-version) is not installed and the active one is $active; CI=true, so this is a failure" >&2
        return 1
    fi
    echo "note: rustc $msrv (rust-version) is not installed (active: $active); not checked" >&2
    return 0
}

check fmt cargo fmt --all -- --check
check clippy cargo clippy --workspace --all-targets --all-features --locked -- -D warnings
check doc env RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --all-features --locked
check doc-private env RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --all-features \
    --document-private-items --locked
check benches cargo build --workspace --bench '*' --all-features --locked
check no-default-features no_default_features
check fuzz-targets cargo check --manifest-path fuzz/Cargo.toml --bins --locked
check msrv msrv
exit "$failed"
