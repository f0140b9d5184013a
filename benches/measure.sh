#!/usr/bin/env bash
# Builds each mesh at several sizes and prints one table row per run:
# voxels, pieces, voxels per piece, search nodes and backtracks, seconds per
# stage, peak memory. Usage: benches/measure.sh [SIZES] MESH...
# (SIZES defaults to "16 32 48"). Needs GNU time (/usr/bin/time).
set -euo pipefail
sizes=${SIZES:-"16 32 48"}
bin=target/release/brickwright
cargo build --release --quiet
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
printf '| mesh | studs | voxels | pieces | voxels/piece | left out | nodes | backtracks | fallbacks | load s | voxelize s | search s | verify s | write s | peak MiB |\n'
printf '|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n'
for mesh in "$@"; do
  for n in $sizes; do
    name=$(basename "$mesh")
    if /usr/bin/time -f '%M' -o "$out/mem" "$bin" build "$mesh" -o "$out/$name-$n" --studs "$n" --quiet --time-budget 300 2>"$out/err"; then
      python3 - "$out/$name-$n/report.json" "$out/mem" "$name" "$n" <<'PY'
import json, sys
r = json.load(open(sys.argv[1])); mem = int(open(sys.argv[2]).read().split()[-1]) / 1024
s, q = r["seconds"], r["search"]
print(f"| {sys.argv[3]} | {sys.argv[4]} | {r['voxels']} | {r['pieces']} | {r['voxels_per_piece']} | {r['repairs']['dropped_unbuildable']} | {q['nodes']} | {q['backtracks']} | {q['fallbacks']} | {s['load']} | {s['voxelize']} | {s['search']} | {s['verify']} | {s['write']} | {mem:.0f} |")
PY
    else
      printf '| %s | %s | failed: %s |\n' "$name" "$n" "$(tr '\n' ' ' < "$out/err")"
    fi
  done
done
