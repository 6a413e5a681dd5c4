#!/usr/bin/env bash
# Installs Mesa's software Vulkan driver (lavapipe) so that the wgpu GPU tests of
# mesh-smooth-gpu run on the CPU where no GPU exists. Idempotent and non-interactive:
# it does nothing when a lavapipe ICD manifest is already installed, and never upgrades
# packages that are already there. Exits 1 (without changing anything) where it cannot
# install: not root and no passwordless sudo, or no apt-get.
set -euo pipefail

icd_dir=/usr/share/vulkan/icd.d

has_lavapipe() {
    compgen -G "${icd_dir}/lvp_icd*.json" > /dev/null
}

if has_lavapipe; then
    echo "install-gpu-deps: lavapipe already installed ($(ls "${icd_dir}"/lvp_icd*.json | head -n 1))"
    exit 0
fi

if ! command -v apt-get > /dev/null; then
    echo "install-gpu-deps: no apt-get; install Mesa's Vulkan drivers (lavapipe) with your package manager" >&2
    exit 1
fi
if [ "$(id -u)" -eq 0 ]; then
    as_root=()
elif command -v sudo > /dev/null && sudo -n true 2> /dev/null; then
    as_root=(sudo -n)
else
    echo "install-gpu-deps: not root and no passwordless sudo; cannot install mesa-vulkan-drivers" >&2
    exit 1
fi

export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update
"${as_root[@]}" apt-get install -y --no-install-recommends --no-upgrade mesa-vulkan-drivers libvulkan1

if ! has_lavapipe; then
    echo "install-gpu-deps: mesa-vulkan-drivers installed but no lavapipe ICD under ${icd_dir}" >&2
    exit 1
fi
echo "install-gpu-deps: lavapipe installed ($(ls "${icd_dir}"/lvp_icd*.json | head -n 1))"
