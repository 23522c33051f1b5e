// Posing a scene into the renderer frame by frame (frame_poser.h).
#include "frame_poser.h"

#include <algorithm>
#include <chrono>

#include "patchcull/core/error.h"
#include "patchcull/eval_gl/scene_setup.h"

namespace patchcull::cli {

PoseWhere parse_pose_where(const std::string& flag, const std::string& text) {
    if (text == "cpu") return PoseWhere::cpu;
    if (text == "gpu") return PoseWhere::gpu;
    throw Error(flag + ": unknown value '" + text + "' (cpu or gpu)");
}

const char* pose_where_name(PoseWhere where) { return where == PoseWhere::gpu ? "gpu" : "cpu"; }

struct FramePoser::Gpu {
    explicit Gpu(const gl::GlContext& context) : poser(context) {}
    gl::StencilPoser poser;
};

namespace {

gl::StencilTableView table_view(const PointStencils& s) {
    return {s.offsets.data(), s.rows(), s.indices.data(), s.weights.data()};
}

}  // namespace

FramePoser::FramePoser(const gl::GlContext& context, ScenePoser& poser, gl::PatchRenderer& renderer, PoseWhere where,
                       bool cpu_patches)
    : poser_(&poser), renderer_(&renderer), where_(where), cpu_patches_(cpu_patches) {
    if (where != PoseWhere::gpu) return;
    const std::vector<PoseModelTables>* tables_or_null = nullptr;
    try {
        tables_or_null = &poser.gpu_tables();
    } catch (const Error& e) {
        throw Error(std::string("--pose gpu: ") + e.what());  // the flag that asked for it
    }
    const std::vector<PoseModelTables>& tables = *tables_or_null;
    std::vector<gl::PosingModel> models;
    models.reserve(tables.size());
    for (const PoseModelTables& t : tables)
        models.push_back({table_view(*t.patch_points), table_view(*t.tangent_points), t.tangent_index, t.vertex_count});
    std::vector<std::uint32_t> instance_models;
    for (const SceneInstance& instance : poser.scene().instances)
        instance_models.push_back(static_cast<std::uint32_t>(instance.model));
    gpu_ = std::make_unique<Gpu>(context);
    gpu_->poser.set_tables(models, instance_models);
}

FramePoser::~FramePoser() = default;

const std::vector<BezierPatch>* FramePoser::pose(float time_seconds) {
    using clock = std::chrono::steady_clock;
    const auto start = clock::now();
    cost_ = {};
    cost_.where = where_;
    const std::vector<BezierPatch>* patches = nullptr;
    if (first_ || where_ == PoseWhere::cpu || cpu_patches_) {
        patches = &poser_->pose(time_seconds);
        cost_.cpu_patches = true;
    }
    if (first_) {
        renderer_->set_patches(*patches, eval_gl::pose_attributes(*poser_));
        cost_.bytes_uploaded += renderer_->last_upload_bytes();
    } else if (where_ == PoseWhere::cpu) {
        renderer_->update_patches(*patches, eval_gl::pose_attributes(*poser_));
        cost_.bytes_uploaded += renderer_->last_upload_bytes();
    }
    if (where_ == PoseWhere::gpu) {
        // Frame 0 too: its patches are then the GPU's (equal to the upload, which brought the
        // attributes).
        const auto meshes_start = clock::now();
        const PoseMeshes& meshes = poser_->gpu_meshes(time_seconds);
        cost_.meshes_ms = std::chrono::duration<double, std::milli>(clock::now() - meshes_start).count();
        instances_.resize(meshes.first_vertex.size());
        for (std::size_t i = 0; i < instances_.size(); ++i)
            instances_[i] = {meshes.first_vertex[i], meshes.to_world[i], meshes.mirrored[i] != 0};
        gpu_->poser.pose(meshes.vertices, instances_, renderer_->patch_buffer(), renderer_->tangent_buffer());
        cost_.bytes_uploaded += gpu_->poser.last_upload_bytes();
    }
    first_ = false;
    cost_.cpu_ms = std::chrono::duration<double, std::milli>(clock::now() - start).count();
    renderer_->finish();
    cost_.done_ms = std::chrono::duration<double, std::milli>(clock::now() - start).count();
    return patches;
}

std::size_t displaced_patch_count(const ScenePoser& poser) {
    const std::vector<DisplacementRange>& ranges = poser.displacement_ranges();
    return static_cast<std::size_t>(std::count_if(
        ranges.begin(), ranges.end(), [](const DisplacementRange& r) { return r.d_min != 0 || r.d_max != 0; }));
}

}  // namespace patchcull::cli
