// patchcull/teapot.h: the built-in Utah teapot (Newell), 32 bicubic Bezier patches.
//
// The teapot keeps its degenerate patches: the lid's top and the bottom collapse a patch edge to
// a point, where du x dv vanishes. Seed 001's Pcnt rule exists for exactly these patches.
#pragma once

#include <vector>

#include "patchcull/patch.h"

namespace patchcull {

/// The 32 patches (rim, body, lid, handle, spout, bottom), z up as in Newell's data, w = 1.
std::vector<BezierPatch> teapot_patches();

}  // namespace patchcull
