#!/usr/bin/env bash
# Runs every test of the workspace, the GPU ones included (on Mesa's software Vulkan
# driver where no GPU exists). Installs what the tests need first. This is the README's
# test command and what CI runs.
set -euo pipefail
cd "$(dirname "$0")/.."

bash .ci/install-gpu-deps.sh

cargo test --workspace --all-features --locked
