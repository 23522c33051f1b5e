// Posing a scene's patches (patchcull/import/scene_poser.h): on the CPU (pose) and the linear
// inputs of posing on the GPU (gpu_tables, gpu_meshes).
#include "patchcull/import/scene_poser.h"

#include <algorithm>
#include <limits>

#include "patchcull/core/error.h"

namespace patchcull {

// Mirrored instances (instance_mirrors) are posed transposed, P'(u, v) = P(v, u), which turns
// du x dv out of the mirrored solid again (the derivation: docs/SCENES.md, "Mirrored instances").
// Transposed, with everything that goes with the patch:
// - control points: cp'[4j + i] = cp[4i + j];
// - ACC tangent patches: du'(u, v) = dv(v, u) and dv'(u, v) = du(v, u), i.e.
//   du'[3j + i] = dv[4i + j] (i < 3, j < 4) and dv'[4j + i] = du[3i + j] (i < 4, j < 3);
// - corner texcoords (corners (0,0), (1,0), (0,1), (1,1)): corners 1 and 2 swap;
// - the displacement range (over the corners' texcoord box) and the depth are per patch: unchanged.

ScenePoser::ScenePoser(const Scene& scene) : scene_(&scene) {
    if (scene.displacement.empty()) return;
    for (const SceneInstance& instance : scene.instances) {
        const PatchFrame& rest = scene.models.at(instance.model).rest;
        const bool mirrored = instance_mirrors(instance);
        for (const PatchInfo& info : rest.info) {
            if (mirrored)
                texcoords_.push_back({info.uv[0], info.uv[2], info.uv[1], info.uv[3]});
            else
                texcoords_.push_back({info.uv[0], info.uv[1], info.uv[2], info.uv[3]});
            ranges_.push_back(instance.displaced ? scene.displacement.patch_range(info.uv) : DisplacementRange{});
        }
    }
}

void ScenePoser::group_instances(float time_seconds) {
    const Scene& scene = *scene_;
    const std::size_t n = scene.instances.size();
    order_.resize(n);
    times_.resize(n);
    const float rest_time = -std::numeric_limits<float>::infinity();
    for (std::size_t i = 0; i < n; ++i) {
        const SceneInstance& instance = scene.instances[i];
        const bool animated = instance.deforms && scene.models.at(instance.model).subdiv.has_value();
        times_[i] = animated ? time_seconds + instance.time_offset : rest_time;
        order_[i] = i;
    }
    std::sort(order_.begin(), order_.end(), [&](std::size_t a, std::size_t b) {
        const std::size_t ma = scene.instances[a].model, mb = scene.instances[b].model;
        if (ma != mb) return ma < mb;
        if (times_[a] != times_[b]) return times_[a] < times_[b];
        return a < b;
    });
}

const std::vector<PoseModelTables>& ScenePoser::gpu_tables() {
    const Scene& scene = *scene_;
    if (gpu_tables_.size() == scene.models.size()) return gpu_tables_;
    std::vector<PoseModelTables> tables(scene.models.size());
    identity_tables_.assign(scene.models.size(), PointStencils{});
    for (std::size_t m = 0; m < scene.models.size(); ++m) {
        const LoadedModel& model = scene.models[m];
        if (model.split_levels > 0)
            throw Error(model.name + ": posing by stencils needs unsplit patches (--split " +
                        std::to_string(model.split_levels) + " splits them after the stencils)");
        PoseModelTables& t = tables[m];
        for (const PatchInfo& info : model.rest.info) t.tangent_index.push_back(info.tangent_index);
        if (model.subdiv) {
            t.patch_points = &model.subdiv->patch_points;
            t.tangent_points = &model.subdiv->tangent_points;
            t.vertex_count = static_cast<std::uint32_t>(model.subdiv->mesh.positions.size());
            continue;
        }
        // No control mesh: the rest control points are the "vertices", each row one of them
        // with weight 1 (1 * v is exact in double, and so is its rounding back to float).
        PointStencils& identity = identity_tables_[m];
        std::uint32_t v = 0;
        for (const BezierPatch& patch : model.rest.patches)
            for (const Vec4& c : patch.cp) {
                if (c.w != 1.0f)
                    throw Error(model.name + ": posing by stencils needs control points with w = 1 (a rational patch)");
                identity.add_row({{v++, 1.0f}});
            }
        t.patch_points = &identity;
        t.tangent_points = &no_tangents_;
        t.vertex_count = v;
        for (std::int32_t index : t.tangent_index)
            if (index >= 0) throw Error(model.name + ": tangent patches without a control mesh");
    }
    gpu_tables_ = std::move(tables);
    return gpu_tables_;
}

const PoseMeshes& ScenePoser::gpu_meshes(float time_seconds) {
    const Scene& scene = *scene_;
    const std::size_t n = scene.instances.size();
    group_instances(time_seconds);
    meshes_.vertices.clear();
    meshes_.first_vertex.resize(n);
    meshes_.to_world.resize(n);
    meshes_.mirrored.resize(n);
    const float rest_time = -std::numeric_limits<float>::infinity();
    bool have_group = false;
    std::size_t group_model = 0, group_first = 0;
    float group_time = 0;
    for (std::size_t i : order_) {
        const SceneInstance& instance = scene.instances[i];
        const LoadedModel& model = scene.models.at(instance.model);
        if (!have_group || group_model != instance.model || !(group_time == times_[i])) {
            group_first = meshes_.vertices.size();
            if (!model.subdiv) {
                for (const BezierPatch& patch : model.rest.patches)
                    for (const Vec4& c : patch.cp) meshes_.vertices.push_back({c.x, c.y, c.z});
            } else if (times_[i] == rest_time) {
                const std::vector<Vec3>& rest = model.subdiv->mesh.positions;
                meshes_.vertices.insert(meshes_.vertices.end(), rest.begin(), rest.end());
            } else {
                animate(model.subdiv->mesh.positions, times_[i], scene.animation, positions_);
                meshes_.vertices.insert(meshes_.vertices.end(), positions_.begin(), positions_.end());
            }
            have_group = true;
            group_model = instance.model;
            group_time = times_[i];
        }
        meshes_.first_vertex[i] = group_first;
        meshes_.to_world[i] = instance_to_frame(instance, time_seconds, scene.frame_origin);
        meshes_.mirrored[i] = instance_mirrors(instance) ? 1 : 0;
    }
    return meshes_;
}

const std::vector<BezierPatch>& ScenePoser::pose(float time_seconds) {
    const Scene& scene = *scene_;
    const std::size_t n = scene.instances.size();
    // Each instance's first patch and first tangent entry (recomputed per call: cheap, and the
    // scene may have been edited since the poser was made).
    tangent_counts_.assign(scene.models.size(), 0);
    for (std::size_t m = 0; m < scene.models.size(); ++m)
        for (const PatchInfo& info : scene.models[m].rest.info) tangent_counts_[m] += info.tangent_index >= 0 ? 1 : 0;
    first_patch_.resize(n);
    first_tangent_.resize(n);
    std::size_t total = 0, total_tangents = 0;
    for (std::size_t i = 0; i < n; ++i) {
        first_patch_[i] = total;
        first_tangent_[i] = total_tangents;
        total += scene.models.at(scene.instances[i].model).rest.patches.size();
        total_tangents += tangent_counts_[scene.instances[i].model];
    }
    order_.resize(n);
    times_.resize(n);
    patches_.resize(total);
    tangent_index_.assign(total, -1);
    depth_.assign(total, 0);
    tangents_.resize(total_tangents);
    // Group the instances by (model, effective time): each group's frame is evaluated once.
    const float rest_time = -std::numeric_limits<float>::infinity();
    group_instances(time_seconds);
    const PatchFrame* frame = nullptr;
    std::size_t frame_model = 0;
    float frame_time = 0;
    for (std::size_t i : order_) {
        const SceneInstance& instance = scene.instances[i];
        const LoadedModel& model = scene.models.at(instance.model);
        if (!frame || frame_model != instance.model || !(frame_time == times_[i])) {
            if (times_[i] == rest_time) {
                frame = &model.rest;
            } else {
                animate(model.subdiv->mesh.positions, times_[i], scene.animation, positions_);
                evaluate_frame(model, positions_, frame_);
                frame = &frame_;
            }
            frame_model = instance.model;
            frame_time = times_[i];
        }
        const Mat4 to_world = instance_to_frame(instance, time_seconds, scene.frame_origin);
        // Tangent vectors map by the linear part of the affine transform (w = 0).
        auto linear = [&](Vec3 d) {
            const Vec4 m = to_world * Vec4{d.x, d.y, d.z, 0.0f};
            return Vec3{m.x, m.y, m.z};
        };
        const bool mirrored = instance_mirrors(instance);  // transposed (see above ScenePoser::ScenePoser)
        std::size_t next = first_patch_[i];
        std::size_t next_tangent = first_tangent_[i];
        for (std::size_t p = 0; p < frame->patches.size(); ++p) {
            BezierPatch& out = patches_[next];
            const BezierPatch& in = frame->patches[p];
            if (mirrored) {
                for (int j = 0; j < 4; ++j)
                    for (int k = 0; k < 4; ++k) out.cp[4 * j + k] = to_world * in.cp[4 * k + j];
            } else {
                for (int k = 0; k < kPatchPoints; ++k) out.cp[k] = to_world * in.cp[k];
            }
            depth_[next] = frame->info[p].depth;
            const std::int32_t t = frame->info[p].tangent_index;
            if (t >= 0) {
                TangentPatches& mapped = tangents_[next_tangent];
                const TangentPatches& source = frame->tangents[static_cast<std::size_t>(t)];
                if (mirrored) {
                    for (int j = 0; j < 4; ++j)
                        for (int k = 0; k < 3; ++k) mapped.du[3 * j + k] = linear(source.dv[4 * k + j]);
                    for (int j = 0; j < 3; ++j)
                        for (int k = 0; k < 4; ++k) mapped.dv[4 * j + k] = linear(source.du[3 * k + j]);
                } else {
                    for (int k = 0; k < 12; ++k)
                        mapped.du[k] = linear(source.du[k]), mapped.dv[k] = linear(source.dv[k]);
                }
                tangent_index_[next] = static_cast<std::int32_t>(next_tangent);
                ++next_tangent;
            }
            ++next;
        }
    }
    return patches_;
}

}  // namespace patchcull
