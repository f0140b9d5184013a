#!/usr/bin/env bash
# Whole runs of the release binary, every output, timed the way a user
# waits: builds each mesh at several sizes with every format and
# `--stability off` (so the output stages are measured apart from the
# stability stage) and prints one row per run: pieces, step pictures,
# booklet pages, the seconds of each stage from report.json (rules, load,
# voxelize, search + verify, render, booklet, write), the whole run's
# wall-clock seconds and peak memory, and the cost of one step picture
# (render seconds / pictures) and of one booklet page (booklet seconds /
# pages), in milliseconds.
# Usage: benches/outputs.sh MESH... (SIZES overrides the sizes, default
# "16 24 32 48 64"; BIN the binary, default target/release/brickwright,
# built first unless BIN is set). Needs GNU time (/usr/bin/time).
set -euo pipefail
sizes=${SIZES:-"16 24 32 48 64"}
if [ -z "${BIN:-}" ]; then
  cargo build --release --quiet
fi
bin=${BIN:-target/release/brickwright}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
printf '| mesh | studs | pieces | pictures | pages | rules | load | voxelize | search | render | booklet | write | run s | peak MiB | ms/picture | ms/page |\n'
printf '|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n'
for mesh in "$@"; do
  for n in $sizes; do
    name=$(basename "$mesh")
    if /usr/bin/time -f '%e %M' -o "$out/time" "$bin" build "$mesh" -o "$out/$name-$n" --studs "$n" \
        --quiet --stability off 2>"$out/err"; then
      python3 - "$out/$name-$n" "$out/time" "$name" "$n" <<'PY'
import json, os, sys
d = sys.argv[1]
r = json.load(open(os.path.join(d, "report.json")))
secs, mem = open(sys.argv[2]).read().split()[-2:]
s = r["seconds"]
pictures = len([f for f in os.listdir(os.path.join(d, "steps")) if f.endswith(".png")])
pages = r.get("booklet_pages") or 0
per_picture = 1000 * s["render"] / pictures if pictures else 0
per_page = 1000 * s["booklet"] / pages if pages else 0
print(f"| {sys.argv[3]} | {sys.argv[4]} | {r['pieces']} | {pictures} | {pages} | {s['rules']:.2f} | {s['load']:.2f} "
      f"| {s['voxelize']:.2f} | {s['search'] + s['verify']:.2f} | {s['render']:.2f} | {s['booklet']:.2f} "
      f"| {s['write']:.2f} | {secs} | {int(mem) / 1024:.0f} | {per_picture:.1f} | {per_page:.1f} |")
PY
    else
      printf '| %s | %s | failed: %s |\n' "$name" "$n" "$(tr '\n' ' ' < "$out/err")"
    fi
  done
done
