#!/usr/bin/env bash
# The paper's experiments at its scale (Lau et al., section 5, Figure 6):
# each model built with `--search backward` and with the layout over seeds
# 1-5, one line a run: model, search, seed, bricks (pieces), tree nodes,
# backtracks, search seconds, success (the search's own figures: the
# stability stage is off, as it may search again with another seed where
# a build does not stand). Sizes (--studs) are chosen so the
# layout's piece count is near the paper's brick count: house 61 bricks
# (43 bricks and 24 slopes with slopes), skyscraper 92, mug 132, shuttle
# 111. The shuttle is also built at 16 studs, where a 1 x 8 brick
# reaches from every voxel of its wings to under the fuselage (at 28 the
# wing tips are farther out than any piece reaches).
# The paper took seconds for the house and the skyscraper and minutes for
# the mug and the shuttle; the backward search gets budgets to match.
# Usage: benches/paper.sh. SEEDS (default "1 2 3 4 5"), BUDGET and NODES
# (the backward search's time budget in seconds and node budget for the
# house and the skyscraper, default 60 and 1000000), LONG_BUDGET and
# LONG_NODES (the same for the mug and the shuttle, default 600 and
# 10000000), ONLY (one model's name, as the table's first column has it:
# only its rows) and BIN (a brickwright binary; default: this tree's,
# built) override. The models: fixtures/house.obj, fixtures/skyscraper.obj (five
# setback tiers), fixtures/mug.obj and fixtures/shuttle.obj (a fuselage,
# two delta wings and a fin).
set -uo pipefail
cd "$(dirname "$0")/.."
seeds=${SEEDS:-"1 2 3 4 5"}
budget=${BUDGET:-60}
nodes=${NODES:-1000000}
long_budget=${LONG_BUDGET:-600}
long_nodes=${LONG_NODES:-10000000}
bin=${BIN:-target/release/brickwright}
if [ -z "${BIN:-}" ]; then
    cargo build --release --quiet
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
# model|mesh|studs|extra options|budgets (seconds or minutes)
models=(
    "house|fixtures/house.obj|12||seconds"
    "house, slopes|fixtures/house.obj|11|--slopes|seconds"
    "skyscraper|fixtures/skyscraper.obj|12||seconds"
    "mug|fixtures/mug.obj|15||minutes"
    "shuttle|fixtures/shuttle.obj|28||minutes"
    "shuttle, 16 studs|fixtures/shuttle.obj|16||minutes"
)
printf '| model | search | seed | bricks | nodes | backtracks | search s | success |\n'
printf '|---|---|---|---|---|---|---|---|\n'
for m in "${models[@]}"; do
    IFS='|' read -r name mesh studs extra scale <<< "$m"
    if [ -n "${ONLY:-}" ] && [ "$ONLY" != "$name" ]; then
        continue
    fi
    if [ "$scale" = minutes ]; then
        run_budget=$long_budget run_nodes=$long_nodes
    else
        run_budget=$budget run_nodes=$nodes
    fi
    for search in backward layout; do
        for seed in $seeds; do
            rm -rf "$out/run"
            # shellcheck disable=SC2086
            "$bin" build "$mesh" -o "$out/run" --studs "$studs" --seed "$seed" $extra \
                --search "$search" --node-budget "$run_nodes" --time-budget "$run_budget" \
                --formats ldr --stability off --quiet 2>"$out/err" >/dev/null
            rc=$?
            if [ "$rc" -eq 0 ]; then
                python3 - "$out/run/report.json" "$name" "$search" "$seed" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
s = r["search"]
print(f"| {sys.argv[2]} | {sys.argv[3]} | {sys.argv[4]} | {r['pieces']} | {s['nodes']} "
      f"| {s['backtracks']} | {r['seconds']['search']:.2f} | yes |")
PY
            else
                # "... (N nodes, B backtracks, S s)" from the one-line failure.
                err=$(tr '\n' ' ' < "$out/err")
                n=$(sed -n 's/.*(\([0-9]*\) nodes, \([0-9]*\) backtracks, \([0-9.]*\) s).*/\1 | \2 | \3/p' <<< "$err")
                [ -n "$n" ] || n="- | - | -"
                printf '| %s | %s | %s | - | %s | no (exit %s) |\n' "$name" "$search" "$seed" "$n" "$rc"
            fi
        done
    done
done
