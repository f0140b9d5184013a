#!/usr/bin/env bash
# The sweep: builds every mesh given at several sizes, seeds and options and
# reports every run that does not exit 0 (an internal error is a bug).
# Usage: benches/sweep.sh MESH... (default: every file in fixtures/ that is a
# mesh). SIZES (default "24 32 48 64 96"), SEEDS (default "1 2 3"),
# OPTIONS (default: a `;`-separated list: the default options, --hollow,
# --slopes, --plates, --palette layers) and STABILITY (default "off"; set it
# to "repair" to run the stability stage too, with BUDGET seconds, default
# 20) and BIN (a brickwright binary; default: this tree's, built) override.
# Prints one line a failing run, one line a run that left voxels of the
# model out (with how many), and a summary; exits 1 if any run failed.
set -uo pipefail
cd "$(dirname "$0")/.."
sizes=${SIZES:-"24 32 48 64 96"}
seeds=${SEEDS:-"1 2 3"}
options=${OPTIONS:-";--hollow;--slopes;--plates;--palette layers"}
stability=${STABILITY:-off}
budget=${BUDGET:-20}
bin=${BIN:-target/release/brickwright}
if [ -z "${BIN:-}" ]; then
    cargo build --release --quiet
fi
if [ $# -eq 0 ]; then
    set -- fixtures/*.obj fixtures/*.stl fixtures/*.glb fixtures/*.gltf
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
runs=0
failed=0
lossy=0
IFS=';' read -r -a option_sets <<< "$options"
for mesh in "$@"; do
    [ -f "$mesh" ] || continue
    for n in $sizes; do
        for seed in $seeds; do
            for opt in "${option_sets[@]}"; do
                runs=$((runs + 1))
                # shellcheck disable=SC2086
                "$bin" build "$mesh" -o "$out/run" --studs "$n" --seed "$seed" $opt \
                    --stability "$stability" --stability-budget "$budget" \
                    --formats ldr --quiet 2>"$out/err" >/dev/null
                rc=$?
                if [ "$rc" -ne 0 ]; then
                    failed=$((failed + 1))
                    printf 'exit %s: %s --studs %s --seed %s %s: %s\n' "$rc" "$mesh" "$n" "$seed" \
                        "$opt" "$(head -c 300 "$out/err" | tr '\n' ' ')"
                    continue
                fi
                left=$(grep -o '"left_out": *[0-9]*' "$out/run/report.json" | head -n 1 | grep -o '[0-9]*$')
                if [ "${left:-0}" -gt 0 ]; then
                    lossy=$((lossy + 1))
                    printf 'left out %s voxels: %s --studs %s --seed %s %s\n' "$left" "$mesh" "$n" \
                        "$seed" "$opt"
                fi
            done
        done
    done
done
printf '%s runs, %s failed, %s left voxels out\n' "$runs" "$failed" "$lossy"
[ "$failed" -eq 0 ]
