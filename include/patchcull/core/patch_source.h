// patchcull/core/patch_source.h: the cull kernels over the caller's own control points: float3 or
// float4 positions at any byte stride and offset in a vertex buffer, an index list per patch, and
// patches in Bezier, B-spline (OpenSubdiv's regular patches, boundary and corner ones included)
// or Gregory basis (OpenSubdiv's GREGORY_BASIS end caps), without first copying them into a
// PatchBatch.
//
// A PatchSourceView is a non-owning description of that memory. The entries below gather
// kBlockPatches patches at a time into a 4 KiB block on the stack (PatchBatchView's blocked
// layout, converting B-spline points to Bezier ones on the way) and run the existing kernel on it:
// for Bezier and B-spline sources every decision equals the batch kernel's on the same (converted)
// Bezier patches, byte for byte. Gregory patches have 20 points and a rational interior, so they
// get a small scalar path of their own (below). The entries: cull_frustum, cull_frustum_disp,
// cull_backpatch, cull_occlusion and cull_fused (every test and mode of the batch kernels), and
// their multi-threaded twins in parallel_cull.h.
//
// ---- Points --------------------------------------------------------------------------------------
// Point i is read from (const char*)points.data + points.offset_bytes + i * points.stride_bytes
// (unaligned reads are fine): 3 floats (x, y, z), taken with w = 1, or 4 floats, homogeneous
// (w x, w y, w z, w) with w > 0 (patch.h; not checked, like every view). A NaN or infinite
// coordinate is accepted and never culled.
//
// ---- Patches ---------------------------------------------------------------------------------------
// Patch p's points are indices[n p .. n p + n - 1] (n = 16, or 20 for Gregory), or the
// consecutive points n p .. n p + n - 1 when indices is null.
// - bezier: point k = 4 j + i is control point (i, j) of patch.h (i along u).
// - bspline: the same 4 x 4 grid, of uniform bicubic B-spline control points (OpenSubdiv's REGULAR
//   patch, points in its order: 4 rows of 4, row-major, u along a row). The span is converted to
//   Bezier form with the change of basis per direction, Bezier end point (b0 + 4 b1 + b2) / 6,
//   inner points (2 b1 + b2) / 3 and (b1 + 2 b2) / 3, other end (b1 + 4 b2 + b3) / 6.
//   boundary_mask[p] (optional) is OpenSubdiv's PatchParam::GetBoundary() of the patch: bit 0 the
//   edge v = 0, bit 1 u = 1, bit 2 v = 1, bit 3 u = 0. Beyond a boundary edge the points are
//   phantom points, extrapolated as OpenSubdiv's Far does (its B-spline boundary weights): row 0 =
//   2 row 1 - row 2 for bit 0, column 3 = 2 column 2 - column 1 for bit 1, row 3 = 2 row 2 - row 1
//   for bit 2, column 0 = 2 column 1 - column 2 for bit 3, both for a corner. Substituted into the
//   change of basis, a boundary end point becomes b1 (resp. b2) and the phantom points drop out:
//   their slots are never read and their indices never checked (OpenSubdiv leaves them -1 or
//   repeats a real point).
// - gregory: OpenSubdiv's Far::PatchDescriptor::GREGORY_BASIS order, 5 points per corner, corners
//   (0,0), (1,0), (1,1), (0,1): corner c's points 5c .. 5c + 4 are P, E+, E-, F+, F- (Far's
//   gregoryBasis.h and patchBasis.cpp draw the layout). The surface is a bicubic Bezier patch
//   whose 4 interior points are convex blends of the corners' face points F+ and F- (weights
//   s/(s+t), t/(s+t) at corner 0 and likewise at the others), so it lies in the convex hull of its
//   20 points: frustum and occlusion test all 20. The cone methods (tcone, ncone, the fused
//   kernel's cone stage) test a Gregory patch's own normal cone: Sederberg & Meyers' cone of
//   its s- and t-tangent cones, each the cone of the frozen Bezier net's differences widened by
//   the most the blend's own derivative can turn them (docs/METHODS.md, "Gregory patches"); ptp
//   and registered methods never cull a Gregory patch.
//
// ---- Costs and errors ----------------------------------------------------------------------------
// The entries check the view once, before their loop (check_patch_source: every index, one pass),
// then never allocate or throw. gather_bezier checks nothing: pass only views that
// check_patch_source accepts.
#pragma once

