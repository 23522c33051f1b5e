// Tight bounding volumes (patchcull/objects/tight_bounds.h): a fixed median-split hierarchy over an
// object's pieces, refitted per frame, and the cut chosen by CHC++'s sigma rule.
//
// Layout (as object_bvh.cpp): nodes_[0] is the root; an inner node's children are nodes_[first]
// and nodes_[first + 1], allocated after it, so a reverse sweep over nodes_ is bottom-up (refit).
// Leaves hold the slots [first, first + count) of slot_piece_.
//
// select() keeps its working set in the caller's out vector, past the entries it already held:
// each entry then carries a node index in the bits of min.x (never used as a float), in two
// parts, [heap | finals]: a min-heap of the nodes that may still be split (by the area the split
// adds), then the nodes that stay. At the end every entry is replaced by its node's box. So the
// call allocates nothing of its own and stays safe to run concurrently on one object.
#include "patchcull/objects/tight_bounds.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>

#include "patchcull/core/error.h"

namespace patchcull {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

bool is_empty(const Bounds& b) { return b.min.x > b.max.x || b.min.y > b.max.y || b.min.z > b.max.z; }

bool has_nan(const Bounds& b) {
    return std::isnan(b.min.x) || std::isnan(b.min.y) || std::isnan(b.min.z) || std::isnan(b.max.x) ||
           std::isnan(b.max.y) || std::isnan(b.max.z);
}

Bounds empty_bounds() { return {{kInf, kInf, kInf}, {-kInf, -kInf, -kInf}}; }
Bounds whole_space() { return {{-kInf, -kInf, -kInf}, {kInf, kInf, kInf}}; }

// Exact union of two NaN-free boxes. An empty box here is always {+inf, -inf} (empty_bounds),
// neutral to min / max; an empty piece (any min > max) could widen the union, so add_piece skips it.
inline void unite(Bounds& acc, const Bounds& b) {
    acc.min = {std::min(acc.min.x, b.min.x), std::min(acc.min.y, b.min.y), std::min(acc.min.z, b.min.z)};
    acc.max = {std::max(acc.max.x, b.max.x), std::max(acc.max.y, b.max.y), std::max(acc.max.z, b.max.z)};
}

// A piece joins a union: skipped when empty, the whole space when it has a NaN.
inline void add_piece(Bounds& acc, const Bounds& piece) {
    if (has_nan(piece)) {
        acc = whole_space();
    } else if (!is_empty(piece)) {
        unite(acc, piece);
    }
}

double area_of(const Bounds& b) {
    if (is_empty(b)) return 0;
    const double dx = double(b.max.x) - b.min.x, dy = double(b.max.y) - b.min.y, dz = double(b.max.z) - b.min.z;
    const double a = 2 * (dx * dy + dy * dz + dz * dx);
    return std::isnan(a) ? std::numeric_limits<double>::infinity() : a;
}

inline float axis(Vec3 v, int a) { return a == 0 ? v.x : a == 1 ? v.y : v.z; }

Bounds encode(std::uint32_t node) {
    Bounds e{};
    std::memcpy(&e.min.x, &node, sizeof node);
    return e;
}

std::uint32_t decode(const Bounds& e) {
    std::uint32_t node;
    std::memcpy(&node, &e.min.x, sizeof node);
    return node;
}

}  // namespace

float surface_area(const Bounds& b) { return static_cast<float>(area_of(b)); }

// What the build splits by: each piece's rest box (a point at 0 for an empty, NaN or infinite
// one: such pieces only affect the tree's quality) and its centre, plus a sweep buffer.
struct TightBounds::BuildInput {
    std::vector<Bounds> boxes;
    std::vector<Vec3> centres;
    std::vector<double> suffix_area;
    unsigned max_leaf_pieces = 8;
};

