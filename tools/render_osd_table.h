// `patchcull render MODEL --scheme osd --patch-source osd-table`: MODEL's feature-adaptive
// OpenSubdiv patch table (import/osd_patch_table.h's make_osd_adaptive_table, isolation level 2 as
// Scheme::osd) drawn with OpenSubdiv's own GL patch table and GLSL patch shaders, culled in place
// by the GPU passes (gl_osd/osd_gl_draw.h: frustum, back-patch, Hi-Z occlusion in the two-pass
// frame), on an orbit around the model (orbit_sequence, 4 degrees a frame). --verify draws every
// frame unculled too and compares the id buffers.
// Output (--json), one object:
//   {"model","patches","size":[w,h],"patch_source":"osd-table","clip_depth","tess","cull",
//    "backpatch","verified","renderer",
//    "frames":[{"frame","pass1_drawn","pass2_drawn","frustum_culled","backpatch_culled",
//               "occlusion_culled","false_culls","differing_pixels"}],"false_culls"}
// false_culls: patches with a pixel of the unculled id buffer that the culled one lacks;
// differing_pixels: pixels whose ids differ (both 0 without --verify).
#pragma once

#include <string>

#include "patchcull/core/backpatch_methods.h"
#include "patchcull/core/clip_space.h"
#include "patchcull/gl/gl_cull_flags.h"

namespace patchcull::cli {

struct OsdTableRender {
    std::string model;  ///< an OBJ path or a shipped model's name (not the teapot, not a scene)
    int frames = 1, width = 0, height = 0;
    gl::CullMode cull = gl::CullMode::all;
    BackpatchMethod backpatch = BackpatchMethod::tcone;
    ClipDepth depth = ClipDepth::zero_to_one;
    int tess = 8;  ///< OpenSubdiv's uniform level, 1..16
    bool verify = false, json = false;
};

/// Runs it; returns the exit status (1 when --verify found a false cull). Throws Error for a bad
/// model or a tessellation level above 16.
int run_osd_table_render(const OsdTableRender& options);

}  // namespace patchcull::cli