#include <cstddef>
#include <cstdint>

#include "patchcull/core/backpatch_methods.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/core/fused_cull.h"
#include "patchcull/core/hiz.h"
#include "patchcull/core/patch.h"

namespace patchcull {

/// Where the points are: point i at (const char*)data + offset_bytes + i * stride_bytes.
struct PointLayout {
    const void* data = nullptr;
    std::size_t stride_bytes = 0;  ///< >= offset_bytes + 4 * components (a point lies in its vertex)
    std::size_t offset_bytes = 0;  ///< of x inside each vertex
    int components = 3;            ///< 3: (x, y, z), w = 1; 4: homogeneous (w x, w y, w z, w)
    std::size_t point_count = 0;   ///< points the buffer holds: every index read must be below it
};

enum class PatchBasis : std::uint8_t { bezier, bspline, gregory };

/// Control points per patch of a basis: 16, or 20 for gregory.
constexpr int patch_source_points(PatchBasis basis) { return basis == PatchBasis::gregory ? 20 : 16; }

/// The slots of a 4 x 4 B-spline grid that hold real points under OpenSubdiv's boundary mask
/// (bit 0: row 0 is phantom, bit 1: column 3, bit 2: row 3, bit 3: column 0): bit k set when
/// slot k (row k / 4, column k % 4) is read. Phantom slots are never read.
constexpr std::uint32_t bspline_real_slots(unsigned boundary_mask) {
    std::uint32_t slots = 0;
    for (int k = 0; k < 16; ++k) {
        const int row = k / 4, col = k % 4;
        const bool phantom = ((boundary_mask & 1u) && row == 0) || ((boundary_mask & 2u) && col == 3) ||
                             ((boundary_mask & 4u) && row == 3) || ((boundary_mask & 8u) && col == 0);
        if (!phantom) slots |= 1u << k;
    }
    return slots;
}

/// count patches of one basis over the caller's memory (see the top of this header).
struct PatchSourceView {
    PointLayout points;
    const std::uint32_t* indices = nullptr;  ///< patch_source_points(basis) per patch, or null: consecutive points
    std::size_t count = 0;
    PatchBasis basis = PatchBasis::bezier;
    /// Optional, bspline only: OpenSubdiv's 4-bit boundary edge mask of each patch (count bytes,
    /// each < 16); null: every patch is interior.
    const std::uint8_t* boundary_mask = nullptr;
};

/// Throws Error("<what>: ...") naming the first fault of source: points.components not 3 or 4,
/// stride_bytes < offset_bytes + 4 * components, null points.data with count > 0, a
/// boundary_mask on a basis other than bspline or a mask >= 16, an index (phantom slots skipped)
/// >= points.point_count, or too few points for a source without indices. A view of 0 patches is
/// accepted as it is (nothing is read). One pass over the indices; no allocation.
void check_patch_source(const PatchSourceView& source, const char* what);

/// Writes patches [first, first + n) of source (bezier or bspline; n <= kBlockPatches, first + n
/// <= source.count) into block as one block of PatchBatchView's blocked layout: component c of
/// Bezier control point k of patch first + j at block[(4 k + c) * kBlockPatches + j]. Lanes n ..
/// kBlockPatches - 1 are zeroed. block holds kBlockFloats floats (4 KiB; any alignment). The view
/// {block, n, kBlockPatches, kBlockFloats} is then a batch of those patches. Checks nothing
/// (check_patch_source first); never allocates or throws; a gregory source gets a zeroed block.
void gather_bezier(const PatchSourceView& source, std::size_t first, std::size_t n, float* block);

/// Bezier patch p of source (bezier or bspline): gather_bezier's points for one patch (tests, tools).
BezierPatch source_bezier_patch(const PatchSourceView& source, std::size_t p);

/// frustum kernel (frustum.h, cull_frustum on view.planes) over source: culled holds source.count
/// bytes; max_displacement is null or holds source.count values >= 0. Bezier and B-spline:
/// culled[i] equals cull_frustum's on the converted patches. Gregory: culled when all 20 points
/// are outside one plane, their values formed as frustum_plane_values (+ add_frustum_margins) and
/// FrustumVerdict (never culled with a non-finite coordinate). Throws Error before the loop for a
/// bad view (check_patch_source).
void cull_frustum(const PatchSourceView& source, const float* max_displacement, const CullView& view,
                  std::uint8_t* culled);

/// Back-patch method id (backpatch_methods.h) over source: culled holds source.count bytes.
/// Bezier and B-spline: equals cull_backpatch on the converted patches. Gregory: the cone methods
/// (BackpatchMethodInfo::fusable) test the patch's Gregory tangent cone and the sphere of its 20
/// points (with F+ = F- at every corner, tcone's decision on the equivalent Bezier patch); a patch
/// with a point of w != 1, a view without an eye and the other methods never cull (write 0).
/// Throws Error before the loop for a bad view or an unknown id.
void cull_backpatch(BackpatchMethod id, const PatchSourceView& source, const CullView& view,
                    const BackpatchOptions& options, std::uint8_t* culled);

/// frustum-disp kernel (frustum.h, cull_frustum_disp: the box test of Sathe, "View Frustum Culling
/// of Catmull-Clark Patches in DirectX 11") over source: culled holds source.count bytes;
/// max_displacement as for cull_frustum (null: the box of the control points alone, a looser test
/// than cull_frustum's but valid for any source). Bezier and B-spline:
/// culled[i] equals cull_frustum_disp's on the converted patches. Gregory: the box of all 20
/// Cartesian points (it holds the patch: the surface lies in their convex hull), grown by the
/// displacement and tested as cull_frustum_disp_scalar tests the box of 16 (never culled with a
/// non-finite coordinate). Throws Error before the loop for a bad view or a matrix that
/// contradicts view.depth.
void cull_frustum_disp(const PatchSourceView& source, const float* max_displacement, const CullView& view,
                       std::uint8_t* culled);

/// Frustum + Hi-Z occlusion (hiz.h, cull_occlusion) over source: decision holds source.count
/// bytes of HiZDecision. Bezier and B-spline: equals cull_occlusion on the converted patches.
/// Gregory: kHiZFrustumCulled as cull_frustum above (no displacement); else hiz.h's steps 2-9
/// over the 20 points (not projectable, or a NaN box, -> visible). Throws Error before the loop for
/// a bad view or a pyramid that does not match view.depth (check_hiz_convention).
void cull_occlusion(const PatchSourceView& source, const CullView& view, const HiZPyramid& hiz, std::uint8_t* decision);

/// The fused kernel (fused_cull.h, cull_fused_simd: the plan's frustum, back-patch cone and Hi-Z
/// stages in one pass, each patch's decision the first stage that culls it) over source: decision
/// holds source.count bytes of FusedDecision. Bezier and B-spline: decision[i] equals
/// cull_fused_simd's on the converted patches, and stats (optional) counts as cull_fused_simd's
/// on them. Gregory: the frustum stage is cull_frustum's 20-point test (no displacement), the
/// occlusion stage cull_occlusion's (not projectable, or a NaN box, -> not occluded), and the
/// back-patch stage the Gregory cone test of cull_backpatch (either cone; stats count one group
/// per patch, as cull_fused_scalar's). Throws
/// Error before the loop for a bad view, a plan valid_fused_plan refuses, or a plan with occlusion
/// whose setup.hiz is null, never built or of the other depth direction than setup.planes.
void cull_fused(const PatchSourceView& source, const FusedCullSetup& setup, const FusedPlan& plan,
                std::uint8_t* decision, FusedCullStats* stats = nullptr);

}  // namespace patchcull
