// Pictures of one `patchcull render` frame for Niessner & Loop's figures ("Patch-Based Occlusion
// Culling for Hardware Tessellation"): --dump-hiz DIR writes the Hi-Z pyramid of the last frame
// (their Fig. 3), --draw-bounds P[,P...] draws a displaced patch's CAF and OOBB screen rectangles
// over the last frame (their Fig. 6).
//
// --dump-hiz DIR (DIR created when missing; one line naming --dump-hiz, exit 2, when it cannot be):
//   hiz_level_NN.png   level NN (00 = half resolution, hiz.h) as 8-bit grey, top row first:
//                      depth 1 (the cleared far plane, nothing drawn) is white (255); other
//                      depths d map linearly from the level's smallest depth lo (black, 0) to
//                      its largest depth below 1, hi (grey 254): round(254 (d - lo) / (hi - lo)),
//                      0 when hi == lo. Window depth is not linear in distance, so the per-level
//                      stretch is what makes the levels readable.
//   hiz_level_NN.f32   the level's texels as float32 in host byte order, W_l x H_l, row 0 = bottom
//                      (HiZPyramid's layout): the exact values, for checks.
//   depth.f32          the last frame's final depth buffer (W x H float32, row 0 = bottom).
//   ids.u32            its id buffer (W x H uint32: patch index + 1, 0 = background).
//   hiz.json           {"size":[W,H],"levels":[{"level","width","height","png","raw","lo","hi"}],
//                       "depth":"depth.f32","ids":"ids.u32","mapping":"..."}
// The pyramid is the one the last frame's occlusion tests read: built from pass 1's depth (the
// patches visible in the previous frame and the occluders), so every texel is >= the final depth
// of the pixels it covers (pass 2 only adds nearer surfaces).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "patchcull/core/displaced_bounds.h"
#include "patchcull/core/hiz.h"
#include "patchcull/core/patch.h"
#include "patchcull/gl/gl_pipeline.h"

namespace patchcull::cli {

/// Writes the files above for the pipeline's last frame into dir (which must exist: the caller
/// ran prepare_output_dir). Returns hiz.json's object. Throws patchcull::Error naming the file
/// that cannot be written, or the GL error; "--dump-hiz: ..." when the frame had no pyramid.
nlohmann::json dump_hiz(const gl::CullPipeline& pipeline, const std::string& dir);

/// Parses --draw-bounds' text: patch indices separated by commas, each in [0, patch_count).
/// Throws patchcull::Error naming --draw-bounds otherwise.
std::vector<std::size_t> parse_patch_list(const std::string& text, std::size_t patch_count);

/// One bound of a patch on the screen as the occlusion test uses it (displaced_bounds.h): the
/// window box of its NDC rectangle (fma(ndc, W/2, W/2)) clamped to pixels by
/// hiz_rect_from_window_box; rect only when bound.status is kDisplacedBoundProjected.
struct ScreenBound {
    DisplacedBound bound;
    bool projected = false;
    PixelRect rect;  ///< inclusive pixels, row 0 = bottom
};
/// compute_displaced_bound of the patch (world space, as the pipeline culls it) for the frame's
/// view and projection: the CPU twin of the GPU DisplacedPass (bit-identical bounds).
ScreenBound screen_bound(const BezierPatch& patch, DisplacementRange range, DisplacedBoundKind kind,
                         NormalConeKind cone, const gl::RenderParams& frame);

/// The CAF and OOBB of one patch.
struct PatchBounds {
    std::size_t patch = 0;
    DisplacementRange range;
    ScreenBound caf, oobb;
};
/// {"patch","range":[d_min,d_max],"pixels"(of the patch in ids),"caf":{...},"oobb":{...}} with per
/// bound "status" ("projected", "outside-plane", "unprojectable", "invalid"), and when projected
/// "ndc":[xmin,xmax,ymin,ymax], "rect":[x0,y0,x1,y1] (row 0 = bottom), "depth_near", "depth_far".
nlohmann::json patch_bounds_json(const PatchBounds& bounds, const std::vector<std::uint32_t>& ids);

/// The frame's colour (RGBA8, top row first, width x height: PatchRenderer::read_color) with each
/// patch's pixels (ids, top row first: read_ids; == patch + 1) tinted yellow, its OOBB rectangle outlined in red and
/// its CAF rectangle in green (drawn last: where the two coincide the CAF shows), written to path as a PNG. Throws
/// patchcull::Error naming path when it cannot be written.
void write_bounds_png(const std::string& path, std::vector<std::uint8_t> rgba, const std::vector<std::uint32_t>& ids,
                      int width, int height, const std::vector<PatchBounds>& bounds);

/// An 8-bit PNG (channels 1..4, rows top first) written and closed with every step checked.
void write_png_checked(const std::string& path, int width, int height, int channels,
                       const std::vector<std::uint8_t>& top_first);

}  // namespace patchcull::cli
