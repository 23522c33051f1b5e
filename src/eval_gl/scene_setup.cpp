// A scene as the evaluation runs draw it (scene_setup.h).
#include "patchcull/eval_gl/scene_setup.h"

#include <algorithm>
#include <filesystem>

namespace patchcull::eval_gl {

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
        const std::size_t copy = copies[instance.model]++;
        o.name = !instance.name.empty()
                     ? instance.name
                     : std::filesystem::path(model.name).stem().string() + "#" + std::to_string(copy);
        o.range.first = first;
        o.range.count = model.rest.patches.size();
        o.range.cull = true;
        first += o.range.count;
        objects.push_back(std::move(o));
    }
    return objects;
}

}  // namespace patchcull::eval_gl
