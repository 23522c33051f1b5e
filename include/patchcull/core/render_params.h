// patchcull/core/render_params.h: what the tessellation renderers draw, for both APIs: a frame's
// camera, size and tessellation (RenderParams) and the per-patch data beyond the control points
// (PatchAttributes). gl/gl_renderer.h's PatchRenderer and CullPipeline and vk/vk_renderer.h's
// CullRenderer take them; the conventions (object space, clip depth, displacement, one-sided
// drawing) are gl_renderer.h's header, the same on Vulkan except where vk_renderer.h says.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "patchcull/core/clip_space.h"
#include "patchcull/core/displacement.h"
#include "patchcull/core/math.h"
#include "patchcull/core/patch.h"

namespace patchcull {

/// Per-patch data beyond the control points. Each vector is empty (absent) or has one entry per
/// patch.
struct PatchAttributes {
    /// Cull margin: bound on |D| of the rendered displacement (DisplacementRange::max_abs()), >= 0.
    /// Read by the GPU frustum pass exactly as cull_frustum_scalar reads max_displacement. Empty:
    /// the ranges' max_abs() when displacement_ranges is given, else no margins.
    std::vector<float> max_displacement;
    /// Corner texcoords at (u,v) = (0,0), (1,0), (0,1), (1,1) (PatchInfo::uv) for displacement;
    /// absent means those same four values for every patch (PatchInfo's default).
    std::vector<std::array<Vec2, 4>> texcoords;
    /// ACC tangent patches (Loop & Schaefer 2008; PatchFrame::tangents and PatchInfo::tangent_index):
    /// patch p uses tangents[tangent_index[p]] when tangent_index[p] >= 0. The TES then shades
    /// with their normal du x dv, continuous across extraordinary vertices, instead of the
    /// patch's own derivatives. Displacement keeps the patch's own normal: Niessner & Loop §4.2's cone
    /// bounds (displaced_bounds.h), computed from the control points, bound that normal only.
    /// tangent_index: empty (no tangents) or one per patch.
    std::vector<std::int32_t> tangent_index;
    std::vector<TangentPatches> tangents;
    /// Refinement depth of each patch (PatchInfo::depth), or empty (all 0). With the uniform
    /// level L a patch of depth d is tessellated at min(64, L * 2^(D - d)), D the largest depth of
    /// the set: every patch then has the same vertex density along its base edges, so where an
    /// adaptive (osd) patch meets two of the next depth, its edge vertices are exactly theirs and
    /// no T-junction crack opens (up to float evaluation of the shared curve). Not applied to
    /// adaptive_tess, whose levels follow the eye distance.
    std::vector<std::uint8_t> depth;
    /// DisplacementRange of each patch (min and max of D over it, displacement.h), or empty: the
    /// input of the displaced pass (gl_passes.h's DisplacedPass, Niessner & Loop §4.2's bounds), uploaded
    /// as vec2 per patch (range_buffer()). A patch with range (0, 0) is not displaced.
    std::vector<DisplacementRange> displacement_ranges;
};

/// Parameters of one frame: camera, size, tessellation, what is drawn.
struct RenderParams {
    Mat4 view;        ///< world -> view (look_at); also gives the eye position for shading
    Mat4 projection;  ///< view -> clip (perspective) in convention depth
    /// The depth convention of projection (clip_space.h); the renderer draws in it: the depth test
    /// LESS with depth cleared to 1, or GREATER with depth cleared to 0 for the reversed ones
    /// (OpenGL: glClipControl GL_ZERO_TO_ONE, or GL_NEGATIVE_ONE_TO_ONE for minus_one_to_one;
    /// Vulkan's clip space has no minus_one_to_one).
    ClipDepth depth = ClipDepth::zero_to_one;
    int width = 256;
    int height = 256;
    int tess_level = 8;          ///< uniform tessellation level (adaptive: the maximum), clamped to [1, 64]
    bool use_cull_flags = true;  ///< false: ignore the flags and draw every patch (the reference)
    bool displace = true;        ///< displace the surface when a displacement map is set
    /// Adaptive tessellation by distance (Niessner & Loop §6.3): each edge gets
    /// clamp(tess_level * tess_reference_distance / d, 1, tess_level), d = distance from the eye to
    /// the midpoint of the edge's two corner points; interior levels the max of opposite edges.
    /// Shared edges get equal levels (no T-junction cracks). false: tess_level everywhere.
    bool adaptive_tess = false;
    float tess_reference_distance = 1.0f;  ///< > 0, object-space units
    /// One-sided drawing for closed, outward-oriented surfaces (LoadedModel::closed): a fragment
    /// is kept only where the exact patch at its (u, v) faces the eye, cos(du x dv, to eye) >
    /// kFrontFacingMinCosine (1e-3, shaders/shared.h); the rest is discarded, whatever the
    /// triangles' own facing. This is the visibility the back-patch tests (gl_backpatch.h)
    /// decide on, so they are conservative at every tessellation level (README: "What
    /// contributes a pixel"). false (default): both sides of every patch are drawn (open
    /// surfaces such as the teapot). Ignored while displacing (a displaced surface is two-sided).
    bool discard_back_facing = false;
};

/// Mesa's llvmpipe and lavapipe (22.3.6, still in 25.0.7) emit garbage when one 4096-vertex chunk
/// of a draw yields more than 65536 tessellated vertices: the renderers split every patch draw into
/// draws of at most max(1, 65536 / (L + 1)^2) patches, L the largest tessellation level in the
/// draw (clamped to [1, 64]; depth scales included). Harmless on a GPU.
inline std::size_t max_patches_per_draw(int largest_level) {
    const int top = std::clamp(largest_level, 1, 64);
    return std::max<std::size_t>(1, 65536 / static_cast<std::size_t>((top + 1) * (top + 1)));
}

/// The patches one compacted indirect command holds: per_draw (max_patches_per_draw), or on a
/// software rasterizer a sixteenth of it (about 4096 tessellated vertices a command: llvmpipe
/// tessellates larger draws more slowly per patch; default scene, 640x360, tess 16: 216 ms with
/// 226 patches a command, 34 ms with 16).
inline std::size_t patches_per_indirect_command(std::size_t per_draw, bool software) {
    return software ? std::max<std::size_t>(1, per_draw / 16) : per_draw;
}

}  // namespace patchcull
