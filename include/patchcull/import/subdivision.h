// patchcull/import/subdivision.h: Catmull-Clark control meshes to bicubic Bezier patches.
//
// Two schemes (the papers' setups: Niessner & Loop; Loop, Niessner & Eisenacher; Sathe):
// - Scheme::acc: Loop & Schaefer's approximate Catmull-Clark patches (ACC, Sathe): one
//   bicubic patch per quad, exact on regular quads; extraordinary patches also get ACC tangent
//   patches for a continuous normal field. A mesh with non-quad faces first gets one uniform
//   Catmull-Clark refinement (OpenSubdiv Far), so every face becomes a quad.
// - Scheme::osd: the limit surface through OpenSubdiv Far feature-adaptive refinement
//   (isolation level 2), B-spline-basis end caps, converted to Bezier. Exact everywhere except
//   the end caps next to extraordinary vertices, which are OpenSubdiv's own B-spline
//   approximation (about 0.15% of the model's radius at level 2; our patches equal OpenSubdiv's
//   evaluation of them to float precision). Handles boundaries, creases, triangles, n-gons.
// Both take the mesh's holes and SubdivisionOptions (mesh.h; OpenSubdiv's OBJ tags): osd hands
// them to Far; acc leaves out the faces Far leaves out (holes, and faces at an uninterpolated
// boundary), ignores creases and corners with a warning, and refuses boundary options it
// cannot follow (an edges-only boundary with corners), naming the tag's line and osd.
//   PatchInfo::extraordinary marks every patch that is not one regular patch covering a whole
//   base quad (patches from adaptive isolation, including the end caps).
//
// Both schemes are linear in the control-mesh positions, so a model stores each Bezier control
// point as a stencil (weighted sum of control vertices). Animation deforms the control mesh and
// re-applies the stencils each frame: nothing per patch is precomputed from positions.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "patchcull/core/math.h"
#include "patchcull/core/mesh.h"
#include "patchcull/core/patch.h"

namespace patchcull {

enum class Scheme { acc, osd };

const char* scheme_name(Scheme scheme);
/// Parses "acc" or "osd"; returns false otherwise.
bool parse_scheme(const std::string& text, Scheme& scheme);

/// Row r of a stencil table is sum_k weights[k] * vertex[indices[k]], k in [offsets[r], offsets[r+1]).
struct PointStencils {
    std::vector<std::uint32_t> offsets{0};
    std::vector<std::uint32_t> indices;
    std::vector<float> weights;

    std::size_t rows() const { return offsets.size() - 1; }
    /// Appends a row from (index, weight) pairs; duplicate indices are merged.
    void add_row(const std::vector<std::pair<std::uint32_t, float>>& terms);
    /// out must hold rows() points.
    void apply(const Vec3* vertices, Vec3* out) const;
};

/// Per-patch data that is not geometry.
struct PatchInfo {
    /// Texture coordinates at the patch corners (u,v) = (0,0), (1,0), (0,1), (1,1). The texture
    /// parameterization is bilinear over the patch domain (Sathe's pre-processing step).
    Vec2 uv[4] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
    std::uint32_t base_face = 0;      ///< control-mesh face the patch comes from
    bool extraordinary = false;       ///< acc: touches an extraordinary vertex; osd: end-cap patch
    std::int32_t tangent_index = -1;  ///< row block in SubdivisionModel::tangent_points, or -1
    /// Refinement depth of the patch's domain (osd: Far::PatchParam::GetDepth(), which counts an
    /// n-gon's quadrangulation so that a depth-d patch spans 2^-d of a base edge in every face;
    /// acc: 0). Adaptive refinement puts patches of different depths side by side; the renderer
    /// scales their tessellation by it so that shared edges get matching vertices
    /// (gl::PatchAttributes::depth). 1-to-4 splits keep it (every patch is split alike).
    std::uint8_t depth = 0;
};

struct SubdivisionModel {
    std::string name;
    Scheme scheme = Scheme::acc;
    ControlMesh mesh;              ///< the control mesh; animation deforms mesh.positions
    PointStencils patch_points;    ///< 16 rows per patch, control point 4*j + i (patch.h)
    PointStencils tangent_points;  ///< 24 rows per tangent block: 12 du rows, then 12 dv rows
    std::vector<PatchInfo> patches;

    std::size_t patch_count() const { return patches.size(); }
    std::size_t extraordinary_count() const;
};

/// Largest face (corners) and vertex valence (faces around a vertex) either scheme takes.
/// Why a limit: both schemes store every Bezier control point as a flat stencil over control
/// vertices, and next to a vertex of valence n (an n-gon becomes one: its face point) each of the
/// n patches has points that depend on the whole one-ring, so preprocessing costs ~n^2 time and
/// memory per such vertex or face, which is linear in the mesh only for bounded n (and Far's own
/// stencils for two n-gons sharing their edges cost ~n^3). Measured with `patchcull info` (one
/// vertex or face, Release, 2-core machine under load): at n = 64 every generated case (an open
/// or closed n-gon, an open or closed fan of n quads or n triangles) takes at most 0.33 s and
/// 28 MB with either scheme; at n = 128 a closed 128-gon takes 2.7 s (acc) and 1.4 s (osd), at
/// 256 18 s and 12 s.
inline constexpr std::uint32_t kMaxFaceCorners = 64;
inline constexpr std::uint32_t kMaxValence = 64;

/// Throws patchcull::Error "<mesh.name>: face F has N corners; ..." or "<mesh.name>: vertex V
/// has valence N; ..." (F, V 1-based as in the OBJ, the first offender) when the mesh exceeds
/// kMaxFaceCorners or kMaxValence. O(corners); vertex indices out of range are left to the
/// schemes' own validation. build_model and both back ends call it before any other work.
void check_preprocessing_limits(const ControlMesh& mesh);

/// Builds the patches of mesh under scheme. Throws patchcull::Error for meshes the scheme cannot
/// take (e.g. non-manifold topology, check_preprocessing_limits), naming mesh.name.
SubdivisionModel build_model(const ControlMesh& mesh, Scheme scheme);

/// Patches of one frame.
struct PatchFrame {
    std::vector<BezierPatch> patches;
    std::vector<TangentPatches> tangents;  ///< indexed by info[i].tangent_index
    std::vector<PatchInfo> info;
};

/// Evaluates the model's patches for control-mesh positions (model.mesh.positions or an animated
/// copy of the same size), then applies split_levels uniform 1-to-4 splits (Loop, Niessner & Eisenacher's
/// MonsterFrog with 5168 patches is 1292 quads after one split). Child texture coordinates are
/// the bilinear interpolation of the parent's.
void evaluate_patches(const SubdivisionModel& model, const std::vector<Vec3>& positions, int split_levels,
                      PatchFrame& out);

// Scheme back ends (src/import/acc.cpp, src/import/osd.cpp); build_model dispatches to them.
SubdivisionModel build_acc_model(const ControlMesh& mesh);
SubdivisionModel build_osd_model(const ControlMesh& mesh);

/// One uniform Catmull-Clark refinement of a mesh with OpenSubdiv Far, as stencils over the
/// original vertices: refined positions = stencils.apply(original positions). Texture
/// coordinates are refined linearly (face-varying, linear interpolation everywhere).
struct RefinedMesh {
    ControlMesh mesh;        ///< all-quad mesh; positions already evaluated at rest
    PointStencils stencils;  ///< one row per refined vertex
};
RefinedMesh refine_uniform_once(const ControlMesh& mesh);

}  // namespace patchcull
