// patchcull/import/scene_poser.h: ScenePoser evaluates a Scene's patches at a time (animation,
// then each instance's transform into the scene's frame), on the CPU, or hands the linear inputs
// of the same pose to gl_posing.h's StencilPoser (gpu_tables, gpu_meshes).
//
// Exactness: pose() is exactly instance_to_frame times the (animated) control points, in float
// (tested bit for bit). Mirrored instances (instance_mirrors) are posed transposed,
// P'(u, v) = P(v, u), so that du x dv points out of the mirrored solid again; everything attached
// to a patch follows (see ScenePoser). Why the transposition turns the normal outward and keeps
// model-space patch clusters valid: docs/SCENES.md.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "patchcull/core/displacement.h"
#include "patchcull/core/math.h"
#include "patchcull/core/patch.h"
#include "patchcull/import/scene_model.h"
#include "patchcull/import/subdivision.h"

namespace patchcull {

/// One model's stencil tables for posing on the GPU (ScenePoser::gpu_tables; gl_posing.h's
/// PosingModel is the same data as plain arrays: the import layer does not depend on GL).
struct PoseModelTables {
    const PointStencils* patch_points = nullptr;    ///< 16 rows per patch (patch.h order)
    const PointStencils* tangent_points = nullptr;  ///< 24 rows per tangent block (may have no rows)
    std::vector<std::int32_t> tangent_index;        ///< per patch: PatchInfo::tangent_index
    std::uint32_t vertex_count = 0;                 ///< vertices of the control mesh the rows index
};

/// The linear inputs of one pose (ScenePoser::gpu_meshes): the control meshes of every (model,
/// effective time) group, concatenated, and each instance's place in them and transform.
struct PoseMeshes {
    std::vector<Vec3> vertices;
    std::vector<std::size_t> first_vertex;  ///< per instance: its group's first vertex
    std::vector<Mat4> to_world;             ///< per instance: instance_to_frame at the pose's time (the scene's frame)
    std::vector<std::uint8_t> mirrored;     ///< per instance: instance_mirrors
};

/// Evaluates a scene's patches at a time, keeping its storage between calls (no allocation after
/// the first pose of the same scene). Instances that share a model and an effective time
/// (time_seconds + time_offset, compared as floats; every rigid instance of a model shares its
/// rest frame) share one deformation and one patch evaluation per pose() call: a city of 220
/// characters in 6 phases evaluates 12 frames.
///
/// Mirrored instances (instance_mirrors): world control point 4j + i is instance_to_frame times
/// the model's control point 4i + j (the same point set; only the order of the float products
/// changes). Their tangent patches are the model's with du and dv swapped and transposed
/// (du'[3j + i] = mapped dv[4i + j], dv'[4j + i] = mapped du[3i + j]), their corner texcoords
/// have corners (1,0) and (0,1) swapped; depth and displacement range are the model patch's.
/// The eye-facing test of a transposed world patch equals the model-space test of the model
/// patch with the eye moved into model space, so model-space patch clusters stay valid.
class ScenePoser {
public:
    explicit ScenePoser(const Scene& scene);
    /// The scene posed (the constructor's; it must outlive the poser).
    const Scene& scene() const { return *scene_; }
    /// The patches of every instance at time_seconds in the scene's frame (world space when
    /// Scene::frame_origin is 0), instance by instance (each instance's patches in its model's
    /// order): instance_to_frame(instance, time_seconds, frame_origin) times the (animated) model
    /// patch, transposed for mirrored instances (see above). The reference stays valid until the
    /// next call.
    const std::vector<BezierPatch>& pose(float time_seconds);
    /// The ACC tangent patches of the last pose (PatchInfo::tangent_index semantics): the entry
    /// of each patch of pose(), -1 when it has none, indexing tangents(), whose vectors are mapped
    /// by the instances' linear parts (du and dv swapped and transposed for mirrored instances,
    /// so that they are the derivatives of pose()'s patch). Empty before the first pose.
    const std::vector<std::int32_t>& tangent_index() const { return tangent_index_; }
    const std::vector<TangentPatches>& tangents() const { return tangents_; }
    /// PatchInfo::depth of each patch of the last pose (for gl::PatchAttributes::depth).
    const std::vector<std::uint8_t>& depth() const { return depth_; }
    /// Corner texcoords (PatchInfo::uv, in the order of pose()'s patch: corners (1,0) and (0,1)
    /// swapped for instances that mirrored at construction) and displacement range (the model
    /// patch's, unchanged by the swap) of each patch of pose(), fixed for the scene (computed at
    /// construction from Scene::displacement: the range is zero for instances that are not
    /// displaced); both empty when the scene has no displacement.
    const std::vector<std::array<Vec2, 4>>& texcoords() const { return texcoords_; }
    const std::vector<DisplacementRange>& displacement_ranges() const { return ranges_; }

    // ---- posing on the GPU (gl_posing.h's StencilPoser) ------------------------------------
    /// The stencil tables whose rows, applied to gpu_meshes()'s vertices and mapped by each
    /// instance's transform (transposed for mirrored instances), give exactly pose()'s patches and
    /// tangents(), per model (Scene::models order). A subdivision model's own tables
    /// (SubdivisionModel::patch_points, tangent_points: pointers into the scene, valid while it
    /// lives); a model without a control mesh (the teapot) gets identity rows over its rest
    /// control points (one term of weight 1 each: exact), made once and kept here. Throws
    /// patchcull::Error naming the model when its patches were split (LoadedModel::split_levels
    /// > 0: splits are not stencil rows here) or a rest control point has w != 1.
    const std::vector<PoseModelTables>& gpu_tables();
    /// The control meshes of the pose at time_seconds, grouped as pose() groups them (one
    /// animate() per model and effective time; rigid instances share their model's rest mesh:
    /// the teapot's rest control points), plus each instance's group, transform and mirroring.
    /// Evaluates no patch. The reference stays valid until the next call; no allocation after
    /// the first call on the same scene.
    const PoseMeshes& gpu_meshes(float time_seconds);

private:
    // Instances sorted by (model, effective time) into order_, effective times into times_.
    void group_instances(float time_seconds);
    std::vector<PoseModelTables> gpu_tables_;
    std::vector<PointStencils> identity_tables_;  ///< per model: the teapot's identity rows
    PointStencils no_tangents_;
    PoseMeshes meshes_;

    const Scene* scene_;
    std::vector<Vec3> positions_;
    PatchFrame frame_;
    std::vector<std::size_t> first_patch_;     ///< per instance: its first patch in pose()'s output
    std::vector<std::size_t> first_tangent_;   ///< per instance: its first entry of tangents()
    std::vector<std::size_t> order_;           ///< instances sorted by (model, effective time)
    std::vector<float> times_;                 ///< per instance: effective time (rest: -inf)
    std::vector<std::size_t> tangent_counts_;  ///< per model: patches with tangent patches
    std::vector<BezierPatch> patches_;
    std::vector<std::int32_t> tangent_index_;
    std::vector<TangentPatches> tangents_;
    std::vector<std::uint8_t> depth_;
    std::vector<std::array<Vec2, 4>> texcoords_;
    std::vector<DisplacementRange> ranges_;
};

}  // namespace patchcull
