// The object level of a Scene (patchcull/import/scene_object_level.h).
#include "patchcull/import/scene_object_level.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "patchcull/core/error.h"

namespace patchcull {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// r + d rounded up (a float sum may round down by half an ulp).
float grow_radius(float r, float d) {
    if (d <= 0) return r;
    const float sum = r + d;
    return std::nextafter(sum, std::numeric_limits<float>::infinity());
}

double linear_determinant(const Mat4& m) {
    auto a = [&](int r, int c) { return static_cast<double>(m.at(r, c)); };
    return a(0, 0) * (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1)) - a(0, 1) * (a(1, 0) * a(2, 2) - a(1, 2) * a(2, 0)) +
           a(0, 2) * (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0));
}

std::vector<CullableObject> scene_cullable_objects(const Scene& scene) {
    std::vector<CullableObject> objects;
    std::size_t first = 0;
    for (const SceneInstance& instance : scene.instances) {
        const std::size_t count = scene.models.at(instance.model).rest.patches.size();
        objects.push_back({instance.name, false, {first, count}});
        first += count;
    }
    for (const EnvironmentObject& e : scene.environment)
        objects.push_back({e.name, true, {e.first_triangle, e.triangle_count}});
    return objects;
}

}  // namespace

SceneObjectLevel::SceneObjectLevel(Scene& scene, const ObjectLevelSetup& setup)
    : scene_(&scene), culler_(scene_cullable_objects(scene)) {
    std::size_t first = 0;
    for (const SceneInstance& instance : scene.instances) {
        instance_first_.push_back(first);
        first += scene.models.at(instance.model).rest.patches.size();
    }
    const std::size_t instances = scene.instances.size();
    boxes_.resize(culler_.object_count());
    spheres_.resize(culler_.object_count());
    obbs_.resize(culler_.object_count());
    world_to_cluster_.assign(culler_.object_count(), Mat4{});

    // Triangle clusters of the one-sided environment objects, their triangles reordered in place.
    for (std::size_t e = 0; e < scene.environment.size(); ++e) {
        const EnvironmentObject& object = scene.environment[e];
        const std::size_t begin = 3 * std::size_t{object.first_triangle};
        const std::size_t end = begin + 3 * std::size_t{object.triangle_count};
        std::vector<Vec3> points;
        for (std::size_t i = begin; i < end; ++i)
            points.push_back(scene.occluder_vertices.at(scene.occluder_indices[i]));
        boxes_[instances + e] = aabb_of_points(points.data(), points.size());
        spheres_[instances + e] = sphere_of_points(points.data(), points.size());
        obbs_[instances + e] = obb_of_points(points.data(), points.size());
        if (!setup.clusters || !object.one_sided || object.triangle_count == 0) continue;
        const std::vector<std::uint32_t> own(scene.occluder_indices.begin() + static_cast<std::ptrdiff_t>(begin),
                                             scene.occluder_indices.begin() + static_cast<std::ptrdiff_t>(end));
        ClusterHierarchy clusters =
            build_triangle_clusters(scene.occluder_vertices, own, setup.tc_over_r, setup.max_leaf_triangles);
        if (clusters.indices.size() != own.size())
            throw Error("object level: " + object.name + ": the cluster builder lost triangles");
        std::copy(clusters.indices.begin(), clusters.indices.end(),
                  scene.occluder_indices.begin() + static_cast<std::ptrdiff_t>(begin));
        culler_.set_clusters(instances + e, std::move(clusters), false);
        ++clustered_;
    }

    culler_.set_triangle_mesh(scene.occluder_vertices, scene.occluder_indices);  // as reordered

    // Patch clusters of rigid, undisplaced instances (one build per model, in model space).
    if (!setup.clusters || !setup.patches_one_sided) return;
    std::map<std::size_t, ClusterHierarchy> per_model;
    for (std::size_t i = 0; i < instances; ++i) {
        const SceneInstance& instance = scene.instances[i];
        const bool displaced = instance.displaced && !scene.displacement.empty();
        const LoadedModel& model = scene.models.at(instance.model);
        if (instance.deforms && model.subdiv) continue;  // deforming: its tangent planes change every frame
        if (displaced || model.rest.patches.empty()) continue;
        // A mirroring transform (det < 0) would flip du x dv against the planes moved into world
        // space, but ScenePoser poses mirrored instances transposed (scene_poser.h), which keeps
        // the drawn side the model-space clusters' front side for the eye moved into model space:
        // they get clusters. A singular transform (det == 0) has no inverse to move the eye: none.
        if (linear_determinant(instance.object_to_world) == 0) continue;
        auto it = per_model.find(instance.model);
        if (it == per_model.end())
            it = per_model
                     .emplace(instance.model, build_patch_clusters(model.rest.patches.data(), model.rest.patches.size(),
                                                                   setup.patch_tc_over_r, setup.max_leaf_patches))
                     .first;
        culler_.set_clusters(i, it->second, true);
        ++clustered_;
        ++patch_clustered_;
    }
}

