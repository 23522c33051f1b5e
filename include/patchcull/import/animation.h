// patchcull/import/animation.h: procedural control-mesh animation (Niessner & Loop §1: patches change every
// frame, so nothing per patch can be precomputed from positions).
#pragma once

#include <vector>

#include "patchcull/core/math.h"
#include "patchcull/core/mesh.h"

namespace patchcull {

struct AnimationParams {
    float bend_radians = 0.35f;       ///< peak bend about the bounds' horizontal axis
    float twist_radians = 0.5f;       ///< peak twist about the vertical axis, top against bottom
    float breathe_amplitude = 0.04f;  ///< peak relative radial scale change
    float period_seconds = 2.0f;
};

/// Deforms rest positions at time t into out (resized to rest.size()). Smooth in space and time;
/// at t = 0 out equals rest. The vertical axis is the longest extent of the rest bounds.
void animate(const std::vector<Vec3>& rest, float time_seconds, const AnimationParams& params, std::vector<Vec3>& out);

}  // namespace patchcull
