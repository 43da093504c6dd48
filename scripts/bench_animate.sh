#!/usr/bin/env bash
# End-to-end figures of `shadow animate --format none`: wall time a frame
# (the frame loop's wall time over the frame count, two frames in flight),
# each frame's own time (the median of a run's frames), preprocessing time
# and peak memory, for the room (both strategies) and the bunny scenes from
# 11k to 893k static faces with a 5 000-triangle torus circling the bunny.
# The first 12 frames keep the torus clear of the bunny's faces as seen
# from the light (a few dozen related polygons): the paper's claim that
# frame time follows the dynamic work, not the static count. A second set
# runs the whole orbit, through the bunny's shadow.
#
#   scripts/bench_animate.sh            # everything (a few minutes on 2 cores)
#   RUNS=1 QUICK=1 scripts/bench_animate.sh
#
# Not part of CI. Quote medians; note the machine's load (printed first).
set -euo pipefail
cd "$(dirname "$0")/.."

RUNS=${RUNS:-3}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT

cargo build --profile dist -q -p shadow-cli
BIN=target/dist/shadow

echo "machine: $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg), $(date -u +%F)"

median() { sort -g | awk '{a[NR]=$1} END {print (NR%2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }

# run LABEL FRAMES ARGS...: RUNS runs; per-frame medians from the report
run() {
    local label=$1 frames=$2
    shift 2
    local fr=() mx=() pre=() mem=() rel=() wall=()
    for _ in $(seq "$RUNS"); do
        /usr/bin/time -v "$BIN" animate "$@" --frames "$frames" --format none -q \
            --report "$OUT/r.csv" -o "$OUT/frames" >"$OUT/stdout" 2>"$OUT/time"
        fr+=("$(tail -n +2 "$OUT/r.csv" | cut -d, -f12 | median)")
        mx+=("$(tail -n +2 "$OUT/r.csv" | cut -d, -f12 | sort -g | tail -1)")
        pre+=("$(sed -E 's/.*preprocessing ([0-9.]+) ms.*/\1/' "$OUT/stdout")")
        wall+=("$(sed -E 's/.*wall time a frame ([0-9.]+) ms.*/\1/' "$OUT/stdout")")
        rel+=("$(sed -E 's/.* ([0-9]+) related static polygons.*/\1/' "$OUT/stdout")")
        mem+=("$(awk -F': ' '/Maximum resident set size/ {print $2}' "$OUT/time")")
    done
    printf '| %-34s | %6s | %8.2f ms | %8.2f ms | %8.2f ms | %8.0f ms | %6s | %6.0f MB |\n' \
        "$label" "$frames" \
        "$(printf '%s\n' "${wall[@]}" | median)" \
        "$(printf '%s\n' "${fr[@]}" | median | awk '{print $1 * 1000}')" \
        "$(printf '%s\n' "${mx[@]}" | median | awk '{print $1 * 1000}')" \
        "$(printf '%s\n' "${pre[@]}" | median)" \
        "$(printf '%s\n' "${rel[@]}" | median)" \
        "$(($(printf '%s\n' "${mem[@]}" | median | cut -d. -f1) / 1024))"
}

echo
echo "| run | frames | wall a frame | frame latency (median) | slowest frame | preprocessing | related polygons a frame | peak memory |"
echo "|---|---|---|---|---|---|---|---|"
run "room, fast" 48 --scene room
run "room, paper" 48 --scene room --strategy paper
for s in bunny-11k bunny-33k bunny-99k bunny-298k bunny-893k; do
    if [[ -n "${QUICK:-}" && $s == bunny-893k ]]; then continue; fi
    run "$s + torus, 12 frames" 12 --scene "$s"
done
for s in bunny-11k bunny-99k bunny-893k; do
    if [[ -n "${QUICK:-}" && $s == bunny-893k ]]; then continue; fi
    run "$s + torus, whole orbit" 60 --scene "$s"
done
