// patchcull/core/teapot.h: the built-in Utah teapot (Newell), 32 bicubic Bezier patches.
//
// The teapot keeps its degenerate patches: the lid's top and the bottom collapse a patch edge to
// a point, where du x dv vanishes. Loop, Niessner & Eisenacher's Pcnt rule exists for exactly these patches.
#pragma once

#include <vector>

#include "patchcull/core/patch.h"

namespace patchcull {

/// The 32 patches in the data set's order: rim 0-3, body 4-11, handle 12-15, spout 16-19,
/// lid knob 20-23, lid 24-27, bottom 28-31; z up as in Newell's data, w = 1, du x dv outward.
std::vector<BezierPatch> teapot_patches();

}  // namespace patchcull
