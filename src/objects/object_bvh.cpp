// Object BVH (patchcull/objects/object_bvh.h): binned-SAH build, bottom-up refit and hierarchical
// view-frustum culling with plane masking and coherence (G. Zachmann, "Advanced Visibility
// Computations"), plus the flat list.
//
// Layout: nodes_[0] is the root; an inner node's children are nodes_[first] and nodes_[first + 1],
// always allocated after it, so a reverse sweep over nodes_ is a bottom-up order (refit). Leaves
// hold the slots [first, first + count) of slot_object_ / slot_box_, and every node knows the slot
// range of its whole subtree, so "every object under this node" is one contiguous loop.
#include "patchcull/objects/object_bvh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace patchcull {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr int kBins = 12;
constexpr std::uint32_t kLeafSize = 4;

bool empty_box(const Bounds& b) { return b.min.x > b.max.x || b.min.y > b.max.y || b.min.z > b.max.z; }

Bounds empty_bounds() { return {{kInf, kInf, kInf}, {-kInf, -kInf, -kInf}}; }

// min / max that turn a NaN into the unbounded side, so a node holding a NaN box is unbounded.
inline float lo_of(float a, float b) { return (a != a || b != b) ? -kInf : (a < b ? a : b); }
inline float hi_of(float a, float b) { return (a != a || b != b) ? kInf : (a > b ? a : b); }

inline void grow(Bounds& acc, const Bounds& b) {
    acc.min = {lo_of(acc.min.x, b.min.x), lo_of(acc.min.y, b.min.y), lo_of(acc.min.z, b.min.z)};
    acc.max = {hi_of(acc.max.x, b.max.x), hi_of(acc.max.y, b.max.y), hi_of(acc.max.z, b.max.z)};
}

inline float axis(Vec3 v, int a) { return a == 0 ? v.x : a == 1 ? v.y : v.z; }

// Half the surface area, in double; 0 for an empty box, +inf for an unbounded one.
double half_area(const Bounds& b) {
    if (empty_box(b)) return 0;
    const double dx = double(b.max.x) - b.min.x, dy = double(b.max.y) - b.min.y, dz = double(b.max.z) - b.min.z;
    const double a = dx * dy + dy * dz + dz * dx;
    return std::isnan(a) ? std::numeric_limits<double>::infinity() : a;
}

}  // namespace

void ObjectBvh::build(const Bounds* boxes, std::size_t n) {
    object_count_ = n;
    depth_ = 0;
    nodes_.clear();
    slot_object_.resize(n);
    std::iota(slot_object_.begin(), slot_object_.end(), 0u);
    slot_box_.assign(boxes, boxes + n);
    slot_last_.assign(n, -1);
    if (n == 0) {
        node_last_.clear();
        stack_.clear();
        return;
    }
    // Centres for the split decisions; empty or non-finite boxes get a finite stand-in (0), they
    // only affect the tree's quality, never its answers.
    std::vector<Vec3> centres(n);
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3 c = (boxes[i].min + boxes[i].max) * 0.5f;
        centres[i] = empty_box(boxes[i]) || !is_finite(c) ? Vec3{} : c;
    }
    nodes_.reserve(2 * n);
    nodes_.emplace_back();
    build_node(0, 0, static_cast<std::uint32_t>(n), boxes, centres, 1);
    for (std::size_t s = 0; s < n; ++s) slot_box_[s] = boxes[slot_object_[s]];
    node_last_.assign(nodes_.size(), -1);
    stack_.resize(depth_ + 2);
}

void ObjectBvh::build_node(std::uint32_t index, std::uint32_t begin, std::uint32_t end, const Bounds* boxes,
                           const std::vector<Vec3>& centres, std::size_t level) {
    depth_ = std::max(depth_, level);
    Bounds box = empty_bounds();
    for (std::uint32_t s = begin; s < end; ++s) grow(box, boxes[slot_object_[s]]);
    nodes_[index].box = box;
    nodes_[index].slot_begin = begin;
    nodes_[index].slot_end = end;
    const std::uint32_t count = end - begin;
    if (count <= kLeafSize) {
        nodes_[index].first = begin;
        nodes_[index].count = count;
        return;
    }
    // Centre bounds.
    Vec3 cmin{kInf, kInf, kInf}, cmax{-kInf, -kInf, -kInf};
    for (std::uint32_t s = begin; s < end; ++s) {
        const Vec3 c = centres[slot_object_[s]];
        cmin = {std::min(cmin.x, c.x), std::min(cmin.y, c.y), std::min(cmin.z, c.z)};
        cmax = {std::max(cmax.x, c.x), std::max(cmax.y, c.y), std::max(cmax.z, c.z)};
    }
    // Binned SAH over the three axes: cost of a split after bin b = A_left N_left + A_right N_right.
    int best_axis = -1, best_bin = -1;
    double best_cost = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        const float lo = axis(cmin, a), extent = axis(cmax, a) - lo;
        if (!(extent > 0) || !std::isfinite(extent)) continue;
        const float scale = kBins / extent;
        std::uint32_t bin_count[kBins] = {};
        Bounds bin_box[kBins];
        for (Bounds& b : bin_box) b = empty_bounds();
        for (std::uint32_t s = begin; s < end; ++s) {
            const std::uint32_t o = slot_object_[s];
            const int b = std::min(kBins - 1, static_cast<int>((axis(centres[o], a) - lo) * scale));
            ++bin_count[b];
            grow(bin_box[b], boxes[o]);
        }
        double right_area[kBins];
        std::uint32_t right_count[kBins];
        Bounds acc = empty_bounds();
        std::uint32_t cnt = 0;
        for (int b = kBins - 1; b > 0; --b) {
            grow(acc, bin_box[b]);
            cnt += bin_count[b];
            right_area[b] = half_area(acc);
            right_count[b] = cnt;
        }
        acc = empty_bounds();
        cnt = 0;
        for (int b = 0; b < kBins - 1; ++b) {
            grow(acc, bin_box[b]);
            cnt += bin_count[b];
            if (cnt == 0 || right_count[b + 1] == 0) continue;
            const double cost = half_area(acc) * cnt + right_area[b + 1] * right_count[b + 1];
            if (cost < best_cost) best_cost = cost, best_axis = a, best_bin = b;
        }
    }
    std::uint32_t mid;
    auto* first = slot_object_.data() + begin;
    auto* last = slot_object_.data() + end;
    if (best_axis >= 0) {
        const int a = best_axis;
        const float lo = axis(cmin, a), scale = kBins / (axis(cmax, a) - lo);
        auto* split = std::partition(first, last, [&](std::uint32_t o) {
            return std::min(kBins - 1, static_cast<int>((axis(centres[o], a) - lo) * scale)) <= best_bin;
        });
        mid = static_cast<std::uint32_t>(split - slot_object_.data());
    } else {
        // Coincident centres (duplicates) or unbounded areas: the median on the widest axis.
        int a = 0;
        for (int k = 1; k < 3; ++k)
            if (axis(cmax, k) - axis(cmin, k) > axis(cmax, a) - axis(cmin, a)) a = k;
        mid = begin + count / 2;
        std::nth_element(first, slot_object_.data() + mid, last,
                         [&](std::uint32_t x, std::uint32_t y) { return axis(centres[x], a) < axis(centres[y], a); });
    }
    const std::uint32_t left = static_cast<std::uint32_t>(nodes_.size());
    nodes_.emplace_back();
    nodes_.emplace_back();
    nodes_[index].first = left;
    nodes_[index].count = 0;
    build_node(left, begin, mid, boxes, centres, level + 1);
    build_node(left + 1, mid, end, boxes, centres, level + 1);
}

