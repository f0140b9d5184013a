#!/usr/bin/env bash
# A big mesh made from a small one, timed the way a user waits: each
# triangle of MESH (an OBJ) is split in four, again and again while the
# count stays at most TRIANGLES (default 1,000,000), and the result is
# built with every output and `--stability off` by benches/outputs.sh at
# SIZES (default 38: about 900 pieces from the Stanford bunny).
# Usage: benches/big_mesh.sh MESH. Prints the triangle count and the
# outputs table row (load and voxelize are its columns).
set -euo pipefail
cd "$(dirname "$0")/.."
mesh=${1:?usage: benches/big_mesh.sh MESH.obj}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
big="$out/$(basename "${mesh%.obj}")_big.obj"
python3 - "$mesh" "$big" "${TRIANGLES:-1000000}" <<'PY'
import sys
src, dst, most = sys.argv[1], sys.argv[2], int(sys.argv[3])
verts, tris = [], []
for line in open(src):
    w = line.split()
    if not w:
        continue
    if w[0] == "v":
        verts.append(tuple(map(float, w[1:4])))
    elif w[0] == "f":
        idx = [int(t.split("/")[0]) for t in w[1:]]
        idx = [i - 1 if i > 0 else len(verts) + i for i in idx]
        tris += [(idx[0], idx[k], idx[k + 1]) for k in range(1, len(idx) - 1)]
while len(tris) * 4 <= most:
    mid, out = {}, []
    def m(a, b):
        key = (min(a, b), max(a, b))
        if key not in mid:
            verts.append(tuple((x + y) / 2 for x, y in zip(verts[a], verts[b])))
            mid[key] = len(verts) - 1
        return mid[key]
    for a, b, c in tris:
        ab, bc, ca = m(a, b), m(b, c), m(c, a)
        out += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
    tris = out
with open(dst, "w") as f:
    f.write("".join(f"v {x:.6f} {y:.6f} {z:.6f}\n" for x, y, z in verts))
    f.write("".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in tris))
print(f"{len(tris)} triangles, {len(verts)} vertices")
PY
SIZES=${SIZES:-38} benches/outputs.sh "$big"
