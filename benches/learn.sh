#!/usr/bin/env bash
# Learns the built-in rules again from the models people built and shows
# how the result differs from rules/default.rules (nothing, if the learner
# and the models are unchanged).
# Usage: benches/learn.sh FOLDER, the folder of the 30 models the header of
# rules/default.rules names (official LEGO set models from the LDraw Official
# Model Repository, Datsville and Mike-LDraw-Models, each under its own
# licence). WRITE=1 writes the result over rules/default.rules.
set -euo pipefail
cd "$(dirname "$0")/.."
folder=${1:?usage: benches/learn.sh FOLDER}
cargo build --release --quiet
out=$(mktemp)
trap 'rm -f "$out"' EXIT
target/release/brickwright learn "$folder" -o "$out"
if [ "${WRITE:-0}" = 1 ]; then
    cp "$out" rules/default.rules
    echo "wrote rules/default.rules"
elif diff -u rules/default.rules "$out"; then
    echo "rules/default.rules is what the models teach"
else
    echo "rules/default.rules differs from what the models teach (WRITE=1 to update)" >&2
    exit 1
fi
