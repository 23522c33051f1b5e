// patchcull/import/osd_patch_table.h: an OpenSubdiv Far::PatchTable (feature-adaptive, built by
// Far::PatchTableFactory) culled in place on the CPU: one PatchSourceView (core/patch_source.h)
// per patch array, over the caller's own vertex buffer, decisions in the table's patch order.
//
// What a table may hold: arrays of REGULAR patches (16-point bicubic B-spline patches: the
// regular patches, and ENDCAP_BSPLINE_BASIS end caps) and of GREGORY_BASIS patches (20 points,
// ENDCAP_GREGORY_BASIS, Far's default end caps). Any other patch type (uniform QUADS/TRIANGLES,
// ENDCAP_BILINEAR_BASIS, the legacy GREGORY/GREGORY_BOUNDARY end caps, Loop's patches) is refused.
// Tables built with Options::useSingleCreasePatch are not supported: their crease patches are
// REGULAR patches whose surface also depends on a sharpness that the index arrays do not carry,
// and PatchTable cannot say whether it has any without reading out of bounds when it has none,
// so the caller must not pass one. Options::useInfSharpPatch is fine (those patches are ordinary
// boundary patches).
//
// Decisions map back to OpenSubdiv: byte i of every output below is for the table's patch i, the
// index of Far's PatchHandle::patchIndex and of PatchTable::GetPatchParamTable() (arrays in
// order, patches in order within each); OsdPatchArraySource::first_patch is an array's first.
//
// Points: point i of the caller's buffer is the vertex the table's index i names: with the
// factory's defaults, the refiner's vertices of every level (TopologyRefiner::
// GetNumVerticesTotal(), level 0 first) followed by the table's GetNumLocalPoints() local points
// (PatchTable::ComputeLocalPointValues or its local point stencil table), at any stride and
// offset, float3 or float4 (PointLayout). The local points must be recomputed whenever the
// vertices move, as for OpenSubdiv's own evaluation.
//
// This header includes <opensubdiv/far/patchTable.h>: a translation unit that includes it needs
// OpenSubdiv's headers, of the version patchcull was built with.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <opensubdiv/far/patchTable.h>

#include "patchcull/core/backpatch_methods.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/core/hiz.h"
#include "patchcull/core/math.h"
#include "patchcull/core/mesh.h"
#include "patchcull/core/patch_source.h"

namespace patchcull {

/// One patch array of a table as a patch source.
struct OsdPatchArraySource {
    /// bspline (REGULAR) or gregory (GREGORY_BASIS); indices into the table's own index array
    /// (see OsdPatchTableSource); boundary_mask from PatchParam::GetBoundary() (null when no
    /// patch of the array has a boundary edge); points as last bound.
    PatchSourceView source;
    int array = 0;                ///< the array's index in the table (GetPatchArrayDescriptor(array))
    std::size_t first_patch = 0;  ///< the table's patch index of source's patch 0
};

/// The patch sources of one Far::PatchTable. Build once per table (not per frame): the
/// constructor reads every PatchParam once; per frame only bind_points (if the buffer moved) and
/// the cull entries run. Index arrays are views into the table: Far::Index is int and
/// PatchSourceView reads std::uint32_t, its unsigned counterpart, so the table's memory is read
/// as it is (indices_are_views() true; on a platform where they differed, the constructor would
/// convert them once into memory of its own). The table must outlive this object and stay
/// unchanged. Movable, not copyable (the views point into its own storage).
class OsdPatchTableSource {
public:
    OsdPatchTableSource() = default;
    /// Throws Error naming the array and its type for a patch type other than REGULAR (16 points)
    /// or GREGORY_BASIS (20), and naming the patch for a negative index in a slot that is read
    /// (a REGULAR patch's phantom slots, beyond its boundary edges, are never read) or a REGULAR
    /// patch whose boundary mask has a bit above the quad's 4 edges. points: as bind_points.
    /// O(table): one pass over the params and the indices; allocates the masks.
    explicit OsdPatchTableSource(const OpenSubdiv::Far::PatchTable& table, const PointLayout& points = {});

    OsdPatchTableSource(const OsdPatchTableSource&) = delete;
    OsdPatchTableSource& operator=(const OsdPatchTableSource&) = delete;
    OsdPatchTableSource(OsdPatchTableSource&&) = default;
    OsdPatchTableSource& operator=(OsdPatchTableSource&&) = default;

