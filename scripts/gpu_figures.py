#!/usr/bin/env python3
"""GPU-pipeline figures of docs/PERFORMANCE.md, measured with `patchcull render --json`.

Usage: python3 scripts/gpu_figures.py [BUILD_DIR]   (default: build)

1. Default scene: frame time with culling (cull all, tcone) against without (cull none), per
   tessellation level, as a ratio (the payoff in Fig. 9 of Niessner & Loop, "Patch-Based Occlusion
   Culling for Hardware Tessellation"), with the culled patches issued at level 0 (--draw flags)
   and left out of compacted indirect draws (--draw indirect), side by side.
2. Hi-Z build time against resolution (default scene, cull occlusion).
3. Cull-pass time against patch count (MonsterFrog and BigGuy split 0..2: closed solids, so that
   `all` includes the back-patch pass; cull occlusion alone, and all with each back-patch method;
   Niessner & Loop's Fig. 7).
4. The same frames on Vulkan (`render --api vulkan --vk-device gpu`: the Vulkan passes and
   renderer on the first GPU, else lavapipe), timed by timestamp queries, beside OpenGL's:
   frame, Hi-Z and cull-chain times per tessellation level, and the cull chain against patch count.
   The Vulkan renderer keeps its buffers in host-visible memory (vk_renderer.h: a test and tool
   renderer), so on a discrete GPU its times include reads from system memory: compare its passes'
   trends with GL's rather than the absolute ratio.
Every figure is the mean over frames 1..N-1 (frame 0 compiles and primes the statuses). On
llvmpipe the GL times are wall clock around glFinish (gl_renderer.h); on a GPU, timer queries.
A build without Vulkan (PATCHCULL_WITH_VULKAN=OFF) skips figure 4.
"""
import json
import os
import subprocess
import sys

BUILD = sys.argv[1] if len(sys.argv) > 1 else "build"
CLI = os.path.join(BUILD, "patchcull")
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIGGUY = os.path.join(ROOT, "data", "models", "bigguy.obj")
MONSTERFROG = os.path.join(ROOT, "data", "models", "monsterfrog.obj")


def render(*args):
    cmd = [CLI, "render", *map(str, args), "--json"]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def mean_ms(result, key):
    frames = result["frames"][1:] or result["frames"]
    return sum(f["ms"][key] for f in frames) / len(frames)


def mean_count(result, key):
    frames = result["frames"][1:] or result["frames"]
    return sum(f[key] for f in frames) / len(frames)


