#!/usr/bin/env bash
# The pictures of docs/shadow-art.md: the GEB letters and the bunny's
# silhouettes, their hulls by `shadow art`, and each hull rendered with
# its shadows on three walls.
#
#   scripts/art_docs.sh [OUT_DIR]   (default docs/img)
set -euo pipefail
ROOT=$(realpath "$(dirname "$0")/..")
OUT=$(realpath -m "${1:-$ROOT/docs/img}")
mkdir -p "$OUT"
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
cd "$ROOT"
cargo build --release -q -p shadow-cli -p bsp-shadows --examples
BIN=$ROOT/target/release/shadow
EX=$ROOT/target/release/examples

# a hull plus three walls (x = X, y = Y, z = Z planes, spanning LO..HI),
# each facing the hull, as one OBJ
with_walls() { # HULL.obj X Y Z LO HI OUT.obj
  awk -v x="$2" -v y="$3" -v z="$4" -v lo="$5" -v hi="$6" '
    /^v / { n++; print; next } /^f / { print; next }
    END {
      printf "v %s %s %s\nv %s %s %s\nv %s %s %s\nv %s %s %s\n", x,lo,lo, x,hi,lo, x,hi,hi, x,lo,hi
      printf "f %d %d %d %d\n", n+1, n+2, n+3, n+4
      printf "v %s %s %s\nv %s %s %s\nv %s %s %s\nv %s %s %s\n", lo,y,lo, lo,y,hi, hi,y,hi, hi,y,lo
      printf "f %d %d %d %d\n", n+5, n+6, n+7, n+8
      printf "v %s %s %s\nv %s %s %s\nv %s %s %s\nv %s %s %s\n", lo,lo,z, hi,lo,z, hi,hi,z, lo,hi,z
      printf "f %d %d %d %d\n", n+9, n+10, n+11, n+12
    }' "$1" > "$7"
}

"$EX/art_letters" "$WORK/geb" 512 > /dev/null
"$BIN" art "$WORK/geb/spec.json" -o "$WORK/geb.obj" --report "$WORK/geb_report.json" \
  --images "$WORK/geb/views"
with_walls "$WORK/geb.obj" -0.25 1.25 -0.25 -0.1 1.1 "$WORK/geb_scene.obj"
"$BIN" render "$WORK/geb_scene.obj" --sun 1,0,0 --sun 0,-1,0 --sun 0,0,1 \
  --eye 1.9,-1.15,1.6 --target 0.35,0.6,0.3 --size 640x480 -o "$OUT/art_geb.png" > /dev/null

"$BIN" art "$WORK/geb/spec.json" -o "$WORK/geb_grown.obj" --optimize --images "$WORK/geb/grown"
cp "$WORK/geb/grown/view0.png" "$OUT/art_geb_g_grown.png"
"$BIN" art "$WORK/geb/spec.json" -o "$WORK/geb_moved.obj" --optimize --deform --images "$WORK/geb/moved"
cp "$WORK/geb/moved/view2.png" "$OUT/art_geb_b_deformed.png"
cp "$WORK/geb/moved/view0.png" "$OUT/art_geb_g_after_deform.png"

"$EX/art_silhouettes" "$ROOT/data/meshes/bunny.obj" "$WORK/bunny" 512 > /dev/null
"$BIN" art "$WORK/bunny/spec.json" -o "$WORK/bunny.obj" --report "$WORK/bunny_report.json"
cp "$WORK/geb/views/view2.png" "$OUT/art_geb_b.png"
echo "wrote $OUT/art_geb.png, art_geb_b.png, art_geb_g_grown.png, art_geb_b_deformed.png and"
echo "art_geb_g_after_deform.png; the bunny's report:"
cat "$WORK/bunny_report.json"
