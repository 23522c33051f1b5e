// patchcull/import/scene_object_level.h: the object level (object_culling.h) set up for a Scene
// (scene_model.h): one object per instance (its patches in ScenePoser's order) and one per
// environment object (its triangles), their world boxes each frame, and their back-face clusters.
//
// - Boxes: an instance's box is the AABB of its posed control points (the convex hull holds the
//   surface and every tessellated triangle), grown by the largest |D| of its displaced patches
//   (a displaced vertex moves by at most that along the unit normal), recomputed every frame; an
//   environment object's box is the AABB of its triangles, fixed. With ObjectCullOptions::volume
//   sphere or obb, the same points give a sphere (sphere_of_points) or a PCA OBB
//   (obb_of_points), grown by |D| alike, recomputed every frame.
// - Clusters (Johannsen & Carter's clustered back-face culling, G. Zachmann's lecture "Advanced
//   Visibility Computations"): for every one-sided environment object, triangle clusters in world
//   space (the object's triangles are reordered in Scene::occluder_indices so that each cluster
//   is a contiguous run: the same triangles, so the same image); for every rigid (deforms ==
//   false), undisplaced, unmirrored (det > 0) instance when patches are drawn one-sided, patch clusters from the
//   patches' object-space tangent control planes (Loop, Niessner & Eisenacher, "Effective
//   Back-Patch Culling for Hardware Tessellation"), built once per model and tested with the eye
//   moved into the instance's space each frame.
// - Rounding: the clusters bound the exact surface (M * rest, or the triangles as given), the GPU
//   draws float world coordinates and a float view: both are off by about |coordinate| * 6e-8. A
//   frame leaves an object's clusters out when its box or the eye lies farther from the origin
//   than kClusterRoundingRatio times the box's diagonal: below that the drawn surface is within
//   256 * 6e-8 = 1.5e-5 of the object's size of the exact one, which turns tangent planes by far
//   less than the fragment shader's grazing margin (cos > 1e-3) and an edge-on triangle by far
//   less than a pixel. Found by probing: a rigid BigGuy at 1e5 had 26 false culls in 6 frames.
inline constexpr float kClusterRoundingRatio = 256;
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "patchcull/import/scene_model.h"
#include "patchcull/objects/object_culling.h"

namespace patchcull {

struct ObjectLevelSetup {
    /// Drawn one-sided (RenderParams::discard_back_facing: every model closed): patch clusters
    /// may cull. False: only one-sided environment objects get clusters.
    bool patches_one_sided = false;
    /// Cost of one cluster test over the cost of drawing one primitive (the merge criterion
    /// P(C) > (P(A) nA + P(B) nB - tC/r) / (nA + nB), backface_clusters.h). 1: a cluster test
    /// costs about one triangle drawn; at 4 a box building's faces merge into one cluster that
    /// never culls (docs/PERFORMANCE.md).
    double tc_over_r = 1.0;
    /// The same for patch clusters: a patch costs far more to draw than a cluster test (it is
    /// tessellated), so clusters stay small (backface_clusters.h: 0.01-0.1 keep most of ptp's culls).
    double patch_tc_over_r = 0.05;
    /// False: no clusters at all (a frustum-only level; the occluders keep their order).
    bool clusters = true;
    unsigned max_leaf_triangles = 64;
    unsigned max_leaf_patches = 32;
};

class SceneObjectLevel {
public:
    /// Builds the objects and clusters of scene, reordering scene.occluder_indices within each
    /// one-sided environment object (call before the occluders are uploaded; the clusters refer to
    /// the order they leave, so build at most one level with clusters per scene). scene must
    /// outlive this object and keep its instances.
    SceneObjectLevel(Scene& scene, const ObjectLevelSetup& setup = {});

    /// The object level for the pose (ScenePoser::pose at time_seconds; its displacement ranges
    /// as ScenePoser::displacement_ranges(), empty without displacement) seen from the camera.
    const ObjectCullResult& cull(const std::vector<BezierPatch>& pose, const std::vector<DisplacementRange>& ranges,
                                 float time_seconds, const Camera& camera, int viewport_height,
                                 const ObjectCullOptions& options);

    const ObjectCuller& culler() const { return culler_; }
    /// The world boxes of the last cull (object order: instances, then environment objects).
    const std::vector<Bounds>& boxes() const { return boxes_; }
    /// Objects that have back-face clusters, and of those, rigid instances (patch clusters).
    std::size_t clustered_objects() const { return clustered_; }
    std::size_t patch_clustered_objects() const { return patch_clustered_; }

private:
    const Scene* scene_;
    ObjectCuller culler_;
    std::vector<std::size_t> instance_first_;  // first patch of each instance
    std::vector<Bounds> boxes_;
    std::vector<Sphere> spheres_;
    std::vector<Obb> obbs_;
    std::vector<Mat4> world_to_cluster_;
    std::vector<Vec3> points_;  // an instance's control points (sphere / OBB volumes), reused
    std::vector<std::uint8_t> clusters_usable_;
    std::size_t clustered_ = 0, patch_clustered_ = 0;
};

}  // namespace patchcull
