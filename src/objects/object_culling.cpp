// The object level before patch culling (patchcull/objects/object_culling.h).
//
// Order of the tests in one frame: the frustum test of every object (flat or BVH; both return,
// object for object, classify_aabb's answer, so the method changes the cost and never the
// decision), detail culling of the objects that remain (when asked for), then the clustered
// back-face test of the remaining objects that have clusters. Culled spans are collected in
// object order and sorted once (objects may list their spans in any order).
#include "patchcull/objects/object_culling.h"

#include <algorithm>

#include "patchcull/core/error.h"

namespace patchcull {

const char* object_cull_method_name(ObjectCullMethod method) {
    switch (method) {
        case ObjectCullMethod::none:
            return "none";
        case ObjectCullMethod::frustum:
            return "frustum";
        case ObjectCullMethod::bvh:
            return "bvh";
        case ObjectCullMethod::bvh_backface:
            return "bvh+backface";
    }
    return "?";
}

bool parse_object_cull_method(const std::string& text, ObjectCullMethod& method) {
    for (ObjectCullMethod m :
         {ObjectCullMethod::none, ObjectCullMethod::frustum, ObjectCullMethod::bvh, ObjectCullMethod::bvh_backface})
        if (text == object_cull_method_name(m)) {
            method = m;
            return true;
        }
    return false;
}

const char* object_volume_name(ObjectVolume v) {
    switch (v) {
        case ObjectVolume::aabb:
            return "aabb";
        case ObjectVolume::sphere:
            return "sphere";
        case ObjectVolume::obb:
            return "obb";
    }
    return "?";
}

bool parse_object_volume(const std::string& text, ObjectVolume& v) {
    for (ObjectVolume x : {ObjectVolume::aabb, ObjectVolume::sphere, ObjectVolume::obb})
        if (text == object_volume_name(x)) {
            v = x;
            return true;
        }
    return false;
}

const char* triangle_backface_name(TriangleBackface t) {
    switch (t) {
        case TriangleBackface::clusters:
            return "clusters";
        case TriangleBackface::normal_masks:
            return "masks";
        case TriangleBackface::per_triangle:
            return "triangles";
    }
    return "?";
}

bool parse_triangle_backface(const std::string& text, TriangleBackface& t) {
    for (TriangleBackface v :
         {TriangleBackface::clusters, TriangleBackface::normal_masks, TriangleBackface::per_triangle})
        if (text == triangle_backface_name(v)) {
            t = v;
            return true;
        }
    return false;
}

namespace {

void check_disjoint(const std::vector<CullableObject>& objects, bool triangles) {
    std::vector<IndexSpan> spans;
    for (const CullableObject& o : objects)
        if (o.triangles == triangles && o.span.count) spans.push_back(o.span);
    std::sort(spans.begin(), spans.end(), [](const IndexSpan& a, const IndexSpan& b) { return a.first < b.first; });
    for (std::size_t i = 1; i < spans.size(); ++i)
        if (spans[i].first < spans[i - 1].first + spans[i - 1].count)
            throw Error(std::string("object level: two objects share ") + (triangles ? "triangle " : "patch ") +
                        std::to_string(spans[i].first));
}

// Appends [first, first + count) to spans, merging with the last span when they touch.
void append_span(std::vector<IndexSpan>& spans, std::size_t first, std::size_t count) {
    if (count == 0) return;
    if (!spans.empty() && spans.back().first + spans.back().count == first) {
        spans.back().count += count;
        return;
    }
    spans.push_back({first, count});
}

void sort_and_merge(std::vector<IndexSpan>& spans) {
    std::sort(spans.begin(), spans.end(), [](const IndexSpan& a, const IndexSpan& b) { return a.first < b.first; });
    std::size_t out = 0;
    for (std::size_t i = 0; i < spans.size(); ++i) {
        if (out > 0 && spans[out - 1].first + spans[out - 1].count == spans[i].first)
            spans[out - 1].count += spans[i].count;
        else
            spans[out++] = spans[i];
    }
    spans.resize(out);
}

Vec3 transform_point(const Mat4& m, Vec3 p) { return cartesian(m * Vec4{p.x, p.y, p.z, 1.0f}); }

}  // namespace

ObjectCuller::ObjectCuller(std::vector<CullableObject> objects)
    : objects_(std::move(objects)),
      clusters_(objects_.size()),
      object_space_(objects_.size(), 0),
      flat_states_(objects_.size()),
      containment_(objects_.size()) {
    check_disjoint(objects_, false);
    check_disjoint(objects_, true);
}

void ObjectCuller::set_clusters(std::size_t object, ClusterHierarchy clusters, bool object_space) {
    if (object >= objects_.size()) throw Error("object level: set_clusters: no object " + std::to_string(object));
    const std::size_t members = objects_[object].span.count;
    for (std::size_t leaf = 0; leaf < cluster_leaf_count(clusters); ++leaf) {
        const BackfaceCluster& c = cluster_leaf(clusters, leaf);
        if (c.first > members || c.count > members - c.first)
            throw Error("object level: " + objects_[object].name + ": cluster [" + std::to_string(c.first) + ", +" +
                        std::to_string(c.count) + ") leaves the object's " + std::to_string(members) + " members");
    }
    clusters_[object] = std::move(clusters);
    object_space_[object] = object_space ? 1 : 0;
}

void ObjectCuller::set_triangle_mesh(std::vector<Vec3> vertices, std::vector<std::uint32_t> indices) {
    if (indices.size() % 3 != 0) throw Error("object level: set_triangle_mesh: indices not a multiple of 3");
    for (std::uint32_t i : indices)
        if (i >= vertices.size())
            throw Error("object level: set_triangle_mesh: index " + std::to_string(i) + " out of range");
    for (const CullableObject& o : objects_)
        if (o.triangles && o.span.first + o.span.count > indices.size() / 3)
            throw Error("object level: " + o.name + ": its triangles leave the mesh");
    mesh_vertices_ = std::move(vertices);
    mesh_indices_ = std::move(indices);
    triangle_classes_.resize(mesh_indices_.size() / 3);
    mask_grid_.classify_triangles(mesh_vertices_.data(), mesh_indices_.data(), triangle_classes_.size(),
                                  triangle_classes_.data());
}

// The normal-mask or per-triangle back-face test of one triangle object: runs of culled
// triangles become spans. Returns the triangles culled.
std::size_t ObjectCuller::cull_triangles_individually(std::size_t object, const ObjectFrame& frame,
                                                      const ObjectCullOptions& options,
                                                      std::vector<IndexSpan>& culled) {
    const IndexSpan span = objects_[object].span;
    if (span.count == 0 || mesh_indices_.size() < 3 * (span.first + span.count)) return 0;
    triangle_culled_.resize(span.count);
    if (options.triangle_backface == TriangleBackface::per_triangle) {
        cull_backfacing_triangles_simd(mesh_vertices_.data(), mesh_indices_.data() + 3 * span.first, span.count,
                                       frame.eye, triangle_culled_.data());
    } else {
        // The sector mask when the object's box projects into one sector (every corner in
        // front of the eye and in that sector: then every triangle has a point there), else the
        // whole frustum's.
        const int sectors = std::max(1, options.mask_sectors);
        std::size_t mask = 0;
        if (sectors > 1) {
            const Bounds& b = frame.boxes[object];
            int sector = -2;
            for (int k = 0; k < 8 && sector != -1; ++k) {
                const Vec3 corner{(k & 1) ? b.max.x : b.min.x, (k & 2) ? b.max.y : b.min.y,
                                  (k & 4) ? b.max.z : b.min.z};
                const int s = sector_of_point(frame.world_to_clip, corner, sectors);
                sector = (sector == -2 || sector == s) ? s : -1;
            }
            if (sector >= 0) mask = 1 + static_cast<std::size_t>(sector);
        }
        cull_by_normal_mask_simd(triangle_classes_.data() + span.first, span.count, masks_[mask],
                                 triangle_culled_.data());
    }
    result_.stats.triangle_tests += span.count;
    std::size_t count = 0;
    for (std::size_t t = 0; t < span.count; ++t)
        if (triangle_culled_[t]) {
            append_span(culled, span.first + t, 1);
            ++count;
        }
    return count;
}

const ObjectCullResult& ObjectCuller::cull(const ObjectFrame& frame, const ObjectCullOptions& options) {
    const std::size_t n = objects_.size();
    ObjectCullResult& r = result_;
    r.verdicts.assign(n, ObjectVerdict::visible);
    r.culled_patches.clear();
    r.culled_triangles.clear();
    r.stats = {};
    r.stats.total = n;
    if (options.method == ObjectCullMethod::none || n == 0) return r;
    if (!frame.boxes) throw Error("object level: cull: no object boxes");

    // 1. Frustum: each object's AABB (flat list or BVH: the same answers).
    const FrustumPlanes planes = make_frustum_planes(frame.world_to_clip, frame.depth);
    ObjectBvh::Stats bvh_stats;
    if (options.method == ObjectCullMethod::frustum) {
        cull_objects_flat(planes, frame.boxes, n, flat_states_.data(), options.coherence, containment_.data(),
                          bvh_stats);
    } else {
        if (!bvh_built_ || bvh_.object_count() != n) {
            bvh_.build(frame.boxes, n);
            bvh_built_ = true;
        } else {
            bvh_.refit(frame.boxes);
        }
        bvh_.cull(planes, {options.plane_masking, options.coherence}, containment_.data(), bvh_stats);
    }
    r.stats.plane_tests = bvh_stats.plane_tests;
    r.stats.bvh_nodes_visited = bvh_stats.nodes_visited;
    for (std::size_t i = 0; i < n; ++i)
        if (containment_[i] == Containment::outside) r.verdicts[i] = ObjectVerdict::frustum;
    // The object's own sphere or OBB, for the objects its AABB left in.
    if (options.volume != ObjectVolume::aabb) {
        const bool sphere = options.volume == ObjectVolume::sphere;
        if (sphere ? !frame.spheres : !frame.obbs)
            throw Error(std::string("object level: cull: no object ") + object_volume_name(options.volume) + "s");
        for (std::size_t i = 0; i < n; ++i) {
            if (r.verdicts[i] != ObjectVerdict::visible) continue;
            PlaneCullState fresh;
            const Containment c = sphere ? classify_sphere(planes, frame.spheres[i], fresh, r.stats.plane_tests)
                                         : classify_obb(planes, frame.obbs[i], fresh, r.stats.plane_tests);
            if (c == Containment::outside) {
                r.verdicts[i] = ObjectVerdict::frustum;
                ++r.stats.volume_rejected;
            }
        }
    }
    // Meta-BVs: the frustum's bounding sphere and box reject what the planes' n/p-vertex test
    // calls intersecting beyond a frustum edge (the lecture's false negatives).
    if (options.meta_bvs) {
        const FrustumMetaBounds meta = frustum_meta_bounds(frame.world_to_clip, frame.depth);
        for (std::size_t i = 0; i < n; ++i)
            if (r.verdicts[i] == ObjectVerdict::visible && meta_rejects(meta, frame.boxes[i])) {
                r.verdicts[i] = ObjectVerdict::frustum;
                ++r.stats.meta_rejected;
            }
    }
    const bool individual = options.method == ObjectCullMethod::bvh_backface &&
                            options.triangle_backface != TriangleBackface::clusters && !mesh_indices_.empty();
    if (individual && options.triangle_backface == TriangleBackface::normal_masks) {
        const int sectors = std::max(1, options.mask_sectors);
        masks_.resize(1 + static_cast<std::size_t>(sectors > 1 ? sectors * sectors : 0));
        make_back_mask(mask_grid_, frame.world_to_clip, frame.depth, 0, 0, 1, masks_[0]);
        if (sectors > 1)
            for (int y = 0; y < sectors; ++y)
                for (int x = 0; x < sectors; ++x)
                    make_back_mask(mask_grid_, frame.world_to_clip, frame.depth, x, y, sectors,
                                   masks_[1 + static_cast<std::size_t>(y * sectors + x)]);
    }

    // 2. Detail culling (not conservative), of the objects still in.
    if (options.detail_min_pixels > 0)
        for (std::size_t i = 0; i < n; ++i)
            if (r.verdicts[i] == ObjectVerdict::visible &&
                detail_culled(sphere_of_aabb(frame.boxes[i]), frame.eye, frame.pixel_scale, options.detail_min_pixels))
                r.verdicts[i] = ObjectVerdict::detail;

    // 3. Clustered back-face culling of the rest.
    for (std::size_t i = 0; i < n; ++i) {
        const CullableObject& o = objects_[i];
        std::vector<IndexSpan>& culled = o.triangles ? r.culled_triangles : r.culled_patches;
        if (r.verdicts[i] != ObjectVerdict::visible) {
            append_span(culled, o.span.first, o.span.count);
            continue;
        }
        if (options.method != ObjectCullMethod::bvh_backface || clusters_[i].nodes.empty()) continue;
        if (frame.clusters_usable && !frame.clusters_usable[i]) continue;
        if (o.triangles && individual) {
            if (cull_triangles_individually(i, frame, options, culled) == o.span.count)
                r.verdicts[i] = ObjectVerdict::backface;
            continue;
        }
        const Vec3 eye = object_space_[i] && frame.world_to_cluster
                             ? transform_point(frame.world_to_cluster[i], frame.eye)
                             : frame.eye;
        const std::size_t leaves = cluster_leaf_count(clusters_[i]);
        leaf_culled_.assign(leaves, 0);
        cull_cluster_hierarchy(clusters_[i], eye, leaf_culled_.data(), r.stats.cluster_tests);
        std::size_t culled_members = 0;
        for (std::size_t leaf = 0; leaf < leaves; ++leaf) {
            if (!leaf_culled_[leaf]) continue;
            const BackfaceCluster& c = cluster_leaf(clusters_[i], leaf);
            culled_members += c.count;
        }
        if (culled_members == o.span.count && o.span.count > 0) {
            r.verdicts[i] = ObjectVerdict::backface;
            append_span(culled, o.span.first, o.span.count);
        } else {
            for (std::size_t leaf = 0; leaf < leaves; ++leaf)
                if (leaf_culled_[leaf]) {
                    const BackfaceCluster& c = cluster_leaf(clusters_[i], leaf);
                    culled.push_back({o.span.first + c.first, c.count});
                }
        }
        if (!o.triangles) r.stats.backface_patches_culled += culled_members;
    }
    sort_and_merge(r.culled_patches);
    sort_and_merge(r.culled_triangles);
    for (std::size_t i = 0; i < n; ++i) {
        if (r.verdicts[i] == ObjectVerdict::frustum) ++r.stats.frustum_culled;
        if (r.verdicts[i] == ObjectVerdict::backface) ++r.stats.backface_culled;
        if (r.verdicts[i] == ObjectVerdict::detail) ++r.stats.detail_culled;
    }
    for (const IndexSpan& s : r.culled_patches) r.stats.patches_culled += s.count;
    for (const IndexSpan& s : r.culled_triangles) r.stats.triangles_culled += s.count;
    return r;
}

std::size_t cull_frustum_after_objects(const ObjectCullResult& result, const PatchBatchView& patches,
                                       const float* max_displacement, const FrustumPlanes& planes,
                                       std::uint8_t* culled) {
    for (const IndexSpan& s : result.culled_patches) {
        const std::size_t end = std::min(patches.count, s.first + s.count);
        for (std::size_t i = s.first; i < end; ++i) culled[i] = 1;
    }
    std::size_t tested = 0;
    for_each_active_span(result.culled_patches, patches.count, [&](std::size_t first, std::size_t count) {
        cull_frustum_simd(patches.subrange(first, count), max_displacement ? max_displacement + first : nullptr, planes,
                          culled + first);
        tested += count;
    });
    return tested;
}

}  // namespace patchcull
