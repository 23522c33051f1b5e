// SceneOcclusion (patchcull/import/scene_occlusion.h): the occlusion horizon and cells and portals on a
// Scene's objects, after its object level.
#include "patchcull/import/scene_occlusion.h"

#include <algorithm>
#include <cmath>

#include "patchcull/core/error.h"
#include "patchcull/core/frustum.h"
#include "patchcull/objects/bounding_volumes.h"

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

// The corner index of v in the box (bit 4: x at max, 2: y, 1: z), or -1 when v is no corner.
int corner_index(const Bounds& box, Vec3 v) {
    auto side = [](float x, float lo, float hi) { return x == lo ? 0 : x == hi ? 1 : -1; };
    const int x = side(v.x, box.min.x, box.max.x), y = side(v.y, box.min.y, box.max.y),
              z = side(v.z, box.min.z, box.max.z);
    return x < 0 || y < 0 || z < 0 ? -1 : 4 * x + 2 * y + z;
}

// The six faces as (axis bit, side): face f = 2 * axis + side, axis 0 x (bit 4), 1 y (bit 2), 2 z (bit 1).
int face_of(int a, int b, int c) {
    for (int axis = 0; axis < 3; ++axis) {
        const int bit = 4 >> axis;
        for (int side = 0; side < 2; ++side) {
            const int want = side ? bit : 0;
            if ((a & bit) == want && (b & bit) == want && (c & bit) == want) return 2 * axis + side;
        }
    }
    return -1;
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
        // Per face, which of its 4 corners each covering triangle leaves out: a face is covered when
        // two of its triangles leave out opposite corners (the two halves of one diagonal split).
        // One-sided objects must show each such triangle from outside (counter-clockwise seen from
        // outside), else drawn with back faces culled that face is open from outside.
        std::uint8_t left_out[6] = {};  // bit k: a triangle of the face leaves out its k-th corner (corner index order)
        bool ok = true;
        for (std::size_t t = object.first_triangle; ok && t < object.first_triangle + object.triangle_count; ++t) {
            const Vec3 a = vertex(t, 0), b = vertex(t, 1), c = vertex(t, 2);
            const int ia = corner_index(box, a), ib = corner_index(box, b), ic = corner_index(box, c);
            ok = ia >= 0 && ib >= 0 && ic >= 0 && ia != ib && ib != ic && ia != ic;
            const int f = ok ? face_of(ia, ib, ic) : -1;
            ok = ok && f >= 0;
            if (!ok) break;
            const int axis = f / 2, bit = 4 >> axis;
            if (object.one_sided) {
                const Vec3 n = cross(b - a, c - a);
                const float outward = (axis == 0 ? n.x : axis == 1 ? n.y : n.z) * (f % 2 ? 1.0f : -1.0f);
                if (!(outward > 0))
                    continue;  // faces inwards: drawn from inside only, covers nothing seen from outside
            }
            // The face's corners in a fixed order: the two other axes' bits, lexicographic.
            int others[2], n_others = 0;
            for (int k = 0; k < 3; ++k)
                if ((4 >> k) != bit) others[n_others++] = 4 >> k;
            const int in_face[3] = {ia, ib, ic};
            int present = 0;
            for (int v : in_face) present |= 1 << (((v & others[0]) ? 2 : 0) + ((v & others[1]) ? 1 : 0));
            const int missing = 0xf & ~present;  // exactly one bit: the corner the triangle leaves out
            left_out[f] |= static_cast<std::uint8_t>(missing);
        }
        // Opposite corners in the face's order: 0 (00) with 3 (11), 1 (01) with 2 (10).
        for (int f = 0; ok && f < 6; ++f) ok = (left_out[f] & 0x9) == 0x9 || (left_out[f] & 0x6) == 0x6;
        if (ok) out.push_back(e);
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
            throw Error("horizon: scene '" + scene.name +
                        "' has no box occluders (environment objects that are closed boxes)");
    }
}

// Portal culling assumes that walls are opaque along every line of sight from the eye. The
// near plane breaks that: a wall (or floor, or any environment box) between the eye and the near
// plane is clipped away, and one-sided walls seen from inside (an eye in a wall) draw nothing, so
// the eye then sees into cells no portal leads to. So when the pyramid from the eye to the near
// plane's rectangle touches an environment object's box, nothing is culled by portals (found by
// probing: an eye 0.03 from a wall with z_near 0.05, or inside a wall, showed the next room).
bool SceneOcclusion::near_pyramid_touches_environment(const Mat4& world_to_clip, Vec3 eye) const {
    Mat4 clip_to_world;
    if (!invert(world_to_clip, clip_to_world)) return true;
    Bounds pyramid{eye, eye};
    for (float x : {-1.0f, 1.0f})
        for (float y : {-1.0f, 1.0f}) {
            const Vec4 h = clip_to_world * Vec4{x, y, 0, 1};  // zero-to-one depth: z = 0 on the near plane
            if (!(std::fabs(h.w) > 0)) return true;
            const Vec3 p = cartesian(h);
            if (!is_finite(p)) return true;
            pyramid.min = {std::min(pyramid.min.x, p.x), std::min(pyramid.min.y, p.y), std::min(pyramid.min.z, p.z)};
            pyramid.max = {std::max(pyramid.max.x, p.x), std::max(pyramid.max.y, p.y), std::max(pyramid.max.z, p.z)};
        }
    pyramid = grow_bounds(pyramid, static_cast<float>(portals_->margin()) + rounding_margin(pyramid));
    const std::vector<Bounds>& boxes = level_->boxes();
    for (std::size_t i = scene_->instances.size(); i < boxes.size(); ++i) {
        const Bounds& b = boxes[i];
        if (b.min.x <= pyramid.max.x && b.max.x >= pyramid.min.x && b.min.y <= pyramid.max.y &&
            b.max.y >= pyramid.min.y && b.min.z <= pyramid.max.z && b.max.z >= pyramid.min.z)
            return true;
    }
    return false;
}

const ObjectCullResult& SceneOcclusion::cull(const ObjectCullResult& result, const Camera& camera, int width,
                                             int height) {
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
        horizon_.cull(world_to_clip, camera.depth, width, height, occluder_boxes_.data(), occluder_boxes_.size(),
                      tested_boxes_.data(), tested_boxes_.size(), occluded_.data(), stats_.horizon);
    } else if (!near_pyramid_touches_environment(to_zero_to_one(world_to_clip, camera.depth), camera.eye)) {
        const FrustumPlanes planes = make_frustum_planes(world_to_clip, camera.depth);
        stats_.eye_in_cell = portals_->traverse(camera.eye, planes, stats_.portals);
        for (std::size_t k = 0; k < tested_boxes_.size(); ++k) occluded_[k] = !portals_->box_visible(tested_boxes_[k]);
    } else {
        stats_.near_geometry = true;  // nothing culled this frame
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
