#!/usr/bin/env bash
# Two comparisons the docs report, one table row per build.
#
#   benches/compare.sh rules MESH...    learned rule frequencies (the built-in
#       rules) against the same rules with every weight 1 ("uniform"):
#       vertical seams that continue into the course above (lower is
#       stronger), voxels per piece, how close the derivation's rule shares
#       come to the corpus's, and search seconds.
#   benches/compare.sh slopes MESH...   bricks alone against bricks and
#       slopes (--slopes): bricks, slopes, voxels left out, seconds.
#
# STUDS sets the size (default 16); SEED the seed of the slopes runs
# (default 1), SEEDS the seeds averaged in the rules runs (default 1 to 5);
# SEARCH the search of the rules runs (layout, the default, or backward:
# the paper's backward tracing, BUDGET seconds a run, default 30; a run
# that finds no derivation is counted in "built" and left out of the rest).
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
    print(f"| {name} | {label} | {r['pieces']} | {r['voxels_per_piece']} | {seams['continued']}/{seams['seams']} = {seams['fraction']:.2f} | {r['seconds']['search']:.2f} |")
else:
    print(f"| {name} | {label} | {r['pieces']} | {r['pieces'] - slopes} | {slopes} | {r['voxels']} | {r['quality']['left_out']} | {seams['fraction']:.2f} | {r['seconds']['search']:.2f} |")
PY
}

case "$what" in
rules)
  # The built-in rules, and the same rules with every weight 1; each mesh
  # built with every seed of SEEDS, the figures averaged. "TV to corpus" is
  # the total variation distance between the derivations' shares of the
  # basic rules (starting rules left out, all seeds together) and the
  # corpus's shares (the learned counts) among the rules joining two
  # bricks; "people's rules" is the share of the derivations' joints made
  # by a rule the corpus used at all.
  cp rules/default.rules "$out/learned.rules"
  awk '$1 == "rule" { $8 = 1 } $1 == "unseen" { $2 = 1 } { print }' "$out/learned.rules" >"$out/uniform.rules"
  python3 - "$bin" "$out" "$studs" "${SEEDS:-1 2 3 4 5}" "${SEARCH:-layout}" "${BUDGET:-30}" "$@" <<'PY'
import json, subprocess, sys
bin, out, studs, seeds, search, budget = sys.argv[1:7]
seeds, meshes = seeds.split(), sys.argv[7:]
lines = [l.split("#")[0].split() + [l] for l in open(f"{out}/learned.rules") if l.strip() and not l.startswith("#")]
starts = sum(1 for t in lines if t[0] == "start")
basic = [t for t in lines if t[0] == "rule"]
bricks = {t[1] for t in lines if t[0] == "part" and "# Brick" in t[-1]}
corpus = {starts + i: float(t[7]) for i, t in enumerate(basic) if t[1] in bricks and t[2] in bricks}
total = sum(corpus.values())
corpus = {k: v / total for k, v in corpus.items()}
print(f"| mesh | search | weights | built | pieces | voxels/piece | seams continued | TV to corpus | people's rules | search s |  (mean of seeds {' '.join(seeds)})")
print("|---|---|---|---|---|---|---|---|---|---|")
for mesh in meshes:
    name = mesh.rsplit("/", 1)[-1]
    for w in ["learned", "uniform"]:
        rows, uses = [], {}
        for seed in seeds:
            d = f"{out}/{name}-{w}-{seed}"
            run = subprocess.run([bin, "build", mesh, "-o", d, "--studs", studs, "--seed", seed,
                                  "--rules", f"{out}/{w}.rules", "--stability", "off",
                                  "--search", search, "--time-budget", budget,
                                  "--formats", "ldr", "--quiet"])
            if run.returncode == 2 and search == "backward":
                continue  # no derivation within the budget
            run.check_returncode()
            r = json.load(open(f"{d}/report.json"))
            rows.append(r)
            for k, v in r["derivation"]["uses"].items():
                if int(k) >= starts:
                    uses[int(k)] = uses.get(int(k), 0) + v
        if not rows:
            print(f"| {name} | {search} | {w} | 0 of {len(seeds)} | | | | | | |")
            continue
        n = sum(uses.values())
        shares = {k: v / n for k, v in uses.items()}
        tv = sum(abs(corpus.get(k, 0) - shares.get(k, 0)) for k in set(corpus) | set(shares)) / 2
        seen = sum(v for k, v in shares.items() if k - starts < len(basic))
        mean = lambda f: sum(f(r) for r in rows) / len(rows)
        print(f"| {name} | {search} | {w} | {len(rows)} of {len(seeds)} | {mean(lambda r: r['pieces']):.0f} | {mean(lambda r: r['voxels_per_piece']):.2f} "
              f"| {mean(lambda r: r['seams']['fraction']):.3f} | {tv:.3f} | {seen:.0%} "
              f"| {mean(lambda r: r['seconds']['search']):.2f} |")
PY
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