void ObjectBvh::refit(const Bounds* boxes) {
    for (std::size_t s = 0; s < object_count_; ++s) slot_box_[s] = boxes[slot_object_[s]];
    for (std::size_t i = nodes_.size(); i-- > 0;) {
        Node& node = nodes_[i];
        Bounds box = empty_bounds();
        if (node.count > 0) {
            for (std::uint32_t s = node.first; s < node.first + node.count; ++s) grow(box, slot_box_[s]);
        } else {
            grow(box, nodes_[node.first].box);
            grow(box, nodes_[node.first + 1].box);
        }
        node.box = box;
    }
}

double ObjectBvh::sah_cost() const {
    if (nodes_.empty()) return 0;
    const double root = half_area(nodes_[0].box);
    if (!(root > 0)) return 0;
    double cost = 0;
    for (const Node& node : nodes_) cost += half_area(node.box) / root * (node.count > 0 ? node.count : 1);
    return cost;
}

void ObjectBvh::cull(const FrustumPlanes& planes, Options options, Containment* per_object, Stats& stats) {
    if (nodes_.empty()) return;
    std::size_t sp = 0;
    stack_[sp++] = {0, 0x3f};
    while (sp > 0) {
        const StackEntry e = stack_[--sp];
        const Node& node = nodes_[e.node];
        PlaneCullState state;
        state.plane_mask = options.plane_masking ? e.mask : std::uint8_t{0x3f};
        state.last_plane = options.coherence ? node_last_[e.node] : std::int8_t{-1};
        const Containment c = classify_aabb(planes, node.box, state, stats.plane_tests);
        ++stats.nodes_visited;
        if (options.coherence) node_last_[e.node] = state.last_plane;
        if (c == Containment::outside) {
            for (std::uint32_t s = node.slot_begin; s < node.slot_end; ++s)
                per_object[slot_object_[s]] = Containment::outside;
        } else if (c == Containment::inside) {
            // Empty boxes are outside by their own test (they add nothing to the node's box).
            for (std::uint32_t s = node.slot_begin; s < node.slot_end; ++s)
                per_object[slot_object_[s]] = empty_box(slot_box_[s]) ? Containment::outside : Containment::inside;
        } else if (node.count > 0) {
            for (std::uint32_t s = node.first; s < node.first + node.count; ++s) {
                PlaneCullState os;
                os.plane_mask = options.plane_masking ? state.plane_mask : std::uint8_t{0x3f};
                os.last_plane = options.coherence ? slot_last_[s] : std::int8_t{-1};
                per_object[slot_object_[s]] = classify_aabb(planes, slot_box_[s], os, stats.plane_tests);
                if (options.coherence) slot_last_[s] = os.last_plane;
            }
        } else {
            stack_[sp++] = {node.first + 1, state.plane_mask};
            stack_[sp++] = {node.first, state.plane_mask};
        }
    }
}

void cull_objects_flat(const FrustumPlanes& planes, const Bounds* boxes, std::size_t n, PlaneCullState* states,
                       bool coherence, Containment* per_object, ObjectBvh::Stats& stats) {
    for (std::size_t i = 0; i < n; ++i) {
        PlaneCullState st;
        st.plane_mask = 0x3f;
        st.last_plane = coherence ? states[i].last_plane : std::int8_t{-1};
        per_object[i] = classify_aabb(planes, boxes[i], st, stats.plane_tests);
        if (states) {
            states[i].plane_mask = st.plane_mask;
            if (coherence) states[i].last_plane = st.last_plane;
        }
    }
    stats.nodes_visited += static_cast<std::uint32_t>(n);
}

}  // namespace patchcull
