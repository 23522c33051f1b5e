// patchcull/objects/object_culling.h: the object level that runs before any patch is tested:
// whole objects culled by their bounding volumes against the view frustum (flat, or through a
// BVH with plane masking and plane coherence), and back-facing clusters of their triangles or
// patches culled by Johannsen & Carter's clustered back-face test, following G. Zachmann's
// lecture "Advanced Visibility Computations" and the object bounding-box test that
// Sathe ("View Frustum Culling of Catmull-Clark Patches in DirectX 11") and Niessner & Loop
// ("Patch-Based Occlusion Culling for Hardware Tessellation", §3) ask for before patch culling.
//
// An object is a span of the caller's patches (in the order the patch passes and draws see them)
// or of its triangles (PatchRenderer::set_occluders' order). The result is a list of culled
// patch spans and triangle spans: the CPU kernels skip them (for_each_active_span), the GPU
// pipeline takes them as PipelineParams::object_culled / culled_occluders, so a culled object
// costs no patch test and no patch work.
//
// Conservative (everything but detail culling): a culled object has no point inside the frustum
// (its world AABB, which the caller builds to hold everything it draws, e.g. the control points
// grown by the largest displacement), or every culled cluster member faces away from the eye
// (only for clusters the caller marks as drawn one-sided). Detail culling (projected area below a
// pixel threshold) is an option, off by default, never conservative: report what it changes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "patchcull/core/clip_space.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/math.h"
#include "patchcull/core/mesh.h"
#include "patchcull/objects/backface.h"
#include "patchcull/objects/backface_clusters.h"
#include "patchcull/objects/bounding_volumes.h"
#include "patchcull/objects/object_bvh.h"

namespace patchcull {

/// Which object-level tests run (`--objects`).
enum class ObjectCullMethod : std::uint8_t {
    none,          ///< every object goes on to the patch level
    frustum,       ///< each object's AABB against the frustum, a flat list with plane coherence
    bvh,           ///< the same test through ObjectBvh (plane masking + coherence)
    bvh_backface,  ///< bvh, then the clustered back-face test of the objects that remain
};
/// "none", "frustum", "bvh", "bvh+backface".
const char* object_cull_method_name(ObjectCullMethod method);
/// Parses object_cull_method_name's names; false (method unchanged) otherwise.
bool parse_object_cull_method(const std::string& text, ObjectCullMethod& method);

/// Why an object was culled this frame (visible: not culled whole; some of its clusters may be).
enum class ObjectVerdict : std::uint8_t { visible, frustum, backface, detail };

/// A run [first, first + count) of patches or triangles.
struct IndexSpan {
    std::size_t first = 0;
    std::size_t count = 0;
};

/// One object: a span of patches or of triangles.
struct CullableObject {
    std::string name;
    bool triangles = false;  ///< false: patches; true: triangles
    IndexSpan span;
};

/// What a frame gives the object level.
struct ObjectFrame {
    Mat4 world_to_clip;                        ///< projection * view
    ClipDepth depth = ClipDepth::zero_to_one;  ///< of world_to_clip
    Vec3 eye;                                  ///< world space
    /// World AABB of each object this frame (object order), holding everything it draws.
    const Bounds* boxes = nullptr;
    /// Per object, world -> the space its clusters were built in (object space of a rigid object:
    /// the inverse of its transform this frame); null: every cluster set is in world space.
    const Mat4* world_to_cluster = nullptr;
    /// Pixels per unit of tan(angle) (projection_pixel_scale), for detail culling.
    float pixel_scale = 1;
    /// Per object, for ObjectCullOptions::volume sphere / obb (holding everything it draws); may
    /// be null when that volume is not asked for.
    const Sphere* spheres = nullptr;
    const Obb* obbs = nullptr;
    /// Per object: 0 leaves its back-face clusters out this frame (e.g. float rounding of its
    /// world coordinates too large against its size, scene_object_level.h); null: all usable.
    const std::uint8_t* clusters_usable = nullptr;
};

/// The bounding volume an object is tested with after its AABB (flat list or BVH) left it in:
/// the object is culled when either volume is outside (both hold it, so both tests are
/// conservative and together tighter).
enum class ObjectVolume : std::uint8_t { aabb, sphere, obb };
/// "aabb", "sphere", "obb".
const char* object_volume_name(ObjectVolume v);
bool parse_object_volume(const std::string& text, ObjectVolume& v);

/// How bvh_backface tests the triangles of a one-sided triangle object that survived the frustum.
enum class TriangleBackface : std::uint8_t {
    clusters,      ///< the object's cluster hierarchy (Johannsen & Carter)
    normal_masks,  ///< each triangle's normal class against the frame's back mask (Zhang & Hoff)
    per_triangle,  ///< each triangle's own test (cull_backfacing_triangles_simd)
};
/// "clusters", "masks", "triangles".
const char* triangle_backface_name(TriangleBackface t);
bool parse_triangle_backface(const std::string& text, TriangleBackface& t);

struct ObjectCullOptions {
    ObjectCullMethod method = ObjectCullMethod::none;
    bool plane_masking = true;  ///< bvh: children test only the planes their parent straddles
    bool coherence = true;      ///< the plane that rejected a volume last frame is tried first
    /// Meta-BVs: before its planes, a volume is tested against the frustum's bounding sphere
    /// and box (meta_rejects; it can only reject more, also conservatively). frustum and bvh.
    bool meta_bvs = false;
    ObjectVolume volume = ObjectVolume::aabb;
    TriangleBackface triangle_backface = TriangleBackface::clusters;
    /// normal_masks: screen sectors per side (1: one mask for the frustum); an object whose box
    /// projects into one sector uses that sector's tighter mask.
    int mask_sectors = 1;
    /// Detail culling (not conservative): objects whose bounding sphere projects to less than
    /// this many pixels of area are culled; 0 (default) turns it off.
    float detail_min_pixels = 0;
};

/// Counts of one frame (render --json "objects").
struct ObjectCullStats {
    std::size_t total = 0;                    ///< objects
    std::size_t frustum_culled = 0;           ///< objects culled whole by the frustum test
    std::size_t backface_culled = 0;          ///< objects whose every cluster is back-facing
    std::size_t detail_culled = 0;            ///< objects culled by detail culling
    std::uint32_t plane_tests = 0;            ///< frustum planes evaluated (nodes and objects)
    std::uint32_t bvh_nodes_visited = 0;      ///< BVH nodes tested (the flat list: objects tested)
    std::uint32_t cluster_tests = 0;          ///< back-face cluster tests (hierarchies: nodes tested)
    std::size_t triangle_tests = 0;           ///< per-triangle tests or normal-mask lookups
    std::uint32_t meta_rejected = 0;          ///< objects rejected by the meta-BVs
    std::uint32_t volume_rejected = 0;        ///< objects the sphere / OBB rejected after the AABB
    std::size_t patches_culled = 0;           ///< patches in culled spans (no patch test runs on them)
    std::size_t triangles_culled = 0;         ///< triangles in culled spans
    std::size_t backface_patches_culled = 0;  ///< of patches_culled: in back-facing clusters
};

/// The result of ObjectCuller::cull (valid until the next call).
struct ObjectCullResult {
    std::vector<ObjectVerdict> verdicts;      ///< per object
    std::vector<IndexSpan> culled_patches;    ///< ascending, disjoint
    std::vector<IndexSpan> culled_triangles;  ///< ascending, disjoint
    ObjectCullStats stats;
};

/// The object level of one scene: its objects, their BVH (built on the first bvh frame, refitted
/// after) and their back-face clusters. Not thread-safe; one per scene.
class ObjectCuller {
public:
    /// Objects in a fixed order; spans of one kind must not overlap (else throws patchcull::Error).
    explicit ObjectCuller(std::vector<CullableObject> objects);

