#!/usr/bin/env bash
# Two comparisons the docs report, one table row per build.
#
#   benches/compare.sh rules MESH...    learned rule frequencies (the built-in
#       rules) against the same rules with every weight 1 ("uniform"):
#       vertical seams that continue into the course above (lower is
#       stronger), voxels per piece, search nodes and seconds.
#   benches/compare.sh slopes MESH...   bricks alone against bricks and
#       slopes (--slopes): bricks, slopes, voxels left out, seconds.
#
# STUDS sets the size (default 16), SEED the seed (default 1).
set -euo pipefail
what=${1:?usage: benches/compare.sh rules|slopes MESH...}
shift
studs=${STUDS:-16}
seed=${SEED:-1}
bin=target/release/brickwright
cargo build --release --quiet
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

row() { # name label dir
  python3 - "$3/report.json" "$1" "$2" "$what" <<'PY'
import json, sys
r = json.load(open(sys.argv[1])); name, label, what = sys.argv[2:5]
slopes = sum(p["count"] for p in r["parts"] if p["name"].startswith("Slope"))
seams = r["seams"]
if what == "rules":
    print(f"| {name} | {label} | {r['pieces']} | {r['voxels_per_piece']} | {seams['continued']}/{seams['seams']} = {seams['fraction']:.2f} | {r['search']['nodes']} | {r['seconds']['search']} |")
else:
    print(f"| {name} | {label} | {r['pieces']} | {r['pieces'] - slopes} | {slopes} | {r['voxels']} | {r['repairs']['dropped_unbuildable']} | {seams['fraction']:.2f} | {r['seconds']['search']} |")
PY
}

case "$what" in
rules)
  # The built-in rules, and the same rules with every weight 1.
  cp rules/default.rules "$out/learned.rules"
  awk '$1 == "rule" { $8 = 1 } $1 == "unseen" { $2 = 1 } { print }' "$out/learned.rules" >"$out/uniform.rules"
  printf '| mesh | weights | pieces | voxels/piece | seams continued | nodes | search s |\n|---|---|---|---|---|---|---|\n'
  for mesh in "$@"; do
    name=$(basename "$mesh")
    for w in learned uniform; do
      "$bin" build "$mesh" -o "$out/$name-$w" --studs "$studs" --seed "$seed" --rules "$out/$w.rules" --quiet
      row "$name" "$w" "$out/$name-$w"
    done
  done
  ;;
slopes)
  printf '| mesh | pieces from | pieces | bricks | slopes | voxels | left out | seams continued | search s |\n|---|---|---|---|---|---|---|---|---|\n'
  for mesh in "$@"; do
    name=$(basename "$mesh")
    "$bin" build "$mesh" -o "$out/$name-b" --studs "$studs" --seed "$seed" --quiet
    row "$name" "bricks" "$out/$name-b"
    "$bin" build "$mesh" -o "$out/$name-s" --studs "$studs" --seed "$seed" --slopes --quiet
    row "$name" "bricks + slopes" "$out/$name-s"
  done
  ;;
*)
  echo "usage: benches/compare.sh rules|slopes MESH..." >&2
  exit 2
  ;;
esac
