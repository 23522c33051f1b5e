#!/usr/bin/env bash
# Niessner & Loop, "Patch-Based Occlusion Culling for Hardware Tessellation", section 6.3: the
# two scenes (about 27K patches at tessellation level 16; about 5.5K patches and 156 occluder
# triangles at level 32), rebuilt from our models as data/scenes/occlusion_27k.json and
# data/scenes/occlusion_5k.json. For each scene it runs `render --cull none|occlusion|all` one
# after the other (4 frames, --json --verify), keeps the JSON in OUT and prints a table per frame:
# the fraction of patches culled (1 - visible / patches) and the frame time of none / culled.
# Frame 0 primes the cull statuses (half the patches tagged visible); the orbit camera turns 90
# degrees a frame, so frame 2 is the deep view (the paper's Fig. 1(a)/(c)), frames 1 and 3 the
# shallow ones (Fig. 1(b)/(d)). Results: docs/RESULTS.md, "Niessner & Loop §6.3's two scenes".
#
# Usage: scripts/scenes_63.sh [--cli PATH] [--size WxH] [--out DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
cli=build/patchcull size=640x360 out=build/scenes_63
usage="usage: scripts/scenes_63.sh [--cli PATH] [--size WxH] [--out DIR]"
while [ $# -gt 0 ]; do
  case "$1" in
    --cli|--size|--out)
      [ $# -ge 2 ] && [ -n "$2" ] || { echo "scenes_63.sh: $1 needs a value; $usage" >&2; exit 2; }
      case "$1" in --cli) cli=$2 ;; --size) size=$2 ;; --out) out=$2 ;; esac
      shift 2 ;;
    *) echo "scenes_63.sh: unknown argument '$1'; $usage" >&2; exit 2 ;;
  esac
done
[[ "$size" =~ ^[0-9]+x[0-9]+$ ]] || { echo "scenes_63.sh: --size '$size' is not WxH; $usage" >&2; exit 2; }
[ -x "$cli" ] || { echo "scenes_63.sh: '$cli' is not an executable patchcull; $usage" >&2; exit 2; }
mkdir -p "$out"
uptime
for scene in occlusion_27k:16 occlusion_5k:32; do
  name=${scene%%:*} tess=${scene##*:}
  for cull in none occlusion all; do
    cmd=("$cli" render "data/scenes/$name.json" --cull "$cull" --tess "$tess" --frames 4 --size "$size" --json --verify)
    echo "${cmd[*]}"
    "${cmd[@]}" > "$out/$name.$cull.json"
  done
done
uptime
python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
for name in ("occlusion_27k", "occlusion_5k"):
    r = {c: json.load(open(f"{out}/{name}.{c}.json")) for c in ("none", "occlusion", "all")}
    P = r["all"]["patches"]
    print(f"{name}: {P} patches, tess {r['all']['tess']}, {r['all']['size'][0]}x{r['all']['size'][1]}, "
          f"false culls none/occlusion/all {r['none']['false_culls']}/{r['occlusion']['false_culls']}/{r['all']['false_culls']}")
    print("frame | culled all | culled occlusion | ms none | ms occlusion | ms all | none/occlusion | none/all")
    for f in range(len(r["all"]["frames"])):
        fr = {c: r[c]["frames"][f] for c in r}
        ms = {c: fr[c]["ms"]["total"] for c in r}
        cut = lambda c: 1 - fr[c]["visible"] / P
        print(f"{f} | {cut('all'):.1%} | {cut('occlusion'):.1%} | {ms['none']:.0f} | {ms['occlusion']:.0f} | "
              f"{ms['all']:.0f} | {ms['none'] / ms['occlusion']:.2f} | {ms['none'] / ms['all']:.2f}")
PY