    /// Gives object `object` its back-face clusters (build_triangle_clusters or
    /// build_patch_clusters; leaves relative to the object's span start, i.e. leaf [f, f + n)
    /// is the object's members span.first + f ...), and says whether they were built in world
    /// space (static triangles) or in the object's own space (ObjectFrame::world_to_cluster).
    /// The caller answers for the object being drawn one-sided (back faces never visible).
    /// Throws when a leaf leaves the object's span.
    void set_clusters(std::size_t object, ClusterHierarchy clusters, bool object_space);

    std::size_t object_count() const { return objects_.size(); }
    const CullableObject& object(std::size_t i) const { return objects_[i]; }
    /// True when set_clusters gave the object clusters.
    bool has_clusters(std::size_t i) const { return !clusters_[i].nodes.empty(); }

    /// The triangles the triangle objects' spans index (world space, as drawn: after any cluster
    /// reordering), for the normal_masks and per_triangle variants; their normal classes are
    /// computed here once. Only objects with clusters (the one-sided ones) are back-face tested.
    void set_triangle_mesh(std::vector<Vec3> vertices, std::vector<std::uint32_t> indices);

    /// One frame. Allocates only on the first call and when the result grows.
    const ObjectCullResult& cull(const ObjectFrame& frame, const ObjectCullOptions& options);

private:
    std::vector<CullableObject> objects_;
    std::vector<ClusterHierarchy> clusters_;
    std::vector<std::uint8_t> object_space_;
    std::vector<PlaneCullState> flat_states_;
    ObjectBvh bvh_;
    bool bvh_built_ = false;
    std::vector<Containment> containment_;
    std::vector<std::uint8_t> leaf_culled_;
    std::vector<Vec3> mesh_vertices_;
    std::vector<std::uint32_t> mesh_indices_;
    NormalMaskGrid mask_grid_{16};
    std::vector<std::uint16_t> triangle_classes_;
    std::vector<BackMask> masks_;  // [0]: the frustum; then sectors x sectors
    std::vector<std::uint8_t> triangle_culled_;
    std::size_t cull_triangles_individually(std::size_t object, const ObjectFrame& frame,
                                            const ObjectCullOptions& options, std::vector<IndexSpan>& culled);
    ObjectCullResult result_;
};

/// Calls visit(first, count) for each run of [0, total) outside the culled spans (ascending,
/// disjoint): how a CPU patch kernel skips the patches of culled objects.
template <typename Visit>
void for_each_active_span(const std::vector<IndexSpan>& culled, std::size_t total, Visit visit) {
    std::size_t at = 0;
    for (const IndexSpan& s : culled) {
        if (s.first > at) visit(at, s.first - at);
        at = s.first + s.count > at ? s.first + s.count : at;
    }
    if (at < total) visit(at, total - at);
}

/// The CPU patch level after the object level: the frustum kernel (cull_frustum_simd) runs on the
/// patches outside result.culled_patches only; culled[i] = 1 for the patches of culled spans and
/// for those the kernel culls, else 0. max_displacement: null or one value >= 0 per patch. Returns
/// the patches the kernel tested (patches.count minus the culled spans'). Never allocates.
std::size_t cull_frustum_after_objects(const ObjectCullResult& result, const PatchBatchView& patches,
                                       const float* max_displacement, const FrustumPlanes& planes,
                                       std::uint8_t* culled);

}  // namespace patchcull
