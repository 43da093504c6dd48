#!/usr/bin/env bash
# Peak memory per input face of each command on a large built-in scene, so
# that a user can tell what an input of 10M faces needs; fails if a command
# takes more than its bound (bytes per face, the figures of
# docs/benchmarks.md with a margin).
#
#   scripts/bench_memory.sh [BINARY] [SCENE]     # default: target/release/shadow bunny-893k
set -euo pipefail
BIN=$(realpath "${1:-target/release/shadow}")
SCENE=${2:-bunny-893k}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
faces=$("$BIN" stats --scene "$SCENE" -q | awk '/^faces:/ { print $2 + 0 }')
# a UV sphere pair of about the same number of triangles, for csg (the
# second rotated 5 degrees about (1, 2, 3) and moved, as bsp_fixtures'
# sphere_pair)
python3 - "$OUT" "$faces" <<'PY'
import math, sys
out, faces = sys.argv[1], int(sys.argv[2])
n = max(8, int(math.sqrt(faces / 4)))
ax = [c / math.sqrt(14) for c in (1, 2, 3)]
ca, sa = math.cos(math.radians(5)), math.sin(math.radians(5))
def rot(v):  # Rodrigues
    d = sum(a * b for a, b in zip(ax, v))
    c = [ax[1] * v[2] - ax[2] * v[1], ax[2] * v[0] - ax[0] * v[2], ax[0] * v[1] - ax[1] * v[0]]
    return [v[k] * ca + c[k] * sa + ax[k] * d * (1 - ca) for k in range(3)]
for name, off, turn in (("a", (0, 0, 0), False), ("b", (0.3, 0.1, 0.05), True)):
    def v(p):
        p = rot(p) if turn else p
        return "v %r %r %r\n" % tuple(p[k] + off[k] for k in range(3))
    with open(f"{out}/{name}.obj", "w") as o:
        o.write(v([0, 0, 1]))
        for i in range(1, n):
            t = math.pi * i / n
            for j in range(n):
                p = 2 * math.pi * j / n
                o.write(v([math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)]))
        o.write(v([0, 0, -1]))
        idx = lambda i, j: 2 + (i - 1) * n + j % n
        for j in range(n):
            o.write("f 1 %d %d\n" % (idx(1, j), idx(1, j + 1)))
        for i in range(1, n - 1):
            for j in range(n):
                a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
                o.write("f %d %d %d\nf %d %d %d\n" % (a, b, c, a, c, d))
        s = 2 + (n - 1) * n
        for j in range(n):
            o.write("f %d %d %d\n" % (s, idx(n - 1, j + 1), idx(n - 1, j)))
PY
status=0
measure() { # BOUND FACES ARGS...: peak bytes per face, against BOUND
  local bound=$1 n=$2
  shift 2
  if ! /usr/bin/time -f "%M" -o "$OUT/kib" "$BIN" "$@" -q > /dev/null 2> "$OUT/err"; then
    printf '%-60s failed: %s\n' "$*" "$(tail -1 "$OUT/err")"
    status=1
    return
  fi
  local per=$(( $(tail -1 "$OUT/kib") * 1024 / n ))
  local verdict=ok
  if (( per > bound )); then verdict="OVER $bound"; status=1; fi
  printf '%-60s %6d bytes/face  %s\n' "$*" "$per" "$verdict"
}
measure 2000 "$faces" shadows --scene "$SCENE" -o "$OUT/s.json"
measure 2000 "$faces" shadows --scene "$SCENE" -o "$OUT/s.obj"
measure 3500 "$faces" render --scene "$SCENE" --size 640x360 -o "$OUT/r.png"
sphere=$(grep -c '^f' "$OUT/a.obj")
measure 1000 $((2 * sphere)) csg union "$OUT/a.obj" "$OUT/b.obj" -o "$OUT/u.obj"
exit $status