void TightBounds::build(const Bounds* pieces, std::size_t n, unsigned max_leaf_pieces) {
    if (max_leaf_pieces == 0) throw Error("tight bounds: max_leaf_pieces must be >= 1");
    if (n > std::numeric_limits<std::uint32_t>::max() / 2) throw Error("tight bounds: too many pieces");
    piece_count_ = n;
    nodes_.clear();
    slot_piece_.resize(n);
    std::iota(slot_piece_.begin(), slot_piece_.end(), 0u);
    if (n == 0) return;
    BuildInput in;
    in.boxes.resize(n);
    in.centres.resize(n);
    in.suffix_area.resize(n + 1);
    in.max_leaf_pieces = max_leaf_pieces;
    for (std::size_t i = 0; i < n; ++i) {
        const bool usable = !is_empty(pieces[i]) && is_finite(pieces[i].min) && is_finite(pieces[i].max);
        in.boxes[i] = usable ? pieces[i] : Bounds{};
        in.centres[i] = in.boxes[i].center();
    }
    nodes_.reserve(2 * n);
    nodes_.emplace_back();
    build_node(0, 0, static_cast<std::uint32_t>(n), in);
    refit(pieces);
}

// Splits along the axis where the centres spread the most, at the position (in centre order)
// that minimises the surface-area heuristic area(left) * n_left + area(right) * n_right, each
// side keeping >= 1/16 of the pieces (depth O(log n)); ties go to the more even split, so
// coincident pieces split at the median. A plain median split leaves nodes, down to leaves,
// straddling the gap between clusters of unequal size (an arm beside the body), which no cut can
// then separate; the area heuristic splits at such gaps, and it measures what select() trades.
void TightBounds::build_node(std::uint32_t index, std::uint32_t begin, std::uint32_t end, BuildInput& in) {
    const std::uint32_t count = end - begin;
    if (count <= in.max_leaf_pieces) {
        nodes_[index].first = begin;
        nodes_[index].count = count;
        return;
    }
    Vec3 lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
    for (std::uint32_t s = begin; s < end; ++s) {
        const Vec3 c = in.centres[slot_piece_[s]];
        lo = {std::min(lo.x, c.x), std::min(lo.y, c.y), std::min(lo.z, c.z)};
        hi = {std::max(hi.x, c.x), std::max(hi.y, c.y), std::max(hi.z, c.z)};
    }
    // Extents in double: far from the origin a float difference could round two axes equal.
    int a = 0;
    double widest = -1;
    for (int k = 0; k < 3; ++k) {
        const double extent = double(axis(hi, k)) - axis(lo, k);
        if (extent > widest) widest = extent, a = k;
    }
    // Centre order; ties by piece index, so the tree does not depend on the library's sort.
    std::sort(slot_piece_.begin() + begin, slot_piece_.begin() + end, [&](std::uint32_t x, std::uint32_t y) {
        const float cx = axis(in.centres[x], a), cy = axis(in.centres[y], a);
        return cx < cy || (cx == cy && x < y);
    });
    Bounds acc = empty_bounds();
    for (std::uint32_t k = count; k-- > 0;) {  // suffix_area[k]: pieces k .. count-1 of the node
        unite(acc, in.boxes[slot_piece_[begin + k]]);
        in.suffix_area[k] = area_of(acc);
    }
    const std::uint32_t least = std::max<std::uint32_t>(1, count / 16), half = count / 2;
    std::uint32_t best = half;
    double best_cost = std::numeric_limits<double>::infinity();
    acc = empty_bounds();
    for (std::uint32_t k = 1; k < count; ++k) {  // k pieces on the left
        unite(acc, in.boxes[slot_piece_[begin + k - 1]]);
        if (k < least || count - k < least) continue;
        const double cost = area_of(acc) * k + in.suffix_area[k] * (count - k);
        const auto off_centre = [&](std::uint32_t m) { return m > half ? m - half : half - m; };
        if (cost < best_cost || (cost == best_cost && off_centre(k) < off_centre(best))) best_cost = cost, best = k;
    }
    const std::uint32_t mid = begin + best;
    const auto left = static_cast<std::uint32_t>(nodes_.size());
    nodes_.emplace_back();
    nodes_.emplace_back();
    nodes_[index].first = left;
    nodes_[index].count = 0;
    build_node(left, begin, mid, in);
    build_node(left + 1, mid, end, in);
}

