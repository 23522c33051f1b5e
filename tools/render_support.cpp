// The scene of a MODEL argument and the reference frames of the CLI's GPU commands (render_support.h).
#include "render_support.h"

#include "patchcull/import/scene_file.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <string>

#include "commands.h"
#include "patchcull/core/error.h"
#include "patchcull/gl/gl_verification.h"

namespace patchcull::cli {

gl::RenderParams render_params(const Camera& camera, int width, int height, int tess_level, bool one_sided) {
    gl::RenderParams params;
    params.discard_back_facing = one_sided;
    params.view = camera.view();
    params.projection = camera.projection();
    params.depth = camera.depth;
    params.width = width;
    params.height = height;
    params.tess_level = tess_level;
    return params;
}

ReferenceFrame render_reference(gl::PatchRenderer& renderer, const gl::RenderParams& params) {
    gl::RenderParams unculled = params;
    unculled.use_cull_flags = false;
    renderer.finish();
    const auto start = std::chrono::steady_clock::now();
    renderer.render(unculled);
    renderer.finish();
    ReferenceFrame reference;
    reference.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    reference.capture.ids = renderer.read_ids();
    reference.capture.depth = renderer.read_depth();
    reference.capture.patches = renderer.mark_front_patches(unculled);
    return reference;
}

gl::FrameCapture capture_culled_frame(const gl::PatchRenderer& renderer) {
    return {renderer.read_ids(), renderer.read_depth(), renderer.read_drawn_patches()};
}

gl::FrameComparison compare_with_reference(const gl::PatchRenderer& renderer, const ReferenceFrame& reference) {
    return gl::compare_frames(reference.capture, capture_culled_frame(renderer));
}

bool scene_is_one_sided(const Scene& scene) {
    return std::all_of(scene.models.begin(), scene.models.end(), [](const LoadedModel& m) { return m.closed; });
}

gl::PatchAttributes pose_attributes(const ScenePoser& poser) {
    gl::PatchAttributes attributes;
    attributes.tangent_index = poser.tangent_index();
    attributes.tangents = poser.tangents();
    attributes.depth = poser.depth();
    if (!poser.displacement_ranges().empty()) {
        attributes.texcoords = poser.texcoords();
        attributes.displacement_ranges = poser.displacement_ranges();
    }
    return attributes;
}

Scene load_scene(const std::string& model, const std::string& scheme_text, int split) {
    Scheme scheme = Scheme::acc;
    if (!parse_scheme(scheme_text, scheme)) throw Error("--scheme: unknown scheme '" + scheme_text + "'");
    const bool builtin = model == "default" || model == "city" || model == "building";
    const bool file = model.size() > 5 && model.compare(model.size() - 5, 5, ".json") == 0;
    if ((builtin || file) && split != 0)
        throw Error("--split: not available for a scene (" + model + "); it splits a single model");
    const Scene scene = builtin ? make_builtin_scene(model, scheme)
                        : file  ? load_scene_file(model)
                                : make_model_scene(load_model(model, scheme, split));
    for (const LoadedModel& m : scene.models)
        print_warnings(m.warnings);
    return scene;
}

void upload_scene_occluders(gl::PatchRenderer& renderer, const Scene& scene) {
    std::vector<gl::TriangleSpan> one_sided;
    for (const EnvironmentObject& e : scene.environment)
        if (e.one_sided && e.triangle_count) one_sided.push_back({e.first_triangle, e.triangle_count});
    renderer.set_occluders(scene.occluder_vertices, scene.occluder_indices, one_sided);
}

std::vector<SceneObject> scene_objects(const Scene& scene) {
    std::vector<SceneObject> objects;
    std::vector<std::size_t> copies(scene.models.size(), 0);
    std::size_t first = 0;
    for (const SceneInstance& instance : scene.instances) {
        const LoadedModel& model = scene.models.at(instance.model);
        SceneObject o;
        // The instance's own name (unique: every scene builder and the scene file reader set
        // it); else LoadedModel::name (the OBJ path or "teapot") without the extension.
        const std::size_t copy = copies[instance.model]++;
        o.name = !instance.name.empty() ? instance.name
                                        : std::filesystem::path(model.name).stem().string() + "#" + std::to_string(copy);
        o.range.first = first;
        o.range.count = model.rest.patches.size();
        o.range.cull = true;
        first += o.range.count;
        objects.push_back(std::move(o));
    }
    return objects;
}

gl::CullMode applicable_cull_mode(const Scene& scene, gl::CullMode requested, const std::string& command) {
    const std::uint32_t bits = static_cast<std::uint32_t>(requested);
    if ((bits & gl::kCullBackPatch) == 0) return requested;
    for (const LoadedModel& model : scene.models) {
        if (model.closed) continue;
        // Silently: `all` is the default, and the JSON says "backpatch": "off".
        if (requested == gl::CullMode::all) return static_cast<gl::CullMode>(bits & ~gl::kCullBackPatch);
        print_warnings({command + ": " + model.name +
                        " is not a closed solid: back-patch culling may remove patches seen through its openings"});
        return requested;
    }
    return requested;
}

}  // namespace patchcull::cli
