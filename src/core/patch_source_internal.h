// The patch-source entries (patchcull/core/patch_source.h) on a range of source patches, without
// their checks, for the single-threaded entries and the parallel ones (parallel_cull.h), which
// check a view once and then run these on ranges; not a public header.
#pragma once

#include <cstddef>
#include <cstdint>

#include "patchcull/core/backpatch_methods.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/fused_cull.h"
#include "patchcull/core/patch.h"
#include "patchcull/core/patch_source.h"

namespace patchcull::detail {

/// cull_frustum_disp_simd on planes made once (make_frustum_planes), for callers that run it per
/// block (frustum_simd.cpp).
void cull_frustum_disp_simd_planes(const PatchBatchView& patches, const float* max_displacement,
                                   const FrustumPlanes& planes, std::uint8_t* culled);

// Source patches [first, last) of a view that check_patch_source accepted; every output and
// max_displacement is indexed by source patch (the entry's arrays, not offset by first).
void source_frustum(const PatchSourceView& source, std::size_t first, std::size_t last, const float* max_displacement,
                    const FrustumPlanes& planes, std::uint8_t* culled);
/// planes: make_frustum_planes(view.object_to_clip, view.depth), made once by the caller.
void source_frustum_disp(const PatchSourceView& source, std::size_t first, std::size_t last,
                         const float* max_displacement, const FrustumPlanes& planes, std::uint8_t* culled);
/// method's kernel over Bezier and B-spline sources; over a Gregory source the Gregory cone test
/// for the cone methods (method.fusable, with view.has_eye), else no cull.
void source_backpatch(const BackpatchMethodInfo& method, const PatchSourceView& source, std::size_t first,
                      std::size_t last, const CullView& view, const BackpatchOptions& options, std::uint8_t* culled);
/// plan valid, setup.hiz checked when the plan has occlusion.
void source_fused(const PatchSourceView& source, std::size_t first, std::size_t last, const FusedCullSetup& setup,
                  const FusedPlan& plan, std::uint8_t* decision, FusedCullStats* stats);

/// The checks of cull_fused over a source (patch_source.h) and of its parallel twin: Error
/// (starting "<what>: ") for a plan valid_fused_plan refuses or a plan with occlusion whose
/// setup.hiz is null, never built or of the other depth direction.
void check_fused_inputs(const FusedCullSetup& setup, const FusedPlan& plan, const char* what);

}  // namespace patchcull::detail
