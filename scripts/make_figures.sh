#!/usr/bin/env bash
# Measures the inputs of the docs' figures with the CLI and draws them (scripts/plot_figures.py):
# every command below writes one JSON file under DATA_DIR, then the PNGs go to docs/figures/.
#
# Usage: bash scripts/make_figures.sh [BUILD_DIR] [DATA_DIR]   (defaults: build, docs/figures/data)
#
# Sizes are chosen so that the whole run takes minutes on a 2-core machine with Mesa llvmpipe
# (fewer views than docs/RESULTS.md's tables, which took up to 11 minutes per row); the load
# average before and after each part is recorded in DATA_DIR/uptime.txt, since on a shared machine
# the times depend on it.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD="${1:-build}"
DATA="${2:-docs/figures/data}"
CLI="$BUILD/patchcull"
BIGGUY=data/models/bigguy.obj
FROG=data/models/monsterfrog.obj
if [ ! -x "$CLI" ]; then
  echo "make_figures.sh: error: BUILD_DIR: $CLI is not an executable (build the patchcull_cli target first)" >&2
  exit 2
fi
if ! mkdir -p "$DATA"/cull_pass "$DATA"/tess_levels "$DATA"/backpatch_table "$DATA"/displaced_table 2>/dev/null; then
  echo "make_figures.sh: error: DATA_DIR: cannot create the folders under $DATA" >&2
  exit 2
fi
note() { echo "$(date -u +%H:%M:%S) $1: $(uptime | sed 's/.*load/load/')" | tee -a "$DATA/uptime.txt"; }
: > "$DATA/uptime.txt"

# 1. Cull-pass time against patch count (Niessner & Loop, Fig. 7 left): occlusion alone, and
#    frustum + back-patch + occlusion, on the two closed models split 0, 1, 2 times.
note "cull_pass start"
for model in bigguy monsterfrog; do
  path=data/models/$model.obj
  for split in 0 1 2; do
    common=(--split "$split" --frames 4 --tess 1 --size 256x256 --json)
    "$CLI" render "$path" "${common[@]}" --cull occlusion > "$DATA/cull_pass/${model}_split${split}_occlusion.json"
    for method in tcone ncone ptp; do
      "$CLI" render "$path" "${common[@]}" --cull all --backpatch "$method" \
        > "$DATA/cull_pass/${model}_split${split}_all_${method}.json"
    done
  done
done

# 2. Frame time and break-even against the tessellation level (Fig. 9 left): the default scene
#    without culling, with every test, and with the per-object switch (its measured break-even).
note "tess_levels start"
for level in 1 2 4 8 16; do
  for mode in none all auto; do
    "$CLI" render default --cull "$mode" --tess "$level" --frames 10 --json > "$DATA/tess_levels/level${level}_${mode}.json"
  done
done

# 3. Table 1 of Loop, Niessner & Eisenacher (back-patch cull rates over 10k views, as the paper and docs/RESULTS.md).
note "backpatch_table start"
for model in bigguy monsterfrog; do
  for split in 0 1; do
    "$CLI" cull data/models/$model.obj --split "$split" --methods tcone,ncone,ptp --views 10000 --view-mode contain \
      --json > "$DATA/backpatch_table/${model}_split${split}.json"
  done
done

# 4. Table 1 of Niessner & Loop (displaced MonsterFrog, six bounds; 20 and 10 views, docs/RESULTS.md 1000).
note "displaced_table start"
"$CLI" eval displaced "$FROG" --views 20 --json > "$DATA/displaced_table/monsterfrog_split0.json"
"$CLI" eval displaced "$FROG" --split 1 --views 10 --json > "$DATA/displaced_table/monsterfrog_split1.json"

# 5. Temporal coherence (Fig. 9 right): BigGuy, the camera orbiting at each speed (docs/RESULTS.md's run).
note "temporal start"
"$CLI" eval temporal "$BIGGUY" --speeds 0,1,2,5,10,20,45,90,180 --frames 36 --json > "$DATA/temporal.json"
# 6. Cull-pass time of the undisplaced and displaced kernels against patch count (Niessner & Loop,
#    Fig. 7 left: NoDisp, Full, ACoN, CoN; scripts/fig7_sweep.py writes DATA_DIR/fig7).
note "fig7 start"
python3 scripts/fig7_sweep.py "$BUILD" "$DATA"
note "end"

# The plots need matplotlib: Debian's python3-matplotlib is for /usr/bin/python3, which a
# python3 earlier on PATH (pyenv, a venv) may not see.
PYTHON=python3
if ! python3 -c "import matplotlib" 2>/dev/null && [ -x /usr/bin/python3 ]; then PYTHON=/usr/bin/python3; fi
"$PYTHON" scripts/plot_figures.py "$DATA"
