#!/usr/bin/env bash
# Regenerates the pictures of docs/raster.md (the `dist` build of `shadow`, whose pictures `scripts/check-release.sh dist` checks).
# Each picture is `shadow compare` of exact against one method on one
# camera; the PNGs are then recompressed (zlib level 9) to keep the
# repository small.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --profile dist -p shadow-cli
S=target/dist/shadow
D=docs/img
mkdir -p "$D"
B="--scene bunny --size 400x225 --columns 2"
# the bunny's feet, close up, for peter-panning
FEET="--eye 5,4,13 --target -0.5,1,2"
$S compare $B --methods shadow-map --bias 0,0 -o $D/raster_acne.png
$S compare $B $FEET --methods shadow-map --bias 2,0 -o $D/raster_panning.png
$S compare $B --methods shadow-map --map-size 64 -o $D/raster_aliasing.png
$S compare $B --methods texture --highlight -o $D/raster_texture.png
# the eye under a chair's seat, in its shadow volume
$S compare --scene room --panel 400x225 --columns 3 --eye -2.25,-0.26,0.2 --target 1.5,1.2,0.3 --fov 70 \
  --methods stencil-zpass,stencil-zfail -o $D/raster_zpass.png
# planar shadows: a ground, a post taller than the light (anti-shadow) and
# a box under the ground (false shadow)
P=$(mktemp -d)/planar.obj
cat > "$P" <<'OBJ'
v -10 -10 0
v 10 -10 0
v 10 10 0
v -10 10 0
f 1 2 3 4
g post
v 1 -0.5 0
v 2 -0.5 0
v 2 0.5 0
v 1 0.5 0
v 1 -0.5 5
v 2 -0.5 5
v 2 0.5 5
v 1 0.5 5
f 5 8 7 6
f 9 10 11 12
f 5 6 10 9
f 6 7 11 10
f 7 8 12 11
f 8 5 9 12
g buried
v -4 -4 -3
v -2 -4 -3
v -2 -2 -3
v -4 -2 -3
v -4 -4 -1
v -2 -4 -1
v -2 -2 -1
v -4 -2 -1
f 13 16 15 14
f 17 18 19 20
f 13 14 18 17
f 14 15 19 18
f 15 16 20 19
f 16 13 17 20
OBJ
PL="$P --light 0,0,3 --eye 0,-14,12 --target 0,0,0 --size 400x300 --columns 3"
$S compare $PL --methods planar --no-clip --highlight -o $D/raster_planar_naive.png
$S compare $PL --methods planar --highlight -o $D/raster_planar.png
$S compare --scene room --panel 320x180 --columns 4 --highlight --report $D/raster_room.csv -o $D/raster_room.png
$S lines --scene room --size 800x450 --hidden -o $D/raster_lines.svg
python3 - "$D"/raster_*.png <<'PY'
import struct, sys, zlib
for path in sys.argv[1:]:
    data = open(path, 'rb').read()
    out, idat, pos = [data[:8]], b'', 8
    chunks = []
    while pos < len(data):
        n = struct.unpack('>I', data[pos:pos + 4])[0]
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + n]
        pos += 12 + n
        if kind == b'IDAT':
            idat += body
        else:
            chunks.append((kind, body))
    def chunk(kind, body):
        return struct.pack('>I', len(body)) + kind + body + struct.pack('>I', zlib.crc32(kind + body))
    for kind, body in chunks:
        if kind == b'IEND':
            out.append(chunk(b'IDAT', zlib.compress(zlib.decompress(idat), 9)))
        out.append(chunk(kind, body))
    open(path, 'wb').write(b''.join(out))
PY
ls -l $D/raster_*
