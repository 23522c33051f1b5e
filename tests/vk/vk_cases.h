// Inputs of the Vulkan equality tests: random patches in and around a random camera's frustum
// (clusters near the eye, across the planes, behind the eye, far beyond; a third rational;
// optional displacement margins), the CPU scalar kernel's flag words, and the buffers of a case.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "patchcull/core/camera.h"
#include "patchcull/core/clip_space.h"
#include "patchcull/core/cull_flags.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/patch.h"
#include "vk/vk_test_util.h"

namespace patchcull::vk::test {

struct RandomCase {
    std::vector<BezierPatch> patches;
    std::vector<float> margins;  // empty or one per patch
    Camera camera;
};

inline RandomCase random_case(std::uint32_t seed, std::size_t count, ClipDepth depth, bool with_margins) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    auto range = [&](float lo, float hi) { return lo + (hi - lo) * u01(rng); };
    RandomCase c;
    Camera& cam = c.camera;
    cam.eye = {range(-3, 3), range(-3, 3), range(-3, 3)};
    cam.target = {range(-1, 1), range(-1, 1), range(-1, 1)};
    cam.up = normalize(Vec3{range(-1, 1), range(-1, 1), range(-1, 1)});
    cam.fovy_radians = range(0.3f, 2.0f);
    cam.aspect = range(0.5f, 2.0f);
    cam.z_near = range(0.01f, 1.0f);
    cam.z_far = cam.z_near + range(0.5f, 20.0f);
    cam.depth = depth;
    for (std::size_t p = 0; p < count; ++p) {
        const Vec3 centre{range(-6, 6), range(-6, 6), range(-6, 6)};
        const float size = std::pow(10.0f, range(-2.0f, 0.5f));
        const bool rational = p % 3 == 0;
        BezierPatch patch;
        for (Vec4& cp : patch.cp) {
            const Vec3 x = centre + Vec3{range(-size, size), range(-size, size), range(-size, size)};
            cp = homogeneous(x, rational ? std::pow(2.0f, range(-2, 2)) : 1.0f);
        }
        c.patches.push_back(patch);
        if (with_margins) c.margins.push_back(u01(rng) < 0.3f ? 0.0f : std::pow(10.0f, range(-3.0f, 0.0f)));
    }
    return c;
}

/// The patches as a structure-of-arrays batch, unchecked (the CPU kernels' input).
inline PatchBatch patch_batch(const std::vector<BezierPatch>& patches) {
    PatchBatch batch(patches.size());
    for (std::size_t p = 0; p < patches.size(); ++p)
        for (int k = 0; k < kPatchPoints; ++k) {
            const Vec4& P = patches[p].cp[k];
            batch.component(k, 0)[p] = P.x;
            batch.component(k, 1)[p] = P.y;
            batch.component(k, 2)[p] = P.z;
            batch.component(k, 3)[p] = P.w;
        }
    return batch;
}

/// A CPU kernel's decisions as the flag words a pass of the chain leaves on words that held no
/// reason: `reason` or 0.
inline std::vector<std::uint32_t> words_of(const std::vector<std::uint8_t>& culled, std::uint32_t reason) {
    std::vector<std::uint32_t> words(culled.size());
    for (std::size_t p = 0; p < culled.size(); ++p) words[p] = culled[p] ? reason : 0u;
    return words;
}

/// cull_frustum_scalar's decisions as flag words (kCullFrustum or 0).
inline std::vector<std::uint32_t> cpu_frustum_words(const RandomCase& c, const FrustumPlanes& planes) {
    std::vector<std::uint8_t> culled(c.patches.size());
    cull_frustum_scalar(patch_batch(c.patches).view(), c.margins.empty() ? nullptr : c.margins.data(), planes,
                        culled.data());
    return words_of(culled, kCullFrustum);
}

// A w x h depth buffer in `depth`'s convention: the far end everywhere but a wall over the left
// two thirds (with pinholes) at the window depth of the 40th percentile of the patches' first points, so that
// many patches lie behind it.
inline std::vector<float> wall_depths(const RandomCase& c, const Mat4& m, ClipDepth depth, int w, int h) {
    const Mat4 key = to_depth_key(m, depth);
    std::vector<float> window;
    for (const BezierPatch& p : c.patches) {
        const Vec4 q = key * p.cp[0];
        if (q.w <= 0) continue;
        const float d = is_reversed(depth) ? -q.z / q.w : q.z / q.w;
        if (d > 0.0f && d < 1.0f) window.push_back(d);
    }
    std::sort(window.begin(), window.end());
    const float wall = window.empty() ? 0.5f : window[window.size() * 2 / 5];
    const float far = is_reversed(depth) ? 0.0f : 1.0f;
    std::vector<float> d(static_cast<std::size_t>(w) * h, far);
    // The wall has pinholes (far pixels) on a grid, so that a box's level and footprint matter.
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < 2 * w / 3; ++x)
            if (x % 9 != 4 || y % 7 != 3) d[static_cast<std::size_t>(y) * w + x] = wall;
    return d;
}

/// The case's buffers on the test device: control points, flags (zero), margins when the case has them.
struct CaseBuffers {
    explicit CaseBuffers(const RandomCase& c)
        : points(c.patches.size() * sizeof(BezierPatch)),
          flags(c.patches.size() * 4),
          margins(std::max<std::size_t>(c.margins.size() * 4, 4)),
          has_margins(!c.margins.empty()) {
        points.write(c.patches.data(), c.patches.size() * sizeof(BezierPatch));
        if (has_margins) margins.write(c.margins.data(), c.margins.size() * 4);
        count = c.patches.size();
    }
    PatchBuffers patch_buffers() const {
        PatchBuffers b;
        b.control_points = points.range();
        b.flags = flags.range();
        if (has_margins) b.margins = margins.range();
        b.count = count;
        return b;
    }
    HostBuffer points, flags, margins;
    bool has_margins;
    std::size_t count = 0;
};

}  // namespace patchcull::vk::test
