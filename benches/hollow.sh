#!/usr/bin/env bash
# The hollow table: builds each mesh with --hollow (the default stability
# stage on, as a user builds) at several sizes and prints one row per run:
# the solid layout's pieces, the hollow build's, their share, the mass
# share, the pieces standing inside the shell, whether every step was
# checked and stands, and the whole run's seconds. A run that does not exit
# 0 is a row saying so. Usage: benches/hollow.sh MESH... (SIZES overrides
# the sizes, default "32 48 64"; SEED the seed, default 1; WALL the wall,
# default 2; BIN the binary, default this tree's, built).
set -uo pipefail
cd "$(dirname "$0")/.."
sizes=${SIZES:-"32 48 64"}
seed=${SEED:-1}
wall=${WALL:-2}
bin=${BIN:-target/release/brickwright}
if [ -z "${BIN:-}" ]; then
    cargo build --release --quiet
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
printf '| mesh | studs | solid pieces | hollow pieces | share | mass | inner pieces | stability | run s |\n'
printf '|---|---:|---:|---:|---:|---:|---:|---|---:|\n'
for mesh in "$@"; do
    name=$(basename "$mesh")
    for n in $sizes; do
        start=$(date +%s.%N)
        if "$bin" build "$mesh" -o "$out/run" --studs "$n" --seed "$seed" --hollow --wall "$wall" \
            --formats ldr --quiet 2>"$out/err" >/dev/null; then
            secs=$(echo "$(date +%s.%N) - $start" | bc)
            python3 - "$out/run/report.json" "$name" "$n" "$secs" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
h, s = r["hollow"], r.get("stability") or {}
verdict = "off"
if s:
    verdict = "stands" if s.get("stands") else "does not stand"
    if not s.get("complete"):
        verdict += f" (checked {s.get('steps_checked')} steps, budget out)"
    if s.get("support_pieces"):
        verdict += f", {s['support_pieces']} support pieces"
print(f"| {sys.argv[2]} | {sys.argv[3]} | {h['solid']['pieces']} | {h['hollow']['pieces']} "
      f"| {100 * h['pieces_share']:.0f}% | {100 * h['mass_share']:.0f}% | {h['inner_pieces']} "
      f"| {verdict} | {float(sys.argv[4]):.1f} |")
PY
        else
            printf '| %s | %s | exit %s: %s |\n' "$name" "$n" "$?" "$(head -c 200 "$out/err" | tr '\n' ' ')"
        fi
    done
done
