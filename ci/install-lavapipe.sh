#!/usr/bin/env bash
# Installs Mesa's lavapipe (software Vulkan) and the Vulkan loader when they
# are missing, then verifies that a Vulkan CPU adapter is visible.
# Idempotent: a second run installs nothing. Needs root (or sudo) only when
# something is missing. Debian/Ubuntu (apt).
set -euo pipefail

have_lavapipe() {
    ldconfig -p 2>/dev/null | grep -q 'libvulkan\.so\.1' || return 1
    ls /usr/share/vulkan/icd.d/lvp_icd*.json >/dev/null 2>&1 || return 1
    command -v vulkaninfo >/dev/null 2>&1 || return 1
}

if have_lavapipe; then
    echo "install-lavapipe: lavapipe and the Vulkan loader are already installed"
else
    echo "install-lavapipe: installing mesa-vulkan-drivers, libvulkan1 and vulkan-tools with apt"
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then
        command -v sudo >/dev/null || { echo "install-lavapipe: need root or sudo to apt-get install" >&2; exit 1; }
        SUDO="sudo"
    fi
    export DEBIAN_FRONTEND=noninteractive
    $SUDO apt-get update -qq
    $SUDO apt-get install -y -qq --no-install-recommends mesa-vulkan-drivers libvulkan1 vulkan-tools >/dev/null
    have_lavapipe || { echo "install-lavapipe: install finished but lavapipe is still not visible" >&2; exit 1; }
fi

# Verify: the Vulkan loader must enumerate a CPU-type device (lavapipe).
icd=$(ls /usr/share/vulkan/icd.d/lvp_icd*.json | head -n 1)
echo "install-lavapipe: lavapipe ICD at $icd"
summary=$(XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp} vulkaninfo --summary 2>/dev/null || true)
# By name: other CPU drivers (SwiftShader) may be listed first.
if grep -q 'deviceName *= *llvmpipe' <<<"$summary"; then
    echo "install-lavapipe: Vulkan adapter visible: $(grep -m1 'deviceName *= *llvmpipe' <<<"$summary" | sed 's/.*= //')"
else
    echo "install-lavapipe: the Vulkan loader does not list lavapipe (device 'llvmpipe'); see 'vulkaninfo --summary'" >&2
    exit 1
fi
