// patchcull/objects/object_bvh.h: a bounding-volume hierarchy over a scene's objects' AABBs, traversed
// with hierarchical view-frustum culling, plane masking and plane coherence (G. Zachmann,
// "Advanced Visibility Computations": "Hierarchical View Frustum Culling", "Plane
// Masking", "zeitliche Kohärenz"), and the flat list with the same tests for comparison.
//
// Built once (binned SAH over the boxes' centres, leaves of <= 4 objects) and refitted per frame
// for moving objects (same topology, node boxes recomputed bottom-up). Every node box is the exact
// union (min / max) of its children's boxes, so a node's n/p-vertex test bounds its children's in
// float too (bounding_volumes.cpp: the values are monotone), and cull() returns, bit for bit, what
// classify_aabb returns for each object's own box with a fresh PlaneCullState (the flat list):
// an object under a node found outside is outside by its own test, one under a node found inside
// is inside, and the planes a node is inside of are the planes its children are inside of. So the
// hierarchy and the masking change the cost, never the answer (tests/core/object_bvh_test.cpp).
//
// Boxes: empty boxes (min > max) are allowed (reported outside, as classify_aabb does); a NaN
// coordinate makes every ancestor's box unbounded (never outside or inside), the object's own test
// reports it intersecting.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "patchcull/core/frustum.h"
#include "patchcull/core/mesh.h"
#include "patchcull/objects/bounding_volumes.h"

namespace patchcull {

class ObjectBvh {
public:
    /// Builds the hierarchy over boxes[0 .. n) (copied; n may be 0): binned SAH (12 bins per axis)
    /// on the box centres, leaves of <= 4 objects, median split where the centres coincide. Resets
    /// the coherence state. Allocates (the only call that does).
    void build(const Bounds* boxes, std::size_t n);
    /// New boxes for the same n objects (boxes[i] is object i's, as at build): node boxes
    /// recomputed bottom-up, topology kept (so the tree gets looser as objects move apart; rebuild
    /// when the cull cost grows). Never allocates.
    void refit(const Bounds* boxes);

    /// Objects at the last build.
    std::size_t object_count() const { return object_count_; }
    /// Nodes (inner + leaves); 0 for an empty hierarchy, 1 for a single leaf.
    std::size_t node_count() const { return nodes_.size(); }
    /// Longest root-to-leaf path in nodes (0 when empty).
    std::size_t depth() const { return depth_; }
    /// Surface-area cost of the current tree relative to its root: sum over inner nodes of
    /// area(node) / area(root) plus, over leaves, that ratio times the leaf's object count (the
    /// expected node and object tests for a random query, the quantity the build minimises).
    /// Refits after motion raise it; rebuild when it has grown by, say, 1.5x over the value just
    /// after build. 0 when empty or when the root has no area, +inf when a box is unbounded.
    double sah_cost() const;

    struct Options {
        bool plane_masking = true;  ///< a node's children test only the planes it straddles
        bool coherence = true;      ///< each node / object tries the plane that rejected it last first
    };
    struct Stats {
        std::uint32_t nodes_visited = 0;  ///< BVH nodes tested (flat list: objects tested)
        std::uint32_t plane_tests = 0;    ///< planes evaluated, nodes and objects together
    };

    /// Hierarchical VFC: writes per_object[i] for every object (outside for every object under a
    /// node found outside, inside under a node inside, else the object's own test), adds to stats,
    /// keeps the per-node and per-object last rejecting plane between calls (with coherence).
    /// Never allocates (stack sized at build). per_object must hold object_count() values.
    /// Conservative as classify_aabb: equal to it for each object (see the file comment).
    void cull(const FrustumPlanes& planes, Options options, Containment* per_object, Stats& stats);

    // ---- the tree itself, read-only, for traversals of their own (CHC, gl_object_queries.h) ----
    /// Node 0 is the root (when node_count() > 0). Its box: the exact union of its objects' boxes
    /// at the last build or refit.
    const Bounds& node_box(std::size_t node) const { return nodes_[node].box; }
    /// Leaves hold 1..4 objects; inner nodes have two children, node_left(node) and node_left(node) + 1.
    bool node_is_leaf(std::size_t node) const { return nodes_[node].count != 0; }
    std::size_t node_left(std::size_t node) const { return nodes_[node].first; }
    /// A leaf's objects: node_object(node, k) for k < node_object_count(node) (0 for inner nodes).
    std::size_t node_object_count(std::size_t node) const { return nodes_[node].count; }
    std::size_t node_object(std::size_t node, std::size_t k) const { return slot_object_[nodes_[node].first + k]; }

private:
    struct Node {
        Bounds box;
        std::uint32_t first = 0;                     ///< leaf: first slot; inner: index of the left child (right = +1)
        std::uint32_t count = 0;                     ///< leaf: objects (1..4); inner: 0
        std::uint32_t slot_begin = 0, slot_end = 0;  ///< slots of every object in the subtree
    };
    struct StackEntry {
        std::uint32_t node;
        std::uint8_t mask;
    };
    void build_node(std::uint32_t index, std::uint32_t begin, std::uint32_t end, const Bounds* boxes,
                    const std::vector<Vec3>& centres, std::size_t level);

    std::size_t object_count_ = 0, depth_ = 0;
    std::vector<Node> nodes_;
    std::vector<std::uint32_t> slot_object_;  ///< object index of each leaf slot
    std::vector<Bounds> slot_box_;            ///< the object's box, in slot order
    std::vector<std::int8_t> node_last_;      ///< coherence: last rejecting plane per node
    std::vector<std::int8_t> slot_last_;      ///< ... and per object (slot)
    std::vector<StackEntry> stack_;
};

/// The flat list with the same tests (the comparison): per_object[i] = classify_aabb(boxes[i])
/// with plane_mask 0x3f; with coherence, states[i].last_plane (kept by the caller across frames)
/// is tried first and updated; states may be null without coherence. stats.nodes_visited += n.
void cull_objects_flat(const FrustumPlanes& planes, const Bounds* boxes, std::size_t n, PlaneCullState* states,
                       bool coherence, Containment* per_object, ObjectBvh::Stats& stats);

}  // namespace patchcull
