// patchcull/objects/portal_culling.h: cells and portals, the potentially visible set of one frame by a
// traversal from the eye's cell through the portals (G. Zachmann, lecture "Advanced Visibility
// Computations": cells see each other only through portals; Luebke & Georges, "Portals and Mirrors:
// Simple, Fast Evaluation of Potentially Visible Sets"). The frustum is narrowed at every portal
// to the planes through the eye and the edges of the portal polygon clipped by the frustum so far,
// so a room two doors away is reached only where both doors line up from the eye.
//
// The scene's contract (the scene author's; the built-in `building` scene keeps it): the cells'
// boxes tile the interior (neighbouring boxes meet at the mid-plane of the wall between them),
// every portal is a planar convex polygon in the common boundary of its two cells, and the walls
// are opaque: a segment that goes from one cell's box into another's crosses their common boundary
// only inside a portal between them. Space outside every cell (outside the building) is not seen
// from inside; an eye outside every cell gets no culling at all.
//
// Conservativeness. Call a point p visible when the segment from the eye to p passes only through
// cells and portals and p is inside the view frustum (every one of its six planes, near and far
// included). The segment meets each convex cell box in one interval, so it runs through cells
// c_0 (one containing the eye), c_1, ..., c_k (one containing p), no cell twice, and crosses from
// c_i into c_i+1 at a point x_i of a portal between them (the contract). Induction on i: the reach
// into c_i carries a frustum F_i containing the segment's part beyond x_i-1 (F_0: the view
// frustum). For a plane through the eye (or with the eye inside it) the segment's points lie on
// the same side as p, since the plane's value along the segment moves linearly from the eye's
// value to p's; a plane with the eye outside it (the near plane) is moved to pass through the eye
// for the clip, which keeps every point between eye and p. So x_i is in portal i clipped by F_i,
// that clipped polygon Q_i is not empty, c_i+1 is reached, and F_i+1 (near and far of the view
// frustum, plus the planes through the eye and Q_i's edges: the cone from the eye through Q_i,
// which holds eye + s (x_i - eye) for every s >= 1) contains the rest of the segment, p included.
// Hence every visible point of a box is in a reached cell's box and inside that reach's frustum,
// and box_visible is true. A path never enters a cell twice (the segment does not), so no portal is
// crossed twice and the recursion ends; when the caps (PortalLimits) are hit, the traversal stops
// and every box inside the view frustum counts as visible (every cell reached): conservative.
//
// Rounding. Everything after the inputs is double: the inputs (float cell boxes, portal corners,
// eye, frustum rows, query boxes) are exact in double, so only the double arithmetic rounds,
// relative 1e-16 of R, the largest absolute coordinate of any cell box or portal corner (the
// scene's size including its distance from the origin; a building 1e4 from the origin has R >= 1e4).
// Every plane (the view frustum's, normalised, and every narrowed plane, unit normal) is widened
// outward by the margin m = 1e-7 R, cell boxes are grown by m for "contains the eye" and "the box
// meets the cell", and polygons are clipped keeping points up to m outside each plane, so a
// polygon that touches the frustum survives (as a sliver or a point, never dropped). The errors
// m covers: the clipped corners and planes carry a few dozen roundings (1e-14 R), amplified by at
// most the ratio of the segment's length to the eye's distance from the portal; that distance is
// at least 1e-5 R (an eye closer to a portal's plane crosses it without narrowing, since planes
// through an eye in the portal's plane are degenerate), so the amplified error stays below 1e-8 R,
// a tenth of m. Edge planes whose edge nearly points at the eye (sine of the angle at the eye
// below 1e-6: the normal's direction is ill-conditioned) are left out, which only loosens the
// frustum. At R = 20 (a building near the origin) m is 2e-6 units, at R = 1e4 it is 1e-3 units.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "patchcull/core/frustum.h"
#include "patchcull/core/math.h"
#include "patchcull/core/mesh.h"

namespace patchcull {

/// A planar convex opening between two cells (a door or window): corners in order around it,
/// either winding (the traversal crosses portals both ways).
struct CellPortal {
    std::uint32_t cell_a = 0, cell_b = 0;
    Vec3 corners[4];
};

/// Counters of traverse(), added to (a caller may sum them over frames).
struct PortalStats {
    std::uint32_t start_cells = 0;     ///< cells containing the eye (roots of the traversal)
    std::uint32_t cells_reached = 0;   ///< distinct cells reached (start cells included)
    std::uint32_t portals_tested = 0;  ///< portal polygons clipped against a narrowed frustum
    std::uint32_t portals_passed = 0;  ///< of those, crossed (each crossing makes one reach)
    std::uint32_t reaches = 0;         ///< reaches into cells: start cells plus crossings
    std::uint32_t capped = 0;          ///< traversals that hit a PortalLimits cap (then nothing is culled by cells)
};

/// Caps on one traversal (the number of paths through a grid of open doors grows exponentially
/// with its size; narrowing prunes most, the caps bound the rest).
struct PortalLimits {
    std::uint32_t max_depth = 64;      ///< portals crossed along one path
    std::uint32_t max_reaches = 4096;  ///< reaches in all (start cells included)
};

class PortalCuller {
public:
    /// cells: world boxes tiling the interior (finite, min <= max; flat boxes allowed); portals:
    /// openings between two different cells (indices < cells.size()), finite corners, a convex
    /// polygon with area (corners in order around it). Throws patchcull::Error with a one-line
    /// message naming the cell or portal otherwise. Until the first traverse nothing is culled.
    PortalCuller(std::vector<Bounds> cells, std::vector<CellPortal> portals, PortalLimits limits = {});

