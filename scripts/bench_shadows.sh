#!/usr/bin/env bash
# End-to-end figures of `shadow shadows`: wall time and peak memory of
# whole runs (load, snap, shadows, JSON written), the median of several
# runs, from /usr/bin/time -v. Also, in the same session: one thread
# against two, Chin & Feiner's algorithm on the same scene (the baseline),
# and the exact shadows against one BVH shadow-ray pass of a megapixel's
# worth of samples (the `shade` example).
#
#   scripts/bench_shadows.sh            # everything (about 10 minutes on 2 cores)
#   RUNS=3 scripts/bench_shadows.sh     # fewer repetitions
#   QUICK=1 scripts/bench_shadows.sh    # skip the 893k-face scene and the slow baseline
#
# Not part of CI. Quote medians; note the machine's load (printed first).
set -euo pipefail
cd "$(dirname "$0")/.."

RUNS=${RUNS:-5}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT

cargo build --profile dist -q -p shadow-cli
cargo build --profile dist -q -p shadow-raster --example shade
BIN=target/dist/shadow
SHADE=target/dist/examples/shade

echo "machine: $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg), $(date -u +%F)"

# median of the numbers on stdin
median() { sort -g | awk '{a[NR]=$1} END {print (NR%2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }

# bench LABEL FACES ARGS...: RUNS runs of `shadow shadows ARGS -o OUT.json`
bench() {
    local label=$1 faces=$2
    shift 2
    local walls=() mems=() line=""
    for _ in $(seq "$RUNS"); do
        /usr/bin/time -v "$BIN" shadows "$@" -q -o "$OUT/out.json" >"$OUT/stdout" 2>"$OUT/time"
        walls+=("$(awk -F': ' '/Elapsed \(wall clock\)/ {n=split($2,t,":"); s=0; for(i=1;i<=n;i++) s=s*60+t[i]; print s}' "$OUT/time")")
        mems+=("$(awk -F': ' '/Maximum resident set size/ {print $2}' "$OUT/time")")
        line=$(head -1 "$OUT/stdout")
    done
    local wall mem
    wall=$(printf '%s\n' "${walls[@]}" | median)
    mem=$(printf '%s\n' "${mems[@]}" | median)
    local frags
    frags=$(echo "$line" | sed -E 's/.*: ([0-9]+) fragments.*/\1/')
    printf '| %-36s | %9s | %8.3f s | %7.0f MB | %6.0f B | %8s | %6.3f |\n' \
        "$label" "$faces" "$wall" "$((mem / 1024))" "$(echo "$mem * 1024 / $faces" | bc)" \
        "$frags" "$(echo "scale=4; $frags / $faces" | bc)"
}

echo
echo "| run | faces | wall (median of $RUNS) | peak memory | per face | fragments | per face |"
echo "|---|---|---|---|---|---|---|"
bench "room, default light" 496 --scene room
bench "bunny-99k, 1 light, 2 threads" 99199 --scene bunny-99k --light 4,20.6,5.9
bench "bunny-99k, 1 light, 1 thread" 99199 --scene bunny-99k --light 4,20.6,5.9 --threads 1
bench "bunny-99k, 3 lights and a sun" 99199 --scene bunny-99k --light 4,20.6,5.9 \
    --light -10.9,16.7,2 --light 17.8,9.8,-8.9 --sun 3,10,2
if [[ -z "${QUICK:-}" ]]; then
    bench "bunny-893k, 1 light" 892783 --scene bunny-893k --light 4,20.6,5.9
    RUNS=1 bench "bunny-99k, 1 light, Chin & Feiner" 99199 --scene bunny-99k \
        --light 4,20.6,5.9 --algorithm chin-feiner
fi

echo
echo "exact shadows against a BVH shadow-ray pass (1 000 000 samples), same process:"
for scene in room bunny-99k; do
    "$SHADE" "$scene" | sed 's/^/  /'
done
