#!/usr/bin/env bash
# The layout's scaling table: builds each mesh at several sizes (the layout
# and the verifier only: --stability off --formats ldr) and prints one row
# per run: voxels, pieces, voxels per piece, voxels left out, seams
# continued, share of 1x1s, search seconds, whole run seconds and peak
# memory. Usage: benches/measure.sh MESH... (SIZES overrides the sizes,
# default "16 24 32 48 64 96"). Needs GNU time (/usr/bin/time).
set -euo pipefail
sizes=${SIZES:-"16 24 32 48 64 96"}
bin=target/release/brickwright
cargo build --release --quiet
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
printf '| mesh | studs | voxels | pieces | voxels/piece | left out | seams continued | 1x1s | search s | run s | peak MiB |\n'
printf '|---|---|---|---|---|---|---|---|---|---|---|\n'
for mesh in "$@"; do
  for n in $sizes; do
    name=$(basename "$mesh")
    if /usr/bin/time -f '%e %M' -o "$out/time" "$bin" build "$mesh" -o "$out/$name-$n" --studs "$n" \
        --quiet --stability off --formats ldr 2>"$out/err"; then
      python3 - "$out/$name-$n/report.json" "$out/time" "$name" "$n" <<'PY'
import json, sys
r = json.load(open(sys.argv[1])); secs, mem = open(sys.argv[2]).read().split()[-2:]
q = r["quality"]
print(f"| {sys.argv[3]} | {sys.argv[4]} | {r['voxels']} | {r['pieces']} | {q['voxels_per_piece']} | {q['left_out']} "
      f"| {100 * q['seams_continued']:.1f}% | {100 * q['share_1x1']:.1f}% | {r['seconds']['search']:.2f} | {secs} | {int(mem) / 1024:.0f} |")
PY
    else
      printf '| %s | %s | failed: %s |\n' "$name" "$n" "$(tr '\n' ' ' < "$out/err")"
    fi
  done
done
