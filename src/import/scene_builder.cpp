// Building blocks of the scene builders (scene_builder.h) and the public environment builders
// (patchcull/import/builtin_scenes.h: add_environment_object, add_environment_box).
#include "scene_builder.h"

#include <algorithm>
#include <cmath>

#include "patchcull/core/error.h"
#include "patchcull/import/builtin_scenes.h"

namespace patchcull {
namespace detail {

Mat4 translation(Vec3 t) {
    Mat4 m;
    m.at(0, 3) = t.x;
    m.at(1, 3) = t.y;
    m.at(2, 3) = t.z;
    return m;
}

Mat4 scaling(float s) {
    Mat4 m;
    m.at(0, 0) = m.at(1, 1) = m.at(2, 2) = s;
    return m;
}

Mat4 rotation_y(float degrees) {
    const float a = degrees * kPi / 180.0f;
    Mat4 m;
    m.at(0, 0) = std::cos(a);
    m.at(0, 2) = std::sin(a);
    m.at(2, 0) = -std::sin(a);
    m.at(2, 2) = std::cos(a);
    return m;
}

Mat4 teapot_to_y_up() {
    Mat4 m;
    m.at(1, 1) = 0;
    m.at(1, 2) = 1;
    m.at(2, 1) = -1;
    m.at(2, 2) = 0;
    return m;
}

Bounds transformed_bounds(const PatchFrame& frame, const Mat4& m) {
    std::vector<Vec3> points;
    points.reserve(frame.patches.size() * kPatchPoints);
    for (const BezierPatch& p : frame.patches)
        for (const Vec4& c : p.cp) points.push_back(cartesian(m * c));
    return compute_bounds(points);
}

Mat4 standing_transform(const LoadedModel& model, float height) {
    const Mat4 up = model.subdiv ? Mat4{} : teapot_to_y_up();
    const Bounds b = transformed_bounds(model.rest, up);
    const float extent = b.max.y - b.min.y;
    if (!(extent > 0)) throw Error(model.name + ": the model has no height (all control points at one y)");
    const float s = height / extent;
    const Vec3 base{0.5f * (b.min.x + b.max.x), b.min.y, 0.5f * (b.min.z + b.max.z)};
    return scaling(s) * translation(-base) * up;
}

void add_triangles(Scene& scene, std::string name, const std::vector<Vec3>& vertices,
                   const std::vector<std::uint32_t>& indices, bool one_sided) {
    const auto base = static_cast<std::uint32_t>(scene.occluder_vertices.size());
    EnvironmentObject object;
    object.name = std::move(name);
    object.first_triangle = static_cast<std::uint32_t>(scene.occluder_indices.size() / 3);
    object.triangle_count = static_cast<std::uint32_t>(indices.size() / 3);
    object.one_sided = one_sided;
    scene.occluder_vertices.insert(scene.occluder_vertices.end(), vertices.begin(), vertices.end());
    for (std::uint32_t i : indices) scene.occluder_indices.push_back(base + i);
    scene.environment.push_back(std::move(object));
}

void add_box(Scene& scene, std::string name, Vec3 lo, Vec3 hi) {
    std::vector<Vec3> vertices;
    vertices.reserve(8);
    for (int i = 0; i < 8; ++i)
        vertices.push_back({(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z});
    // Faces as corner quads (bit 0 = x, bit 1 = y, bit 2 = z), each counter-clockwise seen from
    // outside: -x, +x, -y, +y, -z, +z (tests check the signed volume is the box's).
    const std::uint32_t quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                       {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    std::vector<std::uint32_t> indices;
    for (const auto& q : quads)
        for (int k : {0, 1, 2, 0, 2, 3}) indices.push_back(q[k]);
    add_triangles(scene, std::move(name), vertices, indices, true);
}

void add_quad(Scene& scene, std::string name, const Vec3 corners[4], bool one_sided) {
    add_triangles(scene, std::move(name), {corners[0], corners[1], corners[2], corners[3]}, {0, 1, 2, 0, 2, 3},
                  one_sided);
}

void add_ground(Scene& scene, float half_size) {
    const float y = -0.002f;
    const float h = half_size;
    // Counter-clockwise seen from +y.
    const Vec3 corners[4] = {{-h, y, -h}, {-h, y, h}, {h, y, h}, {h, y, -h}};
    add_quad(scene, "ground", corners, true);
}

void load_characters(Scene& scene, Scheme scheme) {
    scene.models.push_back(load_model(shipped_model_path("bigguy.obj"), scheme, 0));
    scene.models.push_back(load_model(shipped_model_path("monsterfrog.obj"), scheme, 0));
}

float animated_reach(const LoadedModel& model, const Mat4& standing, const AnimationParams& animation, int samples) {
    float reach = 0;
    auto measure = [&](const PatchFrame& frame) {
        for (const BezierPatch& p : frame.patches)
            for (const Vec4& c : p.cp) {
                const Vec3 q = cartesian(standing * c);
                reach = std::max(reach, std::hypot(q.x, q.z));
            }
    };
    measure(model.rest);
    if (!model.subdiv) return reach;
    std::vector<Vec3> positions;
    PatchFrame frame;
    for (int k = 0; k < samples; ++k) {
        animate(model.subdiv->mesh.positions,
                animation.period_seconds * static_cast<float>(k) / static_cast<float>(samples), animation, positions);
        evaluate_frame(model, positions, frame);
        measure(frame);
    }
    return reach;
}

}  // namespace detail

using namespace detail;

void add_environment_object(Scene& scene, std::string name, const std::vector<Vec3>& vertices,
                            const std::vector<std::uint32_t>& indices, bool one_sided) {
    if (indices.size() % 3 != 0)
        throw Error(name + ": " + std::to_string(indices.size()) + " indices, not whole triangles");
    for (std::uint32_t i : indices)
        if (i >= vertices.size())
            throw Error(name + ": index " + std::to_string(i) + " beyond the " + std::to_string(vertices.size()) +
                        " vertices");
    add_triangles(scene, std::move(name), vertices, indices, one_sided);
}

void add_environment_box(Scene& scene, std::string name, Vec3 lo, Vec3 hi) { add_box(scene, std::move(name), lo, hi); }

}  // namespace patchcull
