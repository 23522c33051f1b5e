// Cells and portals (patchcull/objects/portal_culling.h): validation, the depth-first traversal with an
// explicit stack (no native recursion: a corridor of many cells must not overflow the stack), the
// portal clip (Sutherland-Hodgman against each plane of the current frustum) and the box test.
#include "patchcull/objects/portal_culling.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "patchcull/core/error.h"

namespace patchcull {
namespace {

constexpr double kMarginRelative = 1e-7;      // m = 1e-7 R (header: Rounding)
constexpr double kNearPortalRelative = 1e-5;  // eyes closer to a portal's plane cross it unnarrowed
constexpr double kMinEdgeSine = 1e-6;         // edge planes with a smaller angle at the eye are left out

struct D3 {
    double x, y, z;
};
inline D3 sub(D3 a, D3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline double dot3(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline D3 cross3(D3 a, D3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline double len3(D3 a) { return std::sqrt(dot3(a, a)); }
inline D3 to_d3(Vec3 v) { return {v.x, v.y, v.z}; }

bool finite_box(const Bounds& b) { return is_finite(b.min) && is_finite(b.max); }

double max_abs(Vec3 v) { return std::max({std::fabs(double(v.x)), std::fabs(double(v.y)), std::fabs(double(v.z))}); }

[[noreturn]] void fail(const std::string& what) { throw Error("portal culling: " + what); }

}  // namespace

PortalCuller::PortalCuller(std::vector<Bounds> cells, std::vector<CellPortal> portals, PortalLimits limits)
    : cells_(std::move(cells)), limits_(limits) {
    double scale = 0;
    for (std::size_t c = 0; c < cells_.size(); ++c) {
        const Bounds& b = cells_[c];
        if (!finite_box(b)) fail("cell " + std::to_string(c) + ": box has a non-finite coordinate");
        if (b.min.x > b.max.x || b.min.y > b.max.y || b.min.z > b.max.z)
            fail("cell " + std::to_string(c) + ": box is empty (min > max)");
        scale = std::max({scale, max_abs(b.min), max_abs(b.max)});
    }
    portals_.reserve(portals.size());
    for (std::size_t p = 0; p < portals.size(); ++p) {
        const CellPortal& in = portals[p];
        const std::string name = "portal " + std::to_string(p);
        if (in.cell_a >= cells_.size() || in.cell_b >= cells_.size())
            fail(name + ": cell index " + std::to_string(std::max(in.cell_a, in.cell_b)) + " out of range (" +
                 std::to_string(cells_.size()) + " cells)");
        if (in.cell_a == in.cell_b) fail(name + " joins cell " + std::to_string(in.cell_a) + " to itself");
        Portal out;
        out.cell_a = in.cell_a;
        out.cell_b = in.cell_b;
        D3 c[4];
        for (int k = 0; k < 4; ++k) {
            if (!is_finite(in.corners[k])) fail(name + ": corner " + std::to_string(k) + " is not finite");
            c[k] = to_d3(in.corners[k]);
            out.corners[k] = {c[k].x, c[k].y, c[k].z};
            scale = std::max(scale, max_abs(in.corners[k]));
        }
        // Newell's normal: right-handed with the corner order, robust for any planar polygon.
        D3 n{0, 0, 0}, centroid{0, 0, 0};
        double size = 0;
        for (int k = 0; k < 4; ++k) {
            const D3 a = c[k], b = c[(k + 1) % 4];
            n.x += (a.y - b.y) * (a.z + b.z);
            n.y += (a.z - b.z) * (a.x + b.x);
            n.z += (a.x - b.x) * (a.y + b.y);
            centroid = {centroid.x + a.x / 4, centroid.y + a.y / 4, centroid.z + a.z / 4};
            size = std::max(size, len3(sub(b, a)));
        }
        const double area2 = len3(n);
        if (!(area2 > 1e-12 * size * size)) fail(name + " has no area");
        const D3 unit{n.x / area2, n.y / area2, n.z / area2};
        // Convex, corners in order: every turn agrees with the normal (collinear corners allowed).
        for (int k = 0; k < 4; ++k) {
            const D3 e1 = sub(c[(k + 1) % 4], c[k]), e2 = sub(c[(k + 2) % 4], c[(k + 1) % 4]);
            if (dot3(cross3(e1, e2), unit) < -1e-6 * len3(e1) * len3(e2))
                fail(name + " is not convex (corners must go around it in order)");
        }
        out.normal = {unit.x, unit.y, unit.z};
        out.offset = -dot3(unit, centroid);
        portals_.push_back(out);
    }
    scale = std::max(scale, 1e-30);
    margin_ = kMarginRelative * scale;
    near_portal_ = kNearPortalRelative * scale;

    adjacency_begin_.assign(cells_.size() + 1, 0);
    for (const Portal& p : portals_) {
        ++adjacency_begin_[p.cell_a + 1];
        ++adjacency_begin_[p.cell_b + 1];
    }
    for (std::size_t c = 0; c < cells_.size(); ++c) adjacency_begin_[c + 1] += adjacency_begin_[c];
    adjacency_.resize(adjacency_begin_.back());
    std::vector<std::uint32_t> fill(adjacency_begin_.begin(), adjacency_begin_.end() - 1);
    for (std::uint32_t p = 0; p < portals_.size(); ++p) {
        adjacency_[fill[portals_[p].cell_a]++] = p;
        adjacency_[fill[portals_[p].cell_b]++] = p;
    }
    first_reach_.assign(cells_.size(), kNone);
    on_path_.assign(cells_.size(), 0);
}

bool PortalCuller::add_reach(std::uint32_t cell, std::uint32_t plane_begin, std::uint32_t plane_end) {
    if (reaches_.size() >= limits_.max_reaches) return false;
    const auto index = static_cast<std::uint32_t>(reaches_.size());
    reaches_.push_back({cell, plane_begin, plane_end, first_reach_[cell]});
    first_reach_[cell] = index;
    return true;
}

bool PortalCuller::traverse(const Vec3& eye_in, const FrustumPlanes& frustum, PortalStats& stats) {
    cull_ = false;
    capped_ = false;
    planes_.clear();
    reaches_.clear();
    stack_.clear();
    std::fill(first_reach_.begin(), first_reach_.end(), kNone);
    std::fill(on_path_.begin(), on_path_.end(), std::uint8_t{0});
    view_planes_ = 0;
    near_far_count_ = 0;

    if (!is_finite(eye_in)) return false;
    for (const Vec4& r : frustum.rows)
        if (!std::isfinite(r.x) || !std::isfinite(r.y) || !std::isfinite(r.z) || !std::isfinite(r.w)) return false;
    const Point eye{eye_in.x, eye_in.y, eye_in.z};

    // The view frustum, normalised (a row without a normal constrains nothing we can use: left out,
    // which only loosens) and widened by the margin.
    for (int q = 0; q < 6; ++q) {
        const Vec4& r = frustum.rows[q];
        const double len = std::sqrt(double(r.x) * r.x + double(r.y) * r.y + double(r.z) * r.z);
        if (!(len > 0)) continue;
        const Plane plane{r.x / len, r.y / len, r.z / len, r.w / len + margin_};
        planes_.push_back(plane);
        if (q >= 4) near_far_[near_far_count_++] = plane;
    }
    view_planes_ = static_cast<std::uint32_t>(planes_.size());

    std::uint32_t starts = 0;
    for (std::uint32_t c = 0; c < cells_.size(); ++c) {
        const Bounds& b = cells_[c];
        const double m = margin_;
        if (eye.x < b.min.x - m || eye.x > b.max.x + m || eye.y < b.min.y - m || eye.y > b.max.y + m ||
            eye.z < b.min.z - m || eye.z > b.max.z + m)
            continue;
        ++starts;
        if (!add_reach(c, 0, view_planes_)) capped_ = true;
    }
    if (starts == 0) return false;
    cull_ = true;
    stats.start_cells += starts;

    std::uint32_t passed = 0;
    const std::uint32_t roots = static_cast<std::uint32_t>(reaches_.size());
    for (std::uint32_t root = 0; root < roots && !capped_; ++root) {
        stack_.push_back({root, adjacency_begin_[reaches_[root].cell]});
        on_path_[reaches_[root].cell] = 1;
        while (!stack_.empty() && !capped_) {
            Frame& top = stack_.back();
            const Reach from = reaches_[top.reach];
            if (top.cursor == adjacency_begin_[from.cell + 1]) {
                on_path_[from.cell] = 0;
                stack_.pop_back();
                continue;
            }
            const Portal& portal = portals_[adjacency_[top.cursor++]];
            const std::uint32_t to = portal.cell_a == from.cell ? portal.cell_b : portal.cell_a;
            if (on_path_[to]) continue;
            ++stats.portals_tested;
            std::uint32_t begin = 0, end = 0;
            if (!cross(portal, from, eye, begin, end)) continue;
            if (stack_.size() > limits_.max_depth || !add_reach(to, begin, end)) {
                capped_ = true;
                break;
            }
            ++passed;
            on_path_[to] = 1;
            stack_.push_back({static_cast<std::uint32_t>(reaches_.size() - 1), adjacency_begin_[to]});
        }
        for (const Frame& f : stack_) on_path_[reaches_[f.reach].cell] = 0;
        stack_.clear();
    }

    stats.portals_passed += passed;
    stats.reaches += static_cast<std::uint32_t>(reaches_.size());
    if (capped_) {
        ++stats.capped;
        stats.cells_reached += static_cast<std::uint32_t>(cells_.size());
    } else {
        for (std::uint32_t r : first_reach_) stats.cells_reached += r != kNone;
    }
    return true;
}

// Clips the portal by the reach's frustum; on a non-empty result appends the narrowed frustum to
// planes_ and returns its range.
bool PortalCuller::cross(const Portal& portal, const Reach& from, const Point& eye_p, std::uint32_t& plane_begin,
                         std::uint32_t& plane_end) {
    const D3 eye{eye_p.x, eye_p.y, eye_p.z};
    const D3 normal{portal.normal.x, portal.normal.y, portal.normal.z};
    const double eye_side = dot3(normal, eye) + portal.offset;
    if (std::fabs(eye_side) <= near_portal_) {
        // Planes through an eye in (or next to) the portal's plane are degenerate: cross with the
        // current frustum unchanged (looser, so conservative).
        plane_begin = from.plane_begin;
        plane_end = from.plane_end;
        return true;
    }

    polygon_.clear();
    for (const Point& c : portal.corners) polygon_.push_back(c);
    for (std::uint32_t q = from.plane_begin; q < from.plane_end && !polygon_.empty(); ++q) {
        const Plane& pl = planes_[q];
        auto value = [&](const Point& p) { return pl.x * p.x + pl.y * p.y + pl.z * p.z + pl.w; };
        // Keep what lies between eye and any point inside: a plane with the eye outside (the near
        // plane) is moved to pass through the eye; then keep up to m outside (touching survives).
        const double limit = std::min(value(eye_p), 0.0) - margin_;
        clipped_.clear();
        const std::size_t n = polygon_.size();
        for (std::size_t i = 0; i < n; ++i) {
            const Point& a = polygon_[i];
            const Point& b = polygon_[(i + 1) % n];
            const double va = value(a) - limit, vb = value(b) - limit;
            if (va >= 0) clipped_.push_back(a);
            if ((va >= 0) != (vb >= 0)) {
                const double t = std::clamp(va / (va - vb), 0.0, 1.0);
                clipped_.push_back({a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), a.z + t * (b.z - a.z)});
            }
        }
        polygon_.swap(clipped_);
    }
    if (polygon_.empty()) return false;

    plane_begin = static_cast<std::uint32_t>(planes_.size());
    for (std::uint32_t k = 0; k < near_far_count_; ++k) planes_.push_back(near_far_[k]);
    // The cone from the eye through the clipped polygon: one plane per edge, its inside towards the
    // polygon. The clip keeps the corners' winding, so the side follows from the normal and the
    // eye's side of the portal; that works for slivers too (a polygon flattened to a segment gives
    // the two sides of the wedge through it).
    const std::size_t n = polygon_.size();
    for (std::size_t i = 0; i < n; ++i) {
        const Point& pa = polygon_[i];
        const Point& pb = polygon_[(i + 1) % n];
        const D3 a = sub({pa.x, pa.y, pa.z}, eye), b = sub({pb.x, pb.y, pb.z}, eye);
        const D3 c = eye_side > 0 ? cross3(b, a) : cross3(a, b);
        const double len = len3(c);
        if (!(len > kMinEdgeSine * len3(a) * len3(b))) continue;
        const D3 u{c.x / len, c.y / len, c.z / len};
        planes_.push_back({u.x, u.y, u.z, -dot3(u, eye) + margin_});
    }
    plane_end = static_cast<std::uint32_t>(planes_.size());
    return true;
}

bool PortalCuller::box_in_planes(const Bounds& box, std::uint32_t begin, std::uint32_t end) const {
    for (std::uint32_t q = begin; q < end; ++q) {
        const Plane& p = planes_[q];
        // The p-vertex: the corner with the largest value.
        const double v = p.x * (p.x >= 0 ? box.max.x : box.min.x) + p.y * (p.y >= 0 ? box.max.y : box.min.y) +
                         p.z * (p.z >= 0 ? box.max.z : box.min.z) + p.w;
        if (v < 0) return false;
    }
    return true;
}

bool PortalCuller::cell_reached(std::size_t cell) const {
    if (cell >= cells_.size()) return false;
    return !cull_ || capped_ || first_reach_[cell] != kNone;
}

bool PortalCuller::box_visible(const Bounds& box) const {
    if (!finite_box(box)) {
        const Vec3 lo = box.min, hi = box.max;
        if (std::isnan(lo.x) || std::isnan(lo.y) || std::isnan(lo.z) || std::isnan(hi.x) || std::isnan(hi.y) ||
            std::isnan(hi.z))
            return true;
    }
    if (!cull_) return true;
    if (box.min.x > box.max.x || box.min.y > box.max.y || box.min.z > box.max.z) return false;
    if (capped_) return box_in_planes(box, 0, view_planes_);
    const double m = margin_;
    for (std::size_t c = 0; c < cells_.size(); ++c) {
        std::uint32_t r = first_reach_[c];
        if (r == kNone) continue;
        const Bounds& cb = cells_[c];
        if (box.max.x < cb.min.x - m || box.min.x > cb.max.x + m || box.max.y < cb.min.y - m ||
            box.min.y > cb.max.y + m || box.max.z < cb.min.z - m || box.min.z > cb.max.z + m)
            continue;
        for (; r != kNone; r = reaches_[r].next_in_cell)
            if (box_in_planes(box, reaches_[r].plane_begin, reaches_[r].plane_end)) return true;
    }
    return false;
}

}  // namespace patchcull
