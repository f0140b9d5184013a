#!/usr/bin/env bash
# The stability stage on real meshes: builds each mesh at several sizes
# with the default stability options (check every step and repair what
# fails, within the default --stability-budget) and prints one row per
# run: pieces, steps, steps checked, whether the check completed within
# the budget, whether the build stands at every step, force programs
# solved, groups certified by a change to the kept equilibrium and, of
# those, the ones whose change took the whole group's program, the
# failing groups carried by a proof kept from an earlier step, the
# stage's seconds and the whole run's. Organic meshes are the
# slow case: most of their steps add pieces that need clutch, and each
# such step is a program of the pieces around its new ones.
# Usage: benches/stability.sh MESH... (SIZES overrides the sizes, default
# "32 48 64"; BUDGET the stage's budget in seconds, default the build's).
# Needs GNU time (/usr/bin/time).
set -euo pipefail
sizes=${SIZES:-"32 48 64"}
bin=target/release/brickwright
cargo build --release --quiet
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
budget=()
if [ -n "${BUDGET:-}" ]; then budget=(--stability-budget "$BUDGET"); fi
printf '| mesh | studs | pieces | steps | checked | complete | stands | programs | certified | whole | carried | stage s | run s |\n'
printf '|---|---|---|---|---|---|---|---|---|---|---|---|---|\n'
for mesh in "$@"; do
  for n in $sizes; do
    name=$(basename "$mesh")
    if /usr/bin/time -f '%e' -o "$out/time" "$bin" build "$mesh" -o "$out/$name-$n" --studs "$n" \
        --quiet --formats ldr "${budget[@]}" 2>"$out/err"; then
      python3 - "$out/$name-$n/report.json" "$out/time" "$name" "$n" <<'PY'
import json, sys
r = json.load(open(sys.argv[1])); secs = open(sys.argv[2]).read().split()[-1]
s = r["stability"]
print(f"| {sys.argv[3]} | {sys.argv[4]} | {r['pieces']} | {r['steps']} | {s['steps_checked']} "
      f"| {'yes' if s['complete'] else 'no'} | {'yes' if s['stands'] else 'no'} | {s['solves']} "
      f"| {s['certified']} | {s['whole_certified']} | {s['failures_carried']} "
      f"| {r['seconds']['stability']:.1f} | {secs} |")
PY
    else
      printf '| %s | %s | failed: %s |\n' "$name" "$n" "$(tr '\n' ' ' < "$out/err")"
    fi
  done
done
