#!/usr/bin/env bash
# examples/harness-crate: a crate outside vista's workspace (its own
# [workspace], vista as a path dependency) whose tests/golden.rs is only
# `vista::harness::main()`. Its golden cases run inside its own `cargo test`,
# each a test named golden::<kernel>::<case> that libtest's arguments select.
# It shares vista's target directory, so the third-party crates build once.
set -euo pipefail
cd "$(dirname "$0")/../examples/harness-crate"
CARGO_TARGET_DIR="$(cd ../.. && pwd)/target"
export CARGO_TARGET_DIR
cargo=${CARGO:-cargo}
list=$("$cargo" test -q --test golden -- --list)
for t in golden::glow::glow golden::glow::glow-blue; do
    echo "$list" | grep -qx "$t: test" || { echo "$list"; echo "harness-example: --list lacks $t"; exit 1; }
done
"$cargo" test --test golden
one=$("$cargo" test -q --test golden -- --exact golden::glow::glow-blue 2>&1)
echo "$one" | grep -q "1 passed; 0 failed; 0 ignored; 0 measured; 1 filtered out" ||
    { echo "$one"; echo "harness-example: --exact did not select one case"; exit 1; }
[ -f target/vista-report/index.html ] || { echo "harness-example: no report in examples/harness-crate/target/vista-report"; exit 1; }
echo "harness-example: the crate's own cargo test ran its 2 golden cases through vista::harness::main()"
