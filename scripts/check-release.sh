#!/usr/bin/env bash
# Tests what ships: the `shadow` binary of a release profile, built as the
# README's first command builds it.
#
#   scripts/check-release.sh           # --release (the README's command; CI)
#   scripts/check-release.sh dist      # --profile dist (the docs' figures)
#
# 1. The CLI's end-to-end suite (shadow-cli/tests) runs with SHADOW_BIN
#    set to the shipped binary: the same expected numbers, the figures
#    docs/raster.md quotes among them. (`cargo test --workspace --release`,
#    the README's test command, runs the suite against the release build
#    already; this run checks the binary `cargo build` makes, which may
#    differ from the test build's in the features of its dependencies;
#    when `cargo build` finds nothing to rebuild, the suite ran against
#    these very bytes already, and is not run again.)
# 2. For a profile other than release: scripts/output-hashes.sh runs a
#    fixed set of commands with that binary and with the release one, and
#    every file they write must be the same bytes. Rust's floating point
#    does not depend on the optimisation settings, so any difference is a
#    miscompile or a race (docs/llvm-clip-miscompile/).
#
# Run `cargo test --workspace --release` first (CI does): it builds the
# suite's test binary.
set -euo pipefail
cd "$(dirname "$0")/.."
PROFILE=${1:-release}
if [[ $PROFILE == release ]]; then
  # the tests' build made target/release/shadow already; the README's
  # build must find nothing to do (shadow-cli's Cargo.toml turns on the
  # features the tests' dev-dependencies add), or the tests ran another
  # binary than the one that ships
  BEFORE=$(sha256sum target/release/shadow 2> /dev/null || true)
  cargo build --release -p shadow-cli
  if [[ -n $BEFORE && $BEFORE != $(sha256sum target/release/shadow) ]]; then
    echo "cargo build --release rebuilt the binary the tests ran: the two builds' dependency features differ (see shadow-cli/Cargo.toml)" >&2
    exit 1
  fi
  if [[ -n $BEFORE && ${CHECK_RELEASE_AGAIN:-} != 1 ]]; then
    # the same bytes as the binary `cargo test --workspace --release` ran
    # its CLI suite against: running the suite again would test nothing
    # new (CHECK_RELEASE_AGAIN=1 runs it anyway)
    echo "-- target/release/shadow is the binary the tests ran: nothing rebuilt"
    exit 0
  fi
else
  cargo build --profile "$PROFILE" -p shadow-cli
fi
SHIPPED=target/$PROFILE/shadow

# the CLI suite's test binary, as `cargo test --workspace --release` built it
SUITE=$(cargo test --workspace --release --no-run --message-format=json 2> /dev/null |
  python3 -c '
import json, sys
for line in sys.stdin:
    m = json.loads(line)
    t = m.get("target", {})
    if m.get("reason") == "compiler-artifact" and m.get("executable") \
            and m["package_id"].find("shadow-cli") >= 0 and t.get("kind") == ["test"]:
        print(m["executable"])')
[[ -x $SUITE ]] || { echo "run cargo test --workspace --release first" >&2; exit 1; }

echo "-- the CLI suite against $SHIPPED"
SHADOW_BIN=$(realpath "$SHIPPED") "$SUITE" -q

if [[ $PROFILE != release ]]; then
  cargo build --release -p shadow-cli
  echo "-- the same bytes from $SHIPPED and target/release/shadow"
  A=$(mktemp) B=$(mktemp)
  trap 'rm -f "$A" "$B"' EXIT
  scripts/output-hashes.sh "$SHIPPED" > "$A"
  scripts/output-hashes.sh target/release/shadow > "$B"
  if ! diff "$A" "$B"; then
    echo "the $PROFILE binary writes other bytes than the release build (above: $PROFILE < > release)" >&2
    exit 1
  fi
  echo "$(wc -l < "$A") outputs identical"
fi
