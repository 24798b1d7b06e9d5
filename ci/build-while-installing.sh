#!/usr/bin/env bash
# Usage: ci/build-while-installing.sh "DRIVER ..." COMMAND ARGS...
# Runs COMMAND (the build) while ci/install-DRIVER.sh runs for each DRIVER,
# in order, in the background. The installs wait on apt and the network,
# the build on the CPU, so on a fresh machine one hides the other instead of
# adding to it (issue 31: README "Build time"). The installs' output is
# printed once both have finished; exits non-zero if either failed, the
# installs' status first (a missing driver is the clearer message).
set -uo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 2 ] || { echo "usage: ci/build-while-installing.sh \"DRIVER ...\" COMMAND ARGS..." >&2; exit 2; }
drivers=$1
shift
for d in $drivers; do
    [ -f "ci/install-$d.sh" ] || { echo "build-while-installing: no ci/install-$d.sh (driver '$d')" >&2; exit 2; }
done
mkdir -p target
log=$(mktemp target/install-drivers.XXXXXX)
trap 'rm -f "$log"' EXIT
(
    set -e
    for d in $drivers; do bash "ci/install-$d.sh"; done
) </dev/null >"$log" 2>&1 &
installing=$!
"$@"
built=$?
wait "$installing"
installed=$?
cat "$log"
if [ "$installed" -ne 0 ]; then
    echo "build-while-installing: installing the drivers ($drivers) failed (exit $installed); output above" >&2
    exit "$installed"
fi
exit "$built"
