#!/usr/bin/env python3
"""Finds the IR shape behind the clip_ring miscompile (README.md here) in
the optimised LLVM IR of a program (`--emit=llvm-ir` of the final, LTO
compilation): in one block, a phi of a small vector and a phi of a scalar whose every incoming
value is lane 0 of the vector phi's incoming value on the same edge."""
import re, sys
from collections import defaultdict
define = re.compile(r'^define .*@("?[^"(]+"?)\(')
phi = re.compile(r'^\s*(%[\w.]+) = phi (?:fast |nnan |ninf |nsz |arcp |contract |afn |reassoc )*(<\d+ x \w+>|double|float|i64|i32) (.*)$')
ext = re.compile(r'^\s*(%[\w.]+) = extractelement (<\d+ x \w+>) (%[\w.]+), i(?:32|64) 0\b')
inc = re.compile(r'\[ ([^,]+), (%[\w.]+) \]')
fn = None; lane0 = {}; block_phis = []; hits = []
def check():
    vec = [(n, t, dict((b, v) for v, b in vals)) for n, t, vals in block_phis if t.startswith('<')]
    sca = [(n, t, dict((b, v) for v, b in vals)) for n, t, vals in block_phis if not t.startswith('<')]
    for vn, vt, vin in vec:
        elem = vt.split(' x ')[1].rstrip('>')
        for sn, st, sin in sca:
            if st != elem or set(sin) != set(vin):
                continue
            if all(lane0.get(sin[b]) == vin[b] for b in vin):
                hits.append((fn, vn, sn))
for line in open(sys.argv[1], errors="replace"):
    m = define.match(line)
    if m:
        fn = m.group(1); lane0 = {}; block_phis = []; continue
    if fn is None:
        continue
    if re.match(r'^\S+:\s', line) or line.startswith('}'):
        check(); block_phis = []
        if line.startswith('}'):
            fn = None
        continue
    m = ext.match(line)
    if m:
        lane0[m.group(1)] = m.group(3)
    m = phi.match(line)
    if m:
        block_phis.append((m.group(1), m.group(2), [(v.strip(), b) for v, b in inc.findall(m.group(3))]))
for h in hits:
    print(*h)
print(len(hits), 'vector phis with a lane-0 scalar twin', file=sys.stderr)