def main():
    first = render("teapot", "--frames", 1, "--size", "8x8")
    print(f"renderer: {first['renderer']}\n")

    print("1. Default scene (8226 patches), 640x360, 5 frames: frame time (ms) without culling, with")
    print("   culling drawn with flags (culled patches issued at level 0) and drawn indirect (compacted)")
    print(f"{'tess':>5} {'none':>9} {'flags':>9} {'indirect':>9} {'flags/none':>10} {'ind/none':>9} {'culled':>7}")
    for tess in (1, 2, 4, 8, 16):
        none = render("default", "--frames", 5, "--tess", tess, "--cull", "none", "--draw", "flags")
        flags = render("default", "--frames", 5, "--tess", tess, "--cull", "all", "--backpatch", "tcone",
                       "--draw", "flags")
        indirect = render("default", "--frames", 5, "--tess", tess, "--cull", "all", "--backpatch", "tcone",
                          "--draw", "indirect")
        culled = sum(mean_count(flags, k) for k in ("frustum_culled", "backpatch_culled", "occlusion_culled"))
        t0, t1, t2 = mean_ms(none, "total"), mean_ms(flags, "total"), mean_ms(indirect, "total")
        print(f"{tess:>5} {t0:>9.1f} {t1:>9.1f} {t2:>9.1f} {t1 / t0:>10.2f} {t2 / t0:>9.2f} "
              f"{100 * culled / flags['patches']:>6.1f}%")

    print("\n2. Hi-Z build time (ms) against resolution (default scene, cull occlusion, level 1, 4 frames)")
    print(f"{'size':>10} {'levels':>6} {'hiz ms':>8}")
    for w, h in ((256, 144), (640, 360), (1280, 720), (1920, 1080), (3840, 2160)):
        r = render("default", "--frames", 4, "--tess", 1, "--cull", "occlusion", "--size", f"{w}x{h}")
        levels = max(w, h).bit_length()
        print(f"{w}x{h:<5} {levels:>6} {mean_ms(r, 'hiz'):>8.2f}")

    print("\n3. Cull-pass time (ms) against patch count (256x256, level 1, 4 frames)")
    print(f"{'model':>14} {'patches':>8} {'occlusion':>10} {'+tcone':>8} {'+ncone':>8} {'+ptp':>8}")
    models = [(MONSTERFROG, s) for s in range(3)] + [(BIGGUY, s) for s in range(3)]
    for model, split in models:
        row = []
        base = ["--split", split, "--frames", 4, "--tess", 1, "--size", "256x256"]
        occ = render(model, *base, "--cull", "occlusion")
        row.append(mean_ms(occ, "cull"))
        for method in ("tcone", "ncone", "ptp"):
            row.append(mean_ms(render(model, *base, "--cull", "all", "--backpatch", method), "cull"))
        name = "monsterfrog" if model == MONSTERFROG else "bigguy"
        print(f"{name + ' /' + str(split):>14} {occ['patches']:>8} {row[0]:>10.2f} "
              + " ".join(f"{v:>8.2f}" for v in row[1:]))

    vulkan = ["--api", "vulkan", "--vk-device", "gpu"]
    try:
        probe = render("teapot", "--frames", 1, "--size", "8x8", *vulkan)
    except subprocess.CalledProcessError as e:
        print(f"\n4. Vulkan: skipped ({e.stderr.strip()})")
        return
    print(f"\n4. Vulkan ({probe['renderer']}, timestamp queries) beside OpenGL: default scene, 640x360, 5 frames,")
    print("   cull all (tcone), indirect draws; ms per frame (total, hiz, cull chain); the Vulkan renderer's")
    print("   buffers are host-visible (a test renderer): on a discrete GPU it reads them from system memory")
    print(f"{'tess':>5} {'gl total':>9} {'vk total':>9} {'vk/gl':>6} {'gl hiz':>7} {'vk hiz':>7} "
          f"{'gl cull':>8} {'vk cull':>8}")
    for tess in (1, 4, 8, 16):
        args = ["default", "--frames", 5, "--tess", tess, "--cull", "all", "--backpatch", "tcone"]
        g, v = render(*args), render(*args, *vulkan)
        print(f"{tess:>5} {mean_ms(g, 'total'):>9.1f} {mean_ms(v, 'total'):>9.1f} "
              f"{mean_ms(v, 'total') / mean_ms(g, 'total'):>6.2f} {mean_ms(g, 'hiz'):>7.2f} {mean_ms(v, 'hiz'):>7.2f} "
              f"{mean_ms(g, 'cull'):>8.2f} {mean_ms(v, 'cull'):>8.2f}")
    print("   cull chain (ms) against patch count (256x256, level 1, 4 frames, cull all, tcone)")
    print(f"{'model':>14} {'patches':>8} {'gl cull':>8} {'vk cull':>8}")
    for model, split in models:
        base = [model, "--split", split, "--frames", 4, "--tess", 1, "--size", "256x256", "--cull", "all"]
        g, v = render(*base), render(*base, *vulkan)
        name = "monsterfrog" if model == MONSTERFROG else "bigguy"
        print(f"{name + ' /' + str(split):>14} {g['patches']:>8} {mean_ms(g, 'cull'):>8.2f} {mean_ms(v, 'cull'):>8.2f}")


if __name__ == "__main__":
    main()
