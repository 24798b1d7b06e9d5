#!/usr/bin/env bash
# Installs the Khronos Vulkan validation layer (Debian's vulkan-validationlayers)
# for VISTA_VALIDATION=1, then checks that the loader lists it. Idempotent.
set -euo pipefail
json=/usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json
if [ -f "$json" ]; then
    echo "install-validation: the Khronos validation layer is already installed"
else
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
    echo "install-validation: installing vulkan-validationlayers with apt"
    export DEBIAN_FRONTEND=noninteractive
    $SUDO apt-get install -y -qq --no-install-recommends vulkan-validationlayers >/dev/null 2>&1 \
        || { $SUDO apt-get update -qq && $SUDO apt-get install -y -qq --no-install-recommends vulkan-validationlayers >/dev/null; }
fi
# Capture first: grep -q closing the pipe early would fail the pipeline (pipefail).
layers=$(XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp} vulkaninfo --summary 2>/dev/null || true)
if grep -q VK_LAYER_KHRONOS_validation <<<"$layers"; then
    echo "install-validation: VK_LAYER_KHRONOS_validation visible"
else
    echo "install-validation: the loader does not list VK_LAYER_KHRONOS_validation; see 'vulkaninfo'" >&2
    exit 1
fi