    /// One frame: eye (world) and the view frustum (planes in world space: make_frustum_planes(world_to_clip,
    /// depth), patchcull/core/frustum.h). Returns false when the eye is in no cell (or the eye or a
    /// frustum row is not finite): nothing is culled then (box_visible is true for everything,
    /// every cell reached). Otherwise starts from every cell whose box contains the eye (grown by
    /// the margin), crosses each portal whose polygon, clipped by the current narrowed frustum, is
    /// not empty, into a reach with the frustum narrowed to the planes through the eye and the
    /// clipped polygon's edges plus the view frustum's near and far planes, and recurses; no cell is
    /// entered twice along one path. Adds to stats. Allocates only while its buffers grow.
    bool traverse(const Vec3& eye, const FrustumPlanes& frustum, PortalStats& stats);

    /// True when the last traverse reached the cell (always for an eye in no cell, a capped
    /// traversal, or before the first traverse); false for an index out of range.
    bool cell_reached(std::size_t cell) const;

    /// True when the world box may be seen: it meets the box of a reached cell and is not outside
    /// the narrowed frustum of a reach into that cell (see the file comment: every visible point of
    /// the box makes it true). A box with a NaN coordinate: true; an empty box (min > max on an
    /// axis): false, unless nothing is culled (eye in no cell). Never allocates.
    bool box_visible(const Bounds& box) const;

    std::size_t cell_count() const { return cells_.size(); }
    std::size_t portal_count() const { return portals_.size(); }
    /// The margin m (world units) planes and cell boxes are widened by: 1e-7 R (file comment).
    double margin() const { return margin_; }

private:
    struct Plane {  // inside: x*p.x + y*p.y + z*p.z + w >= 0; (x, y, z) a unit normal or zero
        double x = 0, y = 0, z = 0, w = 0;
    };
    struct Point {
        double x = 0, y = 0, z = 0;
    };
    struct Portal {
        std::uint32_t cell_a = 0, cell_b = 0;
        Point corners[4];
        Point normal;       ///< unit, right-handed with the corner order
        double offset = 0;  ///< plane: dot(normal, p) + offset = 0 (through the corners' centroid)
    };
    struct Reach {
        std::uint32_t cell = 0;
        std::uint32_t plane_begin = 0, plane_end = 0;  ///< its frustum: planes_[begin, end)
        std::uint32_t next_in_cell = 0;                ///< next reach into the same cell, or kNone
    };
    struct Frame {
        std::uint32_t reach = 0;
        std::uint32_t cursor = 0;  ///< next entry of adjacency_ to try
    };
    static constexpr std::uint32_t kNone = 0xffffffffu;

    bool add_reach(std::uint32_t cell, std::uint32_t plane_begin, std::uint32_t plane_end);
    bool cross(const Portal& portal, const Reach& from, const Point& eye, std::uint32_t& plane_begin,
               std::uint32_t& plane_end);
    bool box_in_planes(const Bounds& box, std::uint32_t begin, std::uint32_t end) const;

    std::vector<Bounds> cells_;
    std::vector<Portal> portals_;
    std::vector<std::uint32_t> adjacency_begin_;  ///< per cell, into adjacency_ (cells + 1 entries)
    std::vector<std::uint32_t> adjacency_;        ///< portal indices touching each cell
    PortalLimits limits_;
    double margin_ = 0, near_portal_ = 0;

    // Per frame.
    bool cull_ = false;          ///< false: nothing is culled (no traverse yet, eye in no cell, bad input)
    bool capped_ = false;        ///< a cap was hit: only the view frustum culls
    std::vector<Plane> planes_;  ///< planes_[0, view_planes_) the widened view frustum, then reaches'
    std::uint32_t view_planes_ = 0;
    Plane near_far_[2];
    std::uint32_t near_far_count_ = 0;
    std::vector<Reach> reaches_;
    std::vector<std::uint32_t> first_reach_;  ///< per cell, or kNone
    std::vector<std::uint8_t> on_path_;
    std::vector<Frame> stack_;
    std::vector<Point> polygon_, clipped_;
};

}  // namespace patchcull
