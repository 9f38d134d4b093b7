#!/usr/bin/env bash
# Fuzzes the loaders with cargo-fuzz (libFuzzer): the OBJ/MTL loader, scene files, and the
# PNG/EXR paths. Not run by CI. Needs a nightly toolchain (`rustup toolchain install nightly`)
# and cargo-fuzz (`cargo install cargo-fuzz`).
#
#   scripts/fuzz.sh [SECONDS] [TARGET...]     default: 300 s each, every target
#
# Each target starts from the committed seeds in fuzz/seeds/<target> (fixtures and canonical
# assets) and grows its corpus in fuzz/corpus/<target> (ignored by git). A crash stops with the
# input under fuzz/artifacts/<target>/: fix it, and keep the input as a test.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-300}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(obj_mtl scene_file images)
for target in "${targets[@]}"; do
  mkdir -p "fuzz/corpus/$target"
  echo "== $target: ${seconds}s"
  cargo +nightly fuzz run --fuzz-dir fuzz "$target" "fuzz/corpus/$target" "fuzz/seeds/$target" -- \
    -max_total_time="$seconds" -max_len=262144 -rss_limit_mb=2048 -malloc_limit_mb=2048 \
    -print_final_stats=1
done
