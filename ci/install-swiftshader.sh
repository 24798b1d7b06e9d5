#!/usr/bin/env bash
# Makes Google's SwiftShader Vulkan ICD visible to the Vulkan loader, then
# verifies that its adapter is listed. Debian ships it inside chromium-common
# (/usr/lib/chromium/libvk_swiftshader.so); rather than installing Chromium's
# dependencies, the package is downloaded with apt and only the driver is
# extracted to /usr/local/lib/vista-swiftshader, registered by an ICD file in
# /usr/share/vulkan/icd.d. Idempotent: a second run changes nothing. Needs
# root (or sudo) only when something is missing. Needs install-lavapipe.sh's
# Vulkan loader and vulkaninfo.
set -euo pipefail

lib_dir=/usr/local/lib/vista-swiftshader
icd=/usr/share/vulkan/icd.d/vista_swiftshader_icd.json
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

summary() {
    XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp} vulkaninfo --summary 2>/dev/null || true
}

listed() {
    # Capture first: grep -q closing the pipe early would fail the pipeline (pipefail).
    local s
    s=$(summary)
    grep -q 'SwiftShader' <<<"$s"
}

if [ -f "$icd" ] && [ -f "$lib_dir/libvk_swiftshader.so" ]; then
    echo "install-swiftshader: SwiftShader ICD already registered at $icd"
else
    so=""
    if [ -f /usr/lib/chromium/libvk_swiftshader.so ]; then
        so=/usr/lib/chromium/libvk_swiftshader.so
        echo "install-swiftshader: using chromium-common's $so"
    else
        echo "install-swiftshader: extracting libvk_swiftshader.so from Debian's chromium-common (apt-get download)"
        work=$(mktemp -d)
        trap 'rm -rf "$work"' EXIT
        (cd "$work" && { apt-get download chromium-common >/dev/null 2>&1 \
            || { $SUDO apt-get update -qq && apt-get download chromium-common >/dev/null; }; })
        dpkg -x "$work"/chromium-common_*.deb "$work/x"
        so="$work/x/usr/lib/chromium/libvk_swiftshader.so"
        [ -f "$so" ] || { echo "install-swiftshader: chromium-common holds no libvk_swiftshader.so" >&2; exit 1; }
    fi
    $SUDO mkdir -p "$lib_dir" /usr/share/vulkan/icd.d
    $SUDO install -m 0644 "$so" "$lib_dir/libvk_swiftshader.so"
    printf '{"file_format_version": "1.0.0", "ICD": {"library_path": "%s", "api_version": "1.0.5"}}\n' \
        "$lib_dir/libvk_swiftshader.so" | $SUDO tee "$icd" >/dev/null
    echo "install-swiftshader: registered $icd"
fi

if listed; then
    s=$(summary)
    echo "install-swiftshader: Vulkan adapter visible: $(grep -m1 'deviceName.*SwiftShader' <<<"$s" | sed 's/.*= //')"
else
    echo "install-swiftshader: the Vulkan loader does not list SwiftShader; see 'vulkaninfo --summary'" >&2
    exit 1
fi
