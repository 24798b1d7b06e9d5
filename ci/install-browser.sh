#!/usr/bin/env bash
# Installs Debian's chromium when it is missing, then verifies that headless
# Chromium exposes a WebGPU adapter on SwiftShader (the browser backend:
# Tint compiles, Dawn runs). Idempotent: a second run installs nothing.
# Needs root (or sudo) only when something is missing. Debian/Ubuntu (apt).
set -euo pipefail

bin=/usr/lib/chromium/chromium
if [ -x "$bin" ]; then
    echo "install-browser: chromium is already installed"
else
    echo "install-browser: installing chromium with apt"
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then
        command -v sudo >/dev/null || { echo "install-browser: need root or sudo to apt-get install" >&2; exit 1; }
        SUDO="sudo"
    fi
    export DEBIAN_FRONTEND=noninteractive
    $SUDO apt-get install -y -qq --no-install-recommends chromium >/dev/null 2>&1 \
        || { $SUDO apt-get update -qq && $SUDO apt-get install -y -qq --no-install-recommends chromium >/dev/null; }
    [ -x "$bin" ] || { echo "install-browser: install finished but $bin is missing" >&2; exit 1; }
fi
echo "install-browser: $("$bin" --version 2>/dev/null)"

# Verify: a page asks for a WebGPU adapter with the flags vista passes.
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cat >"$work/probe.html" <<'HTML'
<!doctype html><pre id=o>no answer</pre><script>
(async () => {
  const o = document.getElementById('o');
  try {
    const a = navigator.gpu && await navigator.gpu.requestAdapter();
    o.textContent = a ? 'webgpu adapter: ' + a.info.vendor + ' ' + a.info.architecture : 'no webgpu adapter';
  } catch (e) { o.textContent = 'webgpu error: ' + e; }
})();
</script>
HTML
out=$(timeout 60 "$bin" --headless --no-sandbox --disable-gpu-sandbox --enable-unsafe-webgpu \
    --use-webgpu-adapter=swiftshader --virtual-time-budget=5000 --user-data-dir="$work/profile" \
    --dump-dom "file://$work/probe.html" 2>/dev/null || true)
line=$(grep -o 'webgpu adapter: [^<]*\|no webgpu adapter\|webgpu error: [^<]*\|no answer' <<<"$out" | head -n 1)
if grep -q 'swiftshader' <<<"$line"; then
    echo "install-browser: headless Chromium's $line"
else
    echo "install-browser: headless Chromium gave no SwiftShader WebGPU adapter (${line:-no output})" >&2
    exit 1
fi
