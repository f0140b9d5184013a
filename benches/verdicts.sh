#!/usr/bin/env bash
# The step check's verdicts against the force program's, every step: builds
# each mesh at several sizes with the default options (the stability stage
# on, so the builds carry their support columns) and compares, for every
# step of each build, the step check's verdict with that of the whole
# structure's force program (examples/verdicts.rs). One table row a build:
# pieces, steps, both methods' seconds, steps agreed, steps only the step
# check finds standing (an equilibrium within every capacity exists, the
# least total usage overloads a joint), and steps the check fails while the
# program holds them (must be none: the script exits 1).
# Usage: benches/verdicts.sh MESH... (SIZES overrides the sizes, default
# "32 48 64").
set -euo pipefail
sizes=${SIZES:-"32 48 64"}
cargo build --release --quiet --bin brickwright --example verdicts
bin=target/release/brickwright
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
models=()
for mesh in "$@"; do
  for n in $sizes; do
    name=$(basename "${mesh%.*}")
    "$bin" build "$mesh" -o "$out/$name-$n" --studs "$n" --quiet --formats ldr
    cp "$out/$name-$n/$name.ldr" "$out/$name-$n.ldr"
    models+=("$out/$name-$n.ldr")
  done
done
target/release/examples/verdicts "${models[@]}"
