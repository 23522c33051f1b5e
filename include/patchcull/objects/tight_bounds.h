// patchcull/objects/tight_bounds.h: tight bounding volumes for occlusion queries (Mattausch, Bittner,
// Wimmer, "CHC++: Coherent Hierarchical Culling Revisited", section "tight bounding volumes";
// G. Zachmann, lecture "Advanced Visibility Computations"). An occlusion query on an object's
// big AABB reports "visible" whenever any of the box's empty corners shows; querying instead the
// union of a few small AABBs around clusters of its pieces (patches) culls more, at the price of
// rasterising more box faces. CHC++ subdivides while the summed surface area of the small boxes
// stays below sigma times the big box's (sigma depends on the GPU, about 1.4 there; measure it).
//
// For animated objects whose pieces keep their order and count across frames: build() makes a
// fixed binary hierarchy once (from the rest pose's piece boxes: the pieces' centres split along
// their longest axis where the surface-area heuristic says, leaves of <= max_leaf_pieces pieces),
// refit() recomputes the node boxes bottom-up from each frame's piece boxes, select() picks a cut
// of the hierarchy.
//
// The sigma rule (select): starting from the cut {root}, a selected node N may be replaced by its
// two children L, R when BOTH
//   (a) area(L) + area(R) <= sigma * area(N)          (the rule applied per node), and
//   (b) the cut's total area stays <= sigma * area(root)   (the rule as CHC++ states it),
// and the cut stays within max_boxes boxes. Candidates are taken best first (the smallest area
// added by the split; separating far-apart clusters removes area and comes first). Why both: (a)
// alone compounds - halving a filled or hollow cube-like cluster gives halves of 4/3 its area,
// below 1.4, so the per-node rule alone refines every compact object to the cap and its cut's
// area to up to sigma^depth times the root's; (b) bounds what a query rasterises: the cut's total
// area is <= sigma * area(root), so with (b) sigma keeps its CHC++ meaning. (a) stops splits that
// add much area for little gain even where the budget (b) would allow them. sigma = 1 keeps the
// root unless a split adds no area (clusters apart from each other, flat objects); a large sigma
// refines to max_boxes boxes or to the leaves.
//
// Conservative: every node box is the exact union (float min / max, no rounding) of the boxes of
// the pieces under it, and a cut holds, for every leaf with a non-empty piece, exactly one of its
// ancestors or the leaf itself, so every piece box lies inside one selected box: whatever the
// pieces draw lies in the union of the selection, and a query on that union that sees no pixel
// proves the object hidden. Far from the origin this stays exact (min / max never round).
//
// Degenerate pieces: an empty piece (min > max on some axis) holds nothing and is skipped by the
// unions (a node of only empty pieces is empty and never selected; an object of only empty pieces
// selects no box). A piece with a NaN coordinate may hold anything: it makes its node and every
// ancestor, so the root, the whole space {-inf, +inf}^3, and select() then returns that one box
// (never culled). Infinite coordinates are kept as they are (an unbounded root is likewise
// returned alone).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "patchcull/core/mesh.h"

namespace patchcull {

/// Surface area of a box, 2 (dx dy + dy dz + dz dx), computed in double and rounded to float;
/// 0 for an empty box (min > max on some axis), +inf for a box with a NaN or infinite extent (and
/// where the area overflows a float).
float surface_area(const Bounds& b);

class TightBounds {
public:
    /// Builds the hierarchy over pieces[0 .. n) (e.g. the rest pose's patch boxes of one object):
    /// the pieces, in the order of their centres along the axis where those spread the most, split
    /// where area(left) * n_left + area(right) * n_right is least (each side >= 1/16 of them; the
    /// median among equal costs; a plain median split would leave nodes straddling the gap between
    /// unequal clusters), until a node holds <= max_leaf_pieces (>= 1, else patchcull::Error)
    /// pieces; node boxes as refit() computes them. Empty, NaN or infinite pieces split as a point
    /// at 0 (quality only). n may be 0. Allocates (the only call that does).
    void build(const Bounds* pieces, std::size_t n, unsigned max_leaf_pieces = 8);
    /// New boxes of the same n pieces, pieces[i] being piece i's as at build: every node box
    /// becomes the exact union of its pieces' boxes (empty pieces skipped, a NaN piece makes it
    /// the whole space). The topology is kept, so the cuts get worse as the pieces move away from
    /// the rest pose's clusters (still conservative). Never allocates.
    void refit(const Bounds* pieces);
    /// The cut by the sigma rule of the file comment: appends to out its boxes, whose union holds
    /// every piece box (each piece box lies inside one of them), at most max_boxes of them, with a
    /// total surface area <= sigma * surface_area(root()) (up to double rounding of the sums).
    /// No box for an empty hierarchy or one of only empty pieces; the root alone when it is
    /// unbounded (a NaN piece). sigma >= 1 and max_boxes >= 1, else patchcull::Error. Returns the
    /// number of boxes appended. Allocates only in out (which it also uses as its scratch).
    std::size_t select(float sigma, std::size_t max_boxes, std::vector<Bounds>& out) const;

    /// The object's AABB after the last build/refit (the empty box {+inf, -inf} when there is no
    /// non-empty piece).
    Bounds root() const;
    /// Pieces at the last build.
    std::size_t piece_count() const { return piece_count_; }
    /// Nodes, inner and leaves (0 when empty, 1 for a single leaf); leaves = (node_count() + 1) / 2.
    std::size_t node_count() const { return nodes_.size(); }

private:
    struct Node {
        Bounds box;
        double area = 0;          ///< surface area of box in double (0 empty, +inf unbounded)
        std::uint32_t first = 0;  ///< leaf: first slot; inner: index of the left child (right = +1)
        std::uint32_t count = 0;  ///< leaf: pieces (>= 1); inner: 0
    };
    struct BuildInput;
    void build_node(std::uint32_t index, std::uint32_t begin, std::uint32_t end, BuildInput& in);
    double split_increase(const Node& node) const;

    std::size_t piece_count_ = 0;
    std::vector<Node> nodes_;                ///< nodes_[0] the root; children after their parent
    std::vector<std::uint32_t> slot_piece_;  ///< piece index of each leaf slot
};

}  // namespace patchcull
