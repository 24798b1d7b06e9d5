#!/usr/bin/env bash
# Installs Debian package PACKAGE with apt unless COMMAND is already on
# the PATH (sudo when not root). Idempotent. Usage: apt-install.sh COMMAND PACKAGE
set -euo pipefail
command=$1
package=$2
if command -v "$command" >/dev/null 2>&1; then
    echo "apt-install: $command is already installed"
    exit 0
fi
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "apt-install: installing $package with apt"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get install -y -qq --no-install-recommends "$package" >/dev/null 2>&1 \
    || { $SUDO apt-get update -qq && $SUDO apt-get install -y -qq --no-install-recommends "$package" >/dev/null; }
command -v "$command" >/dev/null || { echo "apt-install: $command still missing after installing $package" >&2; exit 1; }
