// `patchcull render MODEL --scheme osd --patch-source osd-table`: MODEL's feature-adaptive
// OpenSubdiv patch table (import/osd_patch_table.h's make_osd_adaptive_table, isolation level 2 as
// Scheme::osd) drawn with OpenSubdiv's own GL patch table and GLSL patch shaders, culled in place
// by the GPU passes (gl_osd/osd_gl_draw.h: frustum, back-patch, Hi-Z occlusion in the two-pass
// frame), on an orbit around the model (orbit_sequence, 4 degrees a frame). --verify draws every
// frame unculled too and compares the id buffers. --draw flags (the default here) issues every
// patch and OpenSubdiv's TCS gives the culled ones levels 0; --draw indirect lists each draw
// pass's survivors per patch array with CompactPass (--compact scan|append) and draws only those,
// OpenSubdiv's vertex shader pulling each control point through the list (osd_gl_draw.h).
// Output (--json), one object:
//   {"model","patches","size":[w,h],"patch_source":"osd-table","draw","compact","clip_depth",
//    "tess","cull","backpatch","verified","renderer",
//    "frames":[{"frame","pass1_drawn","pass2_drawn","submitted":{"pass1","pass2"},
//               "frustum_culled","backpatch_culled","occlusion_culled","false_culls",
//               "differing_pixels","depth_ties"}],"false_culls"}
// submitted: the patches each draw pass issued (flags: every patch, pass2 0 without occlusion;
// indirect: the listed ones, read back from the commands); false_culls: patches with a pixel of
// the unculled id buffer that the culled one lacks; differing_pixels: pixels whose ids differ;
// depth_ties: of those, pixels where both ids are patches at equal depth (all 0 without
// --verify); compact: "scan" or "append" with indirect, absent with flags.
#pragma once

#include <string>

#include "patchcull/core/backpatch_methods.h"
#include "patchcull/core/clip_space.h"
#include "patchcull/gl/gl_compaction.h"
#include "patchcull/gl/gl_cull_flags.h"

namespace patchcull::cli {

struct OsdTableRender {
    std::string model;  ///< an OBJ path or a shipped model's name (not the teapot, not a scene)
    int frames = 1, width = 0, height = 0;
    gl::CullMode cull = gl::CullMode::all;
    BackpatchMethod backpatch = BackpatchMethod::tcone;
    ClipDepth depth = ClipDepth::zero_to_one;
    int tess = 8;           ///< OpenSubdiv's uniform level, 1..16
    bool indirect = false;  ///< --draw indirect (else flags)
    gl::CompactMethod compact = gl::CompactMethod::prefix_scan;
    bool verify = false, json = false;
    DriverThreads driver_threads = DriverThreads::spread;  ///< --driver-threads
};

/// Runs it; returns the exit status (1 when --verify found a false cull). Throws Error for a bad
/// model or a tessellation level above 16.
int run_osd_table_render(const OsdTableRender& options);

}  // namespace patchcull::cli
