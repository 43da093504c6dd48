#!/usr/bin/env bash
# Tests what ships: the `shadow` binary of a release profile, built as the
# README's first command builds it, against the one the tests built.
#
#   scripts/check-release.sh           # --release (the README's command; CI)
#   scripts/check-release.sh dist      # --profile dist (the docs' figures)
#
# 1. The CLI's end-to-end suite (shadow-cli/tests) runs again with
#    SHADOW_BIN set to the release binary: the same expected numbers, the
#    figures docs/raster.md quotes among them.
# 2. scripts/output-hashes.sh runs a fixed set of commands with both
#    binaries: every file they write must be the same bytes. Rust's
#    floating point does not depend on the optimisation level, so any
#    difference is a miscompile or a race (docs/llvm-clip-miscompile/).
#
# Run `cargo test --workspace` first (CI does): it builds the test binary
# and the test profile's `shadow`.
set -euo pipefail
cd "$(dirname "$0")/.."
PROFILE=${1:-release}
if [[ $PROFILE == release ]]; then
  cargo build --release -p shadow-cli
else
  cargo build --profile "$PROFILE" -p shadow-cli
fi
SHIPPED=target/$PROFILE/shadow
TESTED=target/debug/shadow

# the CLI suite's test binary, as `cargo test --workspace` built it
SUITE=$(cargo test --workspace --no-run --message-format=json 2> /dev/null |
  python3 -c '
import json, sys
for line in sys.stdin:
    m = json.loads(line)
    t = m.get("target", {})
    if m.get("reason") == "compiler-artifact" and m.get("executable") \
            and m["package_id"].find("shadow-cli") >= 0 and t.get("kind") == ["test"]:
        print(m["executable"])')
[[ -x $SUITE && -x $TESTED ]] || { echo "run cargo test --workspace first" >&2; exit 1; }

echo "-- the CLI suite against $SHIPPED"
SHADOW_BIN=$(realpath "$SHIPPED") "$SUITE" -q

echo "-- the same bytes from $SHIPPED and $TESTED"
A=$(mktemp) B=$(mktemp)
trap 'rm -f "$A" "$B"' EXIT
scripts/output-hashes.sh "$SHIPPED" > "$A"
scripts/output-hashes.sh "$TESTED" > "$B"
if ! diff "$A" "$B"; then
  echo "the $PROFILE binary writes other bytes than the test build (above: $PROFILE < > test)" >&2
  exit 1
fi
echo "$(wc -l < "$A") outputs identical"
