// SceneOcclusion (patchcull/scene_occlusion.h): the occlusion horizon and cells and portals on a
// Scene's objects, after its object level.
#include "patchcull/scene_occlusion.h"

#include <algorithm>
#include <cmath>

#include "patchcull/bounding_volumes.h"
#include "patchcull/error.h"
#include "patchcull/frustum.h"

namespace patchcull {

const char* scene_occlusion_method_name(SceneOcclusionMethod method) {
    return method == SceneOcclusionMethod::portals ? "portals" : "horizon";
}

bool parse_scene_occlusion_method(const std::string& text, SceneOcclusionMethod& method) {
    for (SceneOcclusionMethod m : {SceneOcclusionMethod::horizon, SceneOcclusionMethod::portals})
        if (text == scene_occlusion_method_name(m)) {
            method = m;
            return true;
        }
    return false;
}

namespace {

bool on_face(const Bounds& box, Vec3 a, Vec3 b, Vec3 c) {
    for (int axis = 0; axis < 3; ++axis) {
        auto get = [axis](Vec3 v) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; };
        for (float side : {get(box.min), get(box.max)})
            if (get(a) == side && get(b) == side && get(c) == side) return true;
    }
    return false;
}

bool is_corner(const Bounds& box, Vec3 v) {
    return (v.x == box.min.x || v.x == box.max.x) && (v.y == box.min.y || v.y == box.max.y) &&
           (v.z == box.min.z || v.z == box.max.z);
}

double triangle_area(Vec3 a, Vec3 b, Vec3 c) {
    const double ux = double(b.x) - a.x, uy = double(b.y) - a.y, uz = double(b.z) - a.z;
    const double vx = double(c.x) - a.x, vy = double(c.y) - a.y, vz = double(c.z) - a.z;
    const double x = uy * vz - uz * vy, y = uz * vx - ux * vz, z = ux * vy - uy * vx;
    return 0.5 * std::sqrt(x * x + y * y + z * z);
}

float rounding_margin(const Bounds& b) {
    const float extent = std::max({std::fabs(b.min.x), std::fabs(b.min.y), std::fabs(b.min.z), std::fabs(b.max.x),
                                   std::fabs(b.max.y), std::fabs(b.max.z)});
    return std::isfinite(extent) ? 8.0f * 0x1p-23f * extent : 0.0f;
}

}  // namespace