    /// Points every array's source at points (cheap: no check here; the cull entries check each
    /// source, every index against points.point_count, before their loops).
    void bind_points(const PointLayout& points);

    const std::vector<OsdPatchArraySource>& arrays() const { return arrays_; }
    /// Patches in the table (PatchTable::GetNumPatchesTotal()): the size of every output below.
    std::size_t patch_count() const { return patch_count_; }
    /// 1 + the largest index any patch reads (0 for an empty table): points.point_count must be
    /// at least this.
    std::size_t points_needed() const { return points_needed_; }
    /// True when the sources' indices are the table's own memory (always, where Far::Index is
    /// int and std::uint32_t unsigned int); false when the constructor converted them.
    bool indices_are_views() const { return indices_.empty(); }

private:
    std::vector<OsdPatchArraySource> arrays_;
    std::vector<std::uint8_t> masks_;     // per table patch: GetBoundary() (REGULAR arrays only)
    std::vector<std::uint32_t> indices_;  // converted indices (only where Far::Index is not int)
    std::size_t patch_count_ = 0;
    std::size_t points_needed_ = 0;
};

/// A feature-adaptive table of a control mesh with its points: what an engine that draws
/// OpenSubdiv's patch tables holds.
struct OsdAdaptiveTable {
    std::unique_ptr<const OpenSubdiv::Far::PatchTable> table;
    /// Every refined level's vertices (level 0 = mesh.positions), then the table's local points:
    /// point i is the vertex the table's index i names (float3, PointLayout stride 12).
    std::vector<Vec3> points;
};

/// Builds mesh's feature-adaptive Far::PatchTable at isolation_level (1..10): Catmull-Clark with
/// the mesh's creases, corners, holes and options (as Scheme::osd), REGULAR B-spline patches and
/// GREGORY_BASIS end caps (Far's default; B-spline end caps when bspline_end_caps), no
/// single-crease patches; its points refined by Far::PrimvarRefiner and its local point stencils.
/// Throws Error for a bad mesh (as load_model) or level.
OsdAdaptiveTable make_osd_adaptive_table(const ControlMesh& mesh, int isolation_level, bool bspline_end_caps = false);

/// Far's name of a patch type ("REGULAR", "GREGORY_BASIS", ...; "type N" for a value Far does not
/// name), for error messages about a table.
std::string osd_patch_type_name(OpenSubdiv::Far::PatchDescriptor::Type type);

/// cull_frustum (core/patch_source.h) over every array: culled[i] for the table's patch i
/// (patch_count() bytes); max_displacement null or patch_count() values >= 0 in table order.
/// Throws Error before any array is culled for a bad source (check_patch_source).
void cull_frustum(const OsdPatchTableSource& table, const float* max_displacement, const CullView& view,
                  std::uint8_t* culled);

/// cull_backpatch over every array (Gregory end caps: their Gregory cone with the cone methods,
/// never culled by ptp; core/patch_source.h).
void cull_backpatch(BackpatchMethod id, const OsdPatchTableSource& table, const CullView& view,
                    const BackpatchOptions& options, std::uint8_t* culled);

/// cull_occlusion over every array: decision[i] (HiZDecision) for the table's patch i.
void cull_occlusion(const OsdPatchTableSource& table, const CullView& view, const HiZPyramid& hiz,
                    std::uint8_t* decision);

/// cull_frustum_disp over every array (Sathe's box; a Gregory end cap's over its 20 points):
/// culled[i] for the table's patch i; max_displacement as for cull_frustum.
void cull_frustum_disp(const OsdPatchTableSource& table, const float* max_displacement, const CullView& view,
                       std::uint8_t* culled);

/// cull_fused (core/patch_source.h) over every array: decision[i] (FusedDecision) for the table's
/// patch i, the plan's first stage that culls it (Gregory end caps: the back-patch stage tests
/// their Gregory cone).
/// The plan and the pyramid are checked before any array is culled.
void cull_fused(const OsdPatchTableSource& table, const FusedCullSetup& setup, const FusedPlan& plan,
                std::uint8_t* decision, FusedCullStats* stats = nullptr);

}  // namespace patchcull
