#!/usr/bin/env bash
# The payoff of compaction (Niessner & Loop, "Patch-Based Occlusion Culling for Hardware
# Tessellation", §6.3 and Fig. 9 left, with and without `--draw indirect`): per scene and
# tessellation level, five runs back to back, so that ratios compare runs seconds apart:
#   render SCENE --cull none --draw flags                 (RT: every patch drawn)
#   render SCENE --cull all  --draw flags|indirect        (RT0 from pass 2, CT = cull + Hi-Z)
#   render SCENE --cull auto --draw flags|indirect        (auto's own measured break-even)
# at 640x360, --frames 6 (frame 0 compiles the programs; the tables and the plot average frames
# 1..5), the auto runs --frames 8 (their own decisions start at frame 5), the whole sweep repeated
# ROUNDS times. Scenes: the built-in default (8226 patches, levels 1-16) and city (301,620
# patches, levels 1-8: its unculled frame at level 16 takes ~27 s here). One JSON file per run under
# DATA_DIR/roundR/SCENE/, `uptime` before each level and at the end in DATA_DIR/uptime.txt. Then
# scripts/plot_payoff_compaction.py prints the tables (medians over the rounds) and draws
# docs/figures/payoff_compaction.png. About 6 minutes a round on a quiet 2-core llvmpipe guest.
#
# Usage: bash scripts/payoff_compaction.sh [BUILD_DIR] [DATA_DIR] [ROUNDS]
#        (defaults: build, docs/figures/data/payoff_compaction, 3)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD="${1:-build}"
DATA="${2:-docs/figures/data/payoff_compaction}"
ROUNDS="${3:-3}"
CLI="$BUILD/patchcull"
if [ ! -x "$CLI" ]; then
  echo "payoff_compaction.sh: error: BUILD_DIR: $CLI is not an executable (build the patchcull_cli target first)" >&2
  exit 2
fi
if ! [[ "$ROUNDS" =~ ^[1-9][0-9]?$ ]]; then
  echo "payoff_compaction.sh: error: ROUNDS: expected 1..99, got '$ROUNDS'" >&2
  exit 2
fi
if ! mkdir -p "$DATA" 2>/dev/null; then
  echo "payoff_compaction.sh: error: DATA_DIR: cannot create the folders under $DATA" >&2
  exit 2
fi
note() { echo "$(date -u +%H:%M:%S) $1: $(uptime | sed 's/.*load/load/')" | tee -a "$DATA/uptime.txt"; }
: > "$DATA/uptime.txt"

for round in $(seq 1 "$ROUNDS"); do
for scene in default city; do
  levels="1 2 4 8 16"
  [ "$scene" = city ] && levels="1 2 4 8"
  mkdir -p "$DATA/round$round/$scene"
  for level in $levels; do
    note "round $round $scene level $level"
    common=(--tess "$level" --size 640x360 --json)
    out="$DATA/round$round/$scene/level${level}"
    "$CLI" render "$scene" "${common[@]}" --frames 6 --cull none --draw flags > "${out}_none.json"
    for draw in flags indirect; do
      "$CLI" render "$scene" "${common[@]}" --frames 6 --cull all --draw "$draw" > "${out}_all_${draw}.json"
    done
    for draw in flags indirect; do
      "$CLI" render "$scene" "${common[@]}" --frames 8 --cull auto --draw "$draw" > "${out}_auto_${draw}.json"
    done
  done
done
done
note "end"

# The plot needs matplotlib: Debian's python3-matplotlib is for /usr/bin/python3, which a
# python3 earlier on PATH (pyenv, a venv) may not see.
PYTHON=python3
if ! python3 -c "import matplotlib" 2>/dev/null && [ -x /usr/bin/python3 ]; then PYTHON=/usr/bin/python3; fi
"$PYTHON" scripts/plot_payoff_compaction.py "$DATA"