std::vector<std::size_t> box_environment_objects(const Scene& scene) {
    std::vector<std::size_t> out;
    for (std::size_t e = 0; e < scene.environment.size(); ++e) {
        const EnvironmentObject& object = scene.environment[e];
        if (object.triangle_count < 12) continue;
        auto vertex = [&](std::size_t t, int k) {
            return scene.occluder_vertices[scene.occluder_indices[3 * t + static_cast<std::size_t>(k)]];
        };
        Bounds box{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
        for (std::size_t t = object.first_triangle; t < object.first_triangle + object.triangle_count; ++t)
            for (int k = 0; k < 3; ++k) {
                const Vec3 v = vertex(t, k);
                box.min = {std::min(box.min.x, v.x), std::min(box.min.y, v.y), std::min(box.min.z, v.z)};
                box.max = {std::max(box.max.x, v.x), std::max(box.max.y, v.y), std::max(box.max.z, v.z)};
            }
        if (!is_finite(box.min) || !is_finite(box.max) || !(box.min.x < box.max.x) || !(box.min.y < box.max.y) ||
            !(box.min.z < box.max.z))
            continue;
        bool ok = true;
        double area = 0;
        for (std::size_t t = object.first_triangle; ok && t < object.first_triangle + object.triangle_count; ++t) {
            const Vec3 a = vertex(t, 0), b = vertex(t, 1), c = vertex(t, 2);
            ok = is_corner(box, a) && is_corner(box, b) && is_corner(box, c) && on_face(box, a, b, c);
            area += triangle_area(a, b, c);
        }
        const double dx = double(box.max.x) - box.min.x, dy = double(box.max.y) - box.min.y,
                     dz = double(box.max.z) - box.min.z;
        const double surface = 2 * (dx * dy + dy * dz + dz * dx);
        // Corner triangles on faces tile a face exactly when their areas add up to it (two per
        // face); a missing face leaves the sum short, a doubled one (two-sided copies) is allowed.
        if (ok && area >= surface * (1 - 1e-5)) out.push_back(e);
    }
    return out;
}

void merge_spans(std::vector<IndexSpan>& spans) {
    std::sort(spans.begin(), spans.end(), [](const IndexSpan& a, const IndexSpan& b) { return a.first < b.first; });
    std::size_t out = 0;
    for (const IndexSpan& s : spans) {
        if (s.count == 0) continue;
        if (out > 0 && s.first <= spans[out - 1].first + spans[out - 1].count) {
            IndexSpan& last = spans[out - 1];
            last.count = std::max(last.first + last.count, s.first + s.count) - last.first;
        } else {
            spans[out++] = s;
        }
    }
    spans.resize(out);
}

SceneOcclusion::SceneOcclusion(const Scene& scene, const SceneObjectLevel& level, SceneOcclusionMethod method)
    : scene_(&scene), level_(&level), method_(method) {
    if (method == SceneOcclusionMethod::portals) {
        if (scene.cells.empty()) throw Error("portals: scene '" + scene.name + "' has no cells");
        std::vector<Bounds> cells;
        for (const SceneCell& c : scene.cells) cells.push_back(c.box);
        std::vector<CellPortal> portals;
        for (const ScenePortal& p : scene.portals) {
            CellPortal cp;
            cp.cell_a = static_cast<std::uint32_t>(p.cell_a);
            cp.cell_b = static_cast<std::uint32_t>(p.cell_b);
            std::copy(std::begin(p.corners), std::end(p.corners), cp.corners);
            portals.push_back(cp);
        }
        portals_ = std::make_unique<PortalCuller>(std::move(cells), std::move(portals));
    } else {
        const std::size_t instances = scene.instances.size();
        for (std::size_t e : box_environment_objects(scene)) occluder_objects_.push_back(instances + e);
        if (occluder_objects_.empty())
            throw Error("horizon: scene '" + scene.name + "' has no box occluders (environment objects that are closed boxes)");
    }
}

const ObjectCullResult& SceneOcclusion::cull(const ObjectCullResult& result, const Camera& camera, int width, int height) {
    const std::vector<Bounds>& boxes = level_->boxes();
    const ObjectCuller& culler = level_->culler();
    const std::size_t n = culler.object_count();
    stats_ = {};
    hidden_.assign(n, 0);
    out_ = result;
    // The objects the object level left whole (verdict visible, or no verdicts: level off).
    tested_objects_.clear();
    tested_boxes_.clear();
    for (std::size_t i = 0; i < n; ++i)
        if (result.verdicts.empty() || result.verdicts[i] == ObjectVerdict::visible) {
            tested_objects_.push_back(i);
            tested_boxes_.push_back(boxes[i]);
        }
    stats_.objects_tested = tested_objects_.size();
    // The GPU draws the occluders and the objects in float: a vertex lands within a few ulps of
    // its largest coordinate of where it should. The horizon's margins are in pixels; so that this
    // rounding can never widen an occluder or narrow an object past them, occluders shrink and
    // objects grow by 8 ulps of their largest coordinate (nothing at the built-in scenes' sizes).
    for (Bounds& b : tested_boxes_) b = grow_bounds(b, rounding_margin(b));
    occluded_.assign(tested_objects_.size(), 0);
    const Mat4 world_to_clip = camera.projection() * camera.view();
    if (method_ == SceneOcclusionMethod::horizon) {
        // Occluders culled whole by the object level are not drawn: they may hide nothing.
        occluder_boxes_.clear();
        for (std::size_t o : occluder_objects_)
            if (result.verdicts.empty() || result.verdicts[o] == ObjectVerdict::visible) {
                Bounds b = boxes[o];
                const float m = rounding_margin(b);
                b.min = b.min + Vec3{m, m, m};
                b.max = b.max - Vec3{m, m, m};
                if (b.min.x <= b.max.x && b.min.y <= b.max.y && b.min.z <= b.max.z) occluder_boxes_.push_back(b);
            }
        horizon_.cull(world_to_clip, ClipDepth::zero_to_one, width, height, occluder_boxes_.data(), occluder_boxes_.size(),
                      tested_boxes_.data(), tested_boxes_.size(), occluded_.data(), stats_.horizon);
    } else {
        const FrustumPlanes planes = make_frustum_planes(world_to_clip, ClipDepth::zero_to_one);
        stats_.eye_in_cell = portals_->traverse(camera.eye, planes, stats_.portals);
        for (std::size_t k = 0; k < tested_boxes_.size(); ++k) occluded_[k] = !portals_->box_visible(tested_boxes_[k]);
    }
    for (std::size_t k = 0; k < tested_objects_.size(); ++k) {
        if (!occluded_[k]) continue;
        const std::size_t i = tested_objects_[k];
        hidden_[i] = 1;
        ++stats_.objects_culled;
        const CullableObject& object = culler.object(i);
        if (object.triangles) {
            out_.culled_triangles.push_back(object.span);
            stats_.triangles_culled += object.span.count;
        } else {
            out_.culled_patches.push_back(object.span);
            stats_.patches_culled += object.span.count;
        }
    }
    merge_spans(out_.culled_patches);
    merge_spans(out_.culled_triangles);
    return out_;
}

SceneTightBounds::SceneTightBounds(const Scene& scene, const std::vector<BezierPatch>& pose,
                                   const std::vector<DisplacementRange>& ranges) {
    if (pose.size() != scene.patch_count())
        throw Error("tight bounds: the pose has " + std::to_string(pose.size()) + " patches, the scene " +
                    std::to_string(scene.patch_count()));
    patch_boxes(pose, ranges);
    std::size_t first = 0;
    for (const SceneInstance& instance : scene.instances) {
        const std::size_t count = scene.models[instance.model].rest.patches.size();
        firsts_.push_back(first);
        trees_.emplace_back();
        trees_.back().build(boxes_.data() + first, count);
        first += count;
    }
    firsts_.push_back(first);
}

void SceneTightBounds::update(const std::vector<BezierPatch>& pose, const std::vector<DisplacementRange>& ranges,
                              float sigma, std::size_t max_boxes) {
    if (pose.size() != boxes_.size())
        throw Error("tight bounds: the pose has " + std::to_string(pose.size()) + " patches, not " +
                    std::to_string(boxes_.size()));
    patch_boxes(pose, ranges);
    tight_.clear();
    tight_first_.assign(1, 0);
    for (std::size_t i = 0; i < trees_.size(); ++i) {
        trees_[i].refit(boxes_.data() + firsts_[i]);
        trees_[i].select(sigma, max_boxes, tight_);
        tight_first_.push_back(static_cast<std::uint32_t>(tight_.size()));
    }
}

void SceneTightBounds::patch_boxes(const std::vector<BezierPatch>& pose, const std::vector<DisplacementRange>& ranges) {
    boxes_.resize(pose.size());
    for (std::size_t p = 0; p < pose.size(); ++p) {
        Bounds b{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
        for (const Vec4& c : pose[p].cp) {
            const Vec3 q = cartesian(c);
            b.min = {std::min(b.min.x, q.x), std::min(b.min.y, q.y), std::min(b.min.z, q.z)};
            b.max = {std::max(b.max.x, q.x), std::max(b.max.y, q.y), std::max(b.max.z, q.z)};
        }
        if (!ranges.empty() && ranges[p].max_abs() > 0) b = grow_bounds(b, ranges[p].max_abs());
        boxes_[p] = b;
    }
}

}  // namespace patchcull