void TightBounds::refit(const Bounds* pieces) {
    for (std::size_t i = nodes_.size(); i-- > 0;) {
        Node& node = nodes_[i];
        Bounds box = empty_bounds();
        if (node.count > 0) {
            for (std::uint32_t s = node.first; s < node.first + node.count; ++s) add_piece(box, pieces[slot_piece_[s]]);
        } else {
            // Children are NaN-free; an empty child is {+inf, -inf} exactly, neutral to min / max.
            unite(box, nodes_[node.first].box);
            unite(box, nodes_[node.first + 1].box);
        }
        node.box = box;
        node.area = area_of(box);
    }
}

Bounds TightBounds::root() const { return nodes_.empty() ? empty_bounds() : nodes_[0].box; }

double TightBounds::split_increase(const Node& node) const {
    return nodes_[node.first].area + nodes_[node.first + 1].area - node.area;
}

std::size_t TightBounds::select(float sigma, std::size_t max_boxes, std::vector<Bounds>& out) const {
    if (!(sigma >= 1)) throw Error("tight bounds: sigma must be >= 1");
    if (max_boxes == 0) throw Error("tight bounds: max_boxes must be >= 1");
    if (nodes_.empty() || is_empty(nodes_[0].box)) return 0;
    if (!std::isfinite(nodes_[0].area)) {
        out.push_back(nodes_[0].box);
        return 1;
    }
    const std::size_t base = out.size();
    const double budget = double(sigma) * nodes_[0].area;
    // Rule (a) of the header; the caller's sigma in double so both rules use the same value.
    const auto splittable = [&](const Node& node) {
        return node.count == 0 && nodes_[node.first].area + nodes_[node.first + 1].area <= double(sigma) * node.area;
    };
    // Min-heap on the added area, ties by node index (a deterministic cut).
    const auto later = [&](const Bounds& x, const Bounds& y) {
        const std::uint32_t nx = decode(x), ny = decode(y);
        const double ix = split_increase(nodes_[nx]), iy = split_increase(nodes_[ny]);
        return ix > iy || (ix == iy && nx > ny);
    };
    std::size_t heap_size = 0;
    const auto add = [&](std::uint32_t n) {
        if (!splittable(nodes_[n])) {
            out.push_back(encode(n));
            return;
        }
        const std::size_t slot = base + heap_size;
        if (slot == out.size()) {
            out.push_back(encode(n));
        } else {
            const Bounds first_final = out[slot];
            out.push_back(first_final);
            out[slot] = encode(n);
        }
        ++heap_size;
        std::push_heap(out.begin() + base, out.begin() + base + heap_size, later);
    };

    add(0);
    std::size_t boxes = 1;
    double total = nodes_[0].area;
    while (heap_size > 0) {
        std::pop_heap(out.begin() + base, out.begin() + base + heap_size, later);
        --heap_size;
        // The candidate now sits first among the finals: it stays there unless it is split.
        const std::size_t slot = base + heap_size;
        const std::uint32_t n = decode(out[slot]);
        const Node& node = nodes_[n];
        const double increase = split_increase(node);
        if (total + increase > budget) break;  // rule (b); every other candidate adds at least as much
        const Node& left = nodes_[node.first];
        const Node& right = nodes_[node.first + 1];
        const std::size_t children = std::size_t(!is_empty(left.box)) + std::size_t(!is_empty(right.box));
        if (boxes - 1 + children > max_boxes) continue;
        out[slot] = out.back();
        out.pop_back();
        if (!is_empty(left.box)) add(node.first);
        if (!is_empty(right.box)) add(node.first + 1);
        boxes = boxes - 1 + children;
        total += increase;
    }
    for (std::size_t i = base; i < out.size(); ++i) out[i] = nodes_[decode(out[i])].box;
    return out.size() - base;
}

}  // namespace patchcull
