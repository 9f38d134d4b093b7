#!/usr/bin/env bash
# The portability check: `harness check` of every canonical scene under every source of
# variation the noise model knows, against the committed goldens and golden/noise.toml: the three
# backends, llvmpipe/lavapipe limited to SSE4.1 and to AVX code, 128-bit vectors, one rasterizer
# thread, a second Mesa release (bookworm-backports, in a private prefix), synthetic rounding, and
# renders recorded on other hosts (golden/evidence/). Exits non-zero when any render fails or any
# source comes above half of a limit (the self-test's bound; the check itself fails at the limit).
#
#   scripts/portability.sh           every source; installs the second Mesa first (network, once)
#   scripts/portability.sh --cheap   no download, about a minute: this machine's drivers, the
#                                    CPU-caps variants, synthetic rounding, recorded hosts (CI)
#
# After an intended change to the pictures or the metrics, `harness noise --write` re-measures
# every source and rewrites golden/noise.toml (review its diff like a golden's).
#
# The harness is built in cargo's dev profile (every crate optimised; the build the README's
# commands and `cargo test` share); HARNESS_PROFILE=release uses the release build instead.
set -euo pipefail
cd "$(dirname "$0")/.."
profile=${HARNESS_PROFILE:-dev}
case "${1:-}" in
  --cheap) exec cargo run --profile "$profile" -q -p harness -- noise --source cheap ;;
  "") ;;
  *) echo "usage: scripts/portability.sh [--cheap]" >&2; exit 2 ;;
esac
scripts/mesa-backports.sh
exec cargo run --profile "$profile" -q -p harness -- noise
