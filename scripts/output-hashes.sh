#!/usr/bin/env bash
# Runs a fixed set of `shadow` commands and prints a SHA-256 of every file
# they write (timing columns of CSV reports left out), one line each:
#
#   scripts/output-hashes.sh BINARY [SCALE] > hashes.txt
#
# Two binaries that print the same lines wrote the same bytes. Uses:
# - the release binary against the test profile's (`.ci/run`): the
#   optimiser must not change an answer (a miscompile in the fat-LTO build
#   once drew wrong shadows; docs/llvm-clip-miscompile/README.md);
# - a build before a refactoring against one after it.
# The commands are the README's, and the benches' scenes at a small size;
# SCALE=full adds the bunny-99k scenes the docs' figures use.
set -euo pipefail
BIN=$(realpath "$1")
SCALE=${2:-small}
ROOT=$(realpath "$(dirname "$0")/..")
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
cd "$OUT"

run() { "$BIN" "$@" > /dev/null; }
# a CSV without the columns whose header names a time
untimed() {
  awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) keep[i] = ($i !~ /(^ms$|^t_|_ms$|_s$|time)/) }
           { line = ""; for (i = 1; i <= NF; i++) if (keep[i]) line = line (line == "" ? "" : ",") $i; print line }' "$1"
}

SPHERE=$ROOT/data/meshes/pyvista_sphere.obj
# the sphere moved by a third of its diameter: the two overlap
awk '$1 == "v" { printf "v %.17g %.17g %.17g\n", $2 + 0.37, $3 + 0.21, $4 + 0.1; next } { print }' \
  "$SPHERE" > moved_sphere.obj

run shadows --scene room -o room.svg
run shadows --scene room -o room.json
run shadows --scene room -o room.obj
run shadows --scene room --light 0.9,0.3,2.45 --sun 0.3,-0.2,1 -o room_two.json
run shadows --scene bunny-11k --light 4,20.6,5.9 -o bunny.json
run shadows --scene bunny-11k --light 4,20.6,5.9 --light -10.9,16.7,2 --sun 3,10,2 -o bunny.obj
run view --scene room --eye 3.3,-7.4,4.3 -o view.svg
run demo -o demo.svg
run csg union "$SPHERE" moved_sphere.obj -o union.obj
run csg intersection "$SPHERE" moved_sphere.obj -o inter.stl
run csg difference "$SPHERE" moved_sphere.obj -o diff.obj
run render --scene room --size 320x180 -o render_exact.png --mask render_exact.pgm
run render --scene bunny --size 320x180 --sun 1,2,3 --light 4,20.6,5.9 -o render_bunny.png \
  --mask render_bunny.pgm
for m in shadow-map stencil-zpass stencil-zfail planar texture raycast; do
  run render --scene room --size 320x180 --method "$m" -o "render_$m.png"
done
run compare --scene room --panel 320x180 -o cmp_room.png --report cmp_room.csv
run compare --scene bunny --panel 320x180 -o cmp_bunny.png --report cmp_bunny.csv
run lines --scene room -o lines.svg
# soft lights in pictures, and shadow art
SOFT="0.7,0.1,2.45;0.7,0.5,2.45;1.1,0.5,2.45;1.1,0.1,2.45"
run render --scene room --size 320x180 --area-light "$SOFT" -o render_soft.png
run shadows --scene room --area-light "$SOFT" --sun-disc 0.3,-0.2,1:2 -o soft.json
run shadows --scene room --area-light "$SOFT" -o soft.obj
run render --scene room --size 320x180 --area-light "$SOFT" --sun-disc 0.3,-0.2,1:2 \
  --method pcss -o render_pcss.png
run compare --scene room --panel 160x90 --area-light "$SOFT" --methods sampled:4,pcss \
  -o cmp_soft.png --report cmp_soft.csv
printf 'P2\n4 4\n255\n255 255 255 255\n255 0 0 255\n255 0 255 255\n255 255 255 255\n' > sq.pgm
printf 'P2\n4 4\n255\n255 0 0 255\n255 0 0 255\n255 255 255 255\n255 255 255 255\n' > bar.pgm
printf '%s\n' '{"views": [' \
  '{"image": "sq.pgm", "light": {"sun": [0, 0, 1]}, "plane": {"origin": [0, 0, 0], "u": [1, 0, 0], "v": [0, 1, 0]}},' \
  '{"image": "bar.pgm", "light": {"point": [-9, 2, 1]}, "plane": {"origin": [5, 0, 0], "u": [0, 1, 0], "v": [0, 0, 1]}}' \
  '], "bounds": [[0, 0, 0], [4, 4, 3]]}' > art.json
run art art.json -o art.obj --report art_report.json --images art_views
run art art.json -o art_grown.obj --optimize --report art_grown.json
run sunhours --scene room --lat 51.5 --lon -0.12 --date 2026-03-21 --to 2026-03-23 --every 2 \
  --step 30 -o hours.csv
rm sq.pgm bar.pgm art.json
run animate --scene room --frames 3 --format png --width 320 --height 180 -o anim_png \
  --report anim.csv
run animate --scene room --frames 2 --format json -o anim_json --strategy paper
run animate --scene room --frames 2 --format svg -o anim_svg
if [[ $SCALE == full ]]; then
  # the benches' scenes
  run shadows --scene bunny-99k --light 4,20.6,5.9 -o bunny99k.json
  run shadows --scene bunny-99k --light 4,20.6,5.9 --light -10.9,16.7,2 \
    --light 17.8,9.8,-8.9 --sun 3,10,2 -o bunny99k_four.obj
  awk '$1 == "v" { printf "v %.17g %.17g %.17g\n", $2 + 0.01, $3 + 0.02, $4 + 0.005; next } { print }' \
    "$ROOT/data/meshes/bunny.obj" > moved_bunny.obj
  run csg union "$ROOT/data/meshes/bunny.obj" moved_bunny.obj -o bunny_union.obj
  run csg difference "$ROOT/data/meshes/bunny.obj" moved_bunny.obj -o bunny_diff.stl
  run animate --scene bunny-11k --frames 4 --format png --width 320 --height 180 \
    -o anim_bunny --report anim_bunny.csv
  run compare --scene bunny-99k --panel 960x540 -o cmp_b99k.png --report cmp_b99k.csv
fi

# (compare's panels print each method's time: its report stands for it)
for f in $(find . -type f ! -name 'moved_*.obj' ! -name 'cmp_*.png' | sort); do
  case $f in
    *.csv) echo "$(untimed "$f" | sha256sum | cut -c1-16)  ${f#./}" ;;
    *) echo "$(sha256sum < "$f" | cut -c1-16)  ${f#./}" ;;
  esac
done