const ObjectCullResult& SceneObjectLevel::cull(const std::vector<BezierPatch>& pose,
                                               const std::vector<DisplacementRange>& ranges, float time_seconds,
                                               const Camera& camera, int viewport_height,
                                               const ObjectCullOptions& options) {
    const Scene& scene = *scene_;
    const std::size_t instances = scene.instances.size();
    if (pose.size() != scene.patch_count())
        throw Error("object level: the pose has " + std::to_string(pose.size()) + " patches, the scene " +
                    std::to_string(scene.patch_count()));
    if (options.method != ObjectCullMethod::none) {
        const bool need_points = options.volume != ObjectVolume::aabb;
        for (std::size_t i = 0; i < instances; ++i) {
            const std::size_t first = instance_first_[i];
            const std::size_t count = culler_.object(i).span.count;
            points_.clear();
            float displacement = 0;
            // The exact min / max of the control points (aabb_of_points' answer), without a copy
            // of them unless a sphere or OBB needs them.
            Bounds box{{kInf, kInf, kInf}, {-kInf, -kInf, -kInf}};
            for (std::size_t p = first; p < first + count; ++p) {
                for (const Vec4& c : pose[p].cp) {
                    const Vec3 q = cartesian(c);
                    box.min = {std::min(box.min.x, q.x), std::min(box.min.y, q.y), std::min(box.min.z, q.z)};
                    box.max = {std::max(box.max.x, q.x), std::max(box.max.y, q.y), std::max(box.max.z, q.z)};
                    if (need_points) points_.push_back(q);
                }
                if (!ranges.empty())
                    displacement = std::max({displacement, std::fabs(ranges[p].d_min), std::fabs(ranges[p].d_max)});
            }
            std::vector<Vec3>& points = points_;
            if (displacement > 0) box = grow_bounds(box, displacement);  // rounded outwards
            boxes_[i] = box;
            if (options.volume == ObjectVolume::sphere) {
                Sphere sphere = sphere_of_points(points.data(), points.size());
                sphere.radius = grow_radius(sphere.radius, displacement);
                spheres_[i] = sphere;
            } else if (options.volume == ObjectVolume::obb) {
                Obb obb = obb_of_points(points.data(), points.size());
                for (float& h : obb.half_extents) h = grow_radius(h, displacement);
                obbs_[i] = obb;
            }
            if (culler_.has_clusters(i)) {
                Mat4 inverse;
                if (!invert(instance_to_frame(scene.instances[i], time_seconds, scene.frame_origin), inverse))
                    throw Error("object level: " + scene.instances[i].name + ": its transform is singular");
                world_to_cluster_[i] = inverse;
            }
        }
    }
    // Clusters only where float rounding is small against the object (the header's rule).
    clusters_usable_.assign(culler_.object_count(), 1);
    const float eye_far = std::max({std::fabs(camera.eye.x), std::fabs(camera.eye.y), std::fabs(camera.eye.z)});
    for (std::size_t i = 0; i < culler_.object_count(); ++i) {
        const Bounds& b = boxes_[i];
        const float far = std::max({eye_far, std::fabs(b.min.x), std::fabs(b.min.y), std::fabs(b.min.z),
                                    std::fabs(b.max.x), std::fabs(b.max.y), std::fabs(b.max.z)});
        const float diagonal = length(b.max - b.min);
        if (!(far <= kClusterRoundingRatio * diagonal)) clusters_usable_[i] = 0;
    }
    ObjectFrame frame;
    frame.clusters_usable = clusters_usable_.data();
    frame.world_to_clip = camera.view_projection();
    frame.depth = camera.depth;
    frame.eye = camera.eye;
    frame.boxes = boxes_.data();
    frame.world_to_cluster = world_to_cluster_.data();
    frame.spheres = spheres_.data();
    frame.obbs = obbs_.data();
    frame.pixel_scale = projection_pixel_scale(camera.fovy_radians, static_cast<float>(viewport_height));
    return culler_.cull(frame, options);
}

}  // namespace patchcull
