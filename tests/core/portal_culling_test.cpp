// Cells and portals (patchcull/objects/portal_culling.h): every point visible from the eye (inside the view
// frustum, the segment to it through no wall: CPU ray casting against the wall boxes, in double)
// is in a reached cell and box_visible, over hundreds of random grid buildings (2x2..4x4 rooms of
// random size, walls as thick boxes with doors and windows, cells from wall centre to wall centre
// as in builtin_scenes.h's `building`), eyes in rooms, doorways, exactly on portal planes and
// portal edges, views grazing a portal's edge, buildings 1e4 from the origin, small caps; culling
// does happen (a closed wall and misaligned doors hide the rooms behind them, aligned doors show
// them); an eye outside every cell culls nothing; bad input throws.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "patchcull/core/error.h"
#include "patchcull/core/frustum.h"
#include "patchcull/objects/portal_culling.h"

namespace patchcull {
namespace {

struct DV {
    double x = 0, y = 0, z = 0;
};
DV dv(Vec3 v) { return {v.x, v.y, v.z}; }
double comp(DV v, int k) { return k == 0 ? v.x : k == 1 ? v.y : v.z; }
double comp(Vec3 v, int k) { return k == 0 ? v.x : k == 1 ? v.y : v.z; }

// An opening through a wall: u along the wall (z for a wall across x, x for one across z), y up.
struct Opening {
    float u0 = 0, u1 = 0, y0 = 0, y1 = 0;
};

struct Wall {
    Bounds slab;
    int axis = 0;     // 0: its thickness is along x (the wall lies in a plane x = mid), 2: along z; 1: floor, ceiling
    float mid = 0;    // its mid-plane, where the cells meet and the portals lie
    int line = 0;     // index into xs (axis 0) or zs (axis 2)
    int segment = 0;  // the row (axis 0) or column (axis 2) it closes
    std::vector<Opening> openings;
};

// A grid of rooms: wall centres at xs (x) and zs (z), floor at y0. Cell j * nx + i is the room in
// column i, row j.
struct Building {
    std::vector<float> xs, zs;
    float y0 = 0, height = 0, thickness = 0;
    std::vector<Bounds> cells;
    std::vector<Wall> walls;
    std::vector<CellPortal> portals;
    double scale = 1;  // largest absolute coordinate
    int nx() const { return int(xs.size()) - 1; }
    int nz() const { return int(zs.size()) - 1; }
};

Vec3 on_wall(const Wall& w, float u, float y) { return w.axis == 0 ? Vec3{w.mid, y, u} : Vec3{u, y, w.mid}; }

// Closed rooms (every wall a solid box; walls overlap at the junctions, so there are no seams).
Building make_grid(const std::vector<float>& widths, const std::vector<float>& depths, float height, float thickness,
                   Vec3 offset) {
    Building b;
    b.height = height;
    b.thickness = thickness;
    b.y0 = offset.y;
    b.xs.push_back(offset.x);
    for (float w : widths) b.xs.push_back(b.xs.back() + w);
    b.zs.push_back(offset.z);
    for (float d : depths) b.zs.push_back(b.zs.back() + d);
    // Walls reach into the floor and ceiling slabs: solids overlap, no seam for a segment to slip through.
    const float h = thickness / 2, top = b.y0 + height, wall_lo = b.y0 - thickness, wall_hi = top + thickness;
    for (int j = 0; j < b.nz(); ++j)
        for (int i = 0; i < b.nx(); ++i)
            b.cells.push_back({{b.xs[i], b.y0 - thickness, b.zs[j]}, {b.xs[i + 1], top + thickness, b.zs[j + 1]}});
    for (int i = 0; i <= b.nx(); ++i)
        for (int j = 0; j < b.nz(); ++j) {
            Wall w;
            w.axis = 0, w.mid = b.xs[i], w.line = i, w.segment = j;
            w.slab = {{b.xs[i] - h, wall_lo, b.zs[j] - h}, {b.xs[i] + h, wall_hi, b.zs[j + 1] + h}};
            b.walls.push_back(w);
        }
    for (int j = 0; j <= b.nz(); ++j)
        for (int i = 0; i < b.nx(); ++i) {
            Wall w;
            w.axis = 2, w.mid = b.zs[j], w.line = j, w.segment = i;
            w.slab = {{b.xs[i] - h, wall_lo, b.zs[j] - h}, {b.xs[i + 1] + h, wall_hi, b.zs[j] + h}};
            b.walls.push_back(w);
        }
    // The floor and ceiling slabs (the cells run from the floor's bottom to the ceiling's top).
    for (int k = 0; k < 2; ++k) {
        Wall w;
        w.axis = 1;
        const float y = k == 0 ? b.y0 - thickness : top;
        w.slab = {{b.xs.front() - h, y, b.zs.front() - h}, {b.xs.back() + h, y + thickness, b.zs.back() + h}};
        b.walls.push_back(w);
    }
    for (const Bounds& c : b.cells)
        for (Vec3 v : {c.min, c.max})
            b.scale = std::max({b.scale, std::fabs(double(v.x)), std::fabs(double(v.y)), std::fabs(double(v.z))});
    return b;
}

int wall_index(const Building& b, int axis, int line, int segment) {
    for (std::size_t k = 0; k < b.walls.size(); ++k)
        if (b.walls[k].axis == axis && b.walls[k].line == line && b.walls[k].segment == segment) return int(k);
    return -1;
}

bool inner_wall(const Building& b, const Wall& w) { return w.line > 0 && w.line < (w.axis == 0 ? b.nx() : b.nz()); }

// Cuts an opening into an inner wall and adds its portal: the rectangle in the wall's mid-plane,
// corners in either winding from any start corner (rng), cells in either order.
void add_opening(Building& b, int wall, Opening o, std::mt19937* rng = nullptr) {
    Wall& w = b.walls[wall];
    w.openings.push_back(o);
    CellPortal p;
    const int nx = b.nx();
    if (w.axis == 0) {
        p.cell_a = std::uint32_t(w.segment * nx + w.line - 1);
        p.cell_b = std::uint32_t(w.segment * nx + w.line);
    } else {
        p.cell_a = std::uint32_t((w.line - 1) * nx + w.segment);
        p.cell_b = std::uint32_t(w.line * nx + w.segment);
    }
    Vec3 c[4] = {on_wall(w, o.u0, o.y0), on_wall(w, o.u1, o.y0), on_wall(w, o.u1, o.y1), on_wall(w, o.u0, o.y1)};
    int start = 0;
    bool reverse = false;
    if (rng) {
        start = int((*rng)() % 4);
        reverse = (*rng)() % 2;
        if ((*rng)() % 2) std::swap(p.cell_a, p.cell_b);
    }
    for (int k = 0; k < 4; ++k) p.corners[k] = c[(start + (reverse ? 4 - k : k)) % 4];
    b.portals.push_back(p);
}

// A random building: 2..4 x 2..4 rooms of random size, each inner wall closed or with one or two
// openings (doors from the floor, windows), away from the junctions.
Building random_building(std::mt19937& rng, Vec3 offset) {
    std::uniform_real_distribution<float> unit(0, 1);
    auto between = [&](float a, float c) { return a + (c - a) * unit(rng); };
    std::vector<float> widths(2 + rng() % 3), depths(2 + rng() % 3);
    for (float& w : widths) w = between(2.5f, 7);
    for (float& d : depths) d = between(2.5f, 7);
    Building b = make_grid(widths, depths, between(2.2f, 4), between(0.1f, 0.4f), offset);
    const float h = b.thickness / 2;
    for (int k = 0; k < int(b.walls.size()); ++k) {
        const Wall& w = b.walls[k];
        if (!inner_wall(b, w)) continue;
        const std::vector<float>& along = w.axis == 0 ? b.zs : b.xs;
        const float lo = along[w.segment] + h + 0.1f, hi = along[w.segment + 1] - h - 0.1f;
        const float r = unit(rng);
        const int count = r < 0.25f ? 0 : r < 0.8f ? 1 : 2;
        for (int n = 0; n < count; ++n) {
            // Two openings share the wall: each gets its own half, 0.1 apart.
            const float a = count == 1 ? lo : n == 0 ? lo : (lo + hi) / 2 + 0.05f;
            const float c = count == 1 ? hi : n == 0 ? (lo + hi) / 2 - 0.05f : hi;
            const float width = std::min(between(0.5f, 1.5f), c - a);
            const float u0 = between(a, c - width);
            Opening o;
            o.u0 = u0, o.u1 = u0 + width;
            if (unit(rng) < 0.6f) {
                o.y0 = b.y0, o.y1 = b.y0 + std::min(between(1.6f, 2.2f), b.height - 0.1f);
            } else {
                o.y0 = b.y0 + between(0.4f, 1.0f), o.y1 = b.y0 + between(1.4f, b.height - 0.1f);
            }
            add_opening(b, k, o, &rng);
        }
    }
    return b;
}

// ---- ground truth ----

bool in_opening(const Wall& w, const Opening& o, DV q, double tol) {
    const double u = w.axis == 0 ? q.z : q.x;
    return u >= o.u0 - tol && u <= o.u1 + tol && q.y >= o.y0 - tol && q.y <= o.y1 + tol;
}

// True when the segment e -> p passes through a wall's solid: through the open interior of a wall
// box, not within one opening's tunnel all the way (the tunnel is convex, so both ends of the part
// inside the box decide). Grazing a wall's face or an opening's edge is not blocked; 1e-10 of the
// scale is forgiven at the edges (so the culler must keep those segments too).
bool blocked(const Building& b, DV e, DV p) {
    const DV d{p.x - e.x, p.y - e.y, p.z - e.z};
    const double tol = 1e-10 * b.scale;
    for (const Wall& w : b.walls) {
        double t0 = 0, t1 = 1;
        bool miss = false;
        for (int k = 0; k < 3 && !miss; ++k) {
            const double lo = comp(w.slab.min, k), hi = comp(w.slab.max, k), o = comp(e, k), dk = comp(d, k);
            if (dk == 0) {
                miss = !(o > lo && o < hi);
                continue;
            }
            double ta = (lo - o) / dk, tb = (hi - o) / dk;
            if (ta > tb) std::swap(ta, tb);
            t0 = std::max(t0, ta);
            t1 = std::min(t1, tb);
        }
        if (miss || !(t0 < t1)) continue;
        const DV q0{e.x + t0 * d.x, e.y + t0 * d.y, e.z + t0 * d.z};
        const DV q1{e.x + t1 * d.x, e.y + t1 * d.y, e.z + t1 * d.z};
        bool through = false;
        for (const Opening& o : w.openings)
            through = through || (in_opening(w, o, q0, tol) && in_opening(w, o, q1, tol));
        if (!through) return true;
    }
    return false;
}

bool in_frustum(const FrustumPlanes& planes, DV p) {
    for (const Vec4& r : planes.rows)
        if (double(r.x) * p.x + double(r.y) * p.y + double(r.z) * p.z + double(r.w) < 0) return false;
    return true;
}

bool in_box(const Bounds& c, Vec3 p) {
    return p.x >= c.min.x && p.x <= c.max.x && p.y >= c.min.y && p.y <= c.max.y && p.z >= c.min.z && p.z <= c.max.z;
}

bool in_some_cell(const Building& b, Vec3 p) {
    for (const Bounds& c : b.cells)
        if (in_box(c, p)) return true;
    return false;
}

bool some_cell_reached(const Building& b, const PortalCuller& culler, Vec3 p) {
    for (std::size_t c = 0; c < b.cells.size(); ++c)
        if (in_box(b.cells[c], p) && culler.cell_reached(c)) return true;
    return false;
}

bool visible(const Building& b, const FrustumPlanes& planes, Vec3 eye, Vec3 p) {
    return in_frustum(planes, dv(p)) && !blocked(b, dv(eye), dv(p));
}

FrustumPlanes camera_planes(Vec3 eye, Vec3 direction, float fovy, float aspect, float z_near, float z_far,
                            ClipDepth depth) {
    const Mat4 world_to_clip =
        perspective(fovy, aspect, z_near, z_far, depth) * look_at(eye, eye + direction, {0, 1, 0});
    return make_frustum_planes(world_to_clip, depth);
}

// ---- random points ----

struct Sampler {
    const Building& b;
    std::mt19937& rng;
    std::uniform_real_distribution<float> unit{0, 1};
    float between(float a, float c) { return a + (c - a) * unit(rng); }

    Vec3 in_room(float inset) {
        const int i = int(rng() % b.nx()), j = int(rng() % b.nz());
        const float h = b.thickness / 2 + inset;
        return {between(b.xs[i] + h, b.xs[i + 1] - h), between(b.y0 + inset, b.y0 + b.height - inset),
                between(b.zs[j] + h, b.zs[j + 1] - h)};
    }
    bool has_openings() const {
        for (const Wall& w : b.walls)
            if (!w.openings.empty()) return true;
        return false;
    }
    void random_opening(const Wall*& wall, const Opening*& opening) {
        std::vector<std::pair<const Wall*, const Opening*>> all;
        for (const Wall& w : b.walls)
            for (const Opening& o : w.openings) all.push_back({&w, &o});
        const auto& pick = all[rng() % all.size()];
        wall = pick.first, opening = pick.second;
    }
    // A point of an opening's tunnel (across the wall's thickness); mid_plane: exactly on the portal;
    // near_plane: 1e-7 .. 1e-2 off it, either way (where planes through the eye degenerate).
    Vec3 in_doorway(bool mid_plane, bool near_plane = false) {
        const Wall* w;
        const Opening* o;
        random_opening(w, o);
        const float h = b.thickness / 2;
        float across = mid_plane ? w->mid : between(w->mid - h, w->mid + h);
        if (near_plane) across = w->mid + (rng() % 2 ? 1 : -1) * std::pow(10.0f, between(-7, -2));
        const Vec3 q = on_wall(*w, between(o->u0, o->u1), between(o->y0 + 0.01f, o->y1 - 0.01f));
        return w->axis == 0 ? Vec3{across, q.y, q.z} : Vec3{q.x, q.y, across};
    }
    // A point on an edge of an opening's tunnel: at its mid-plane or either face.
    Vec3 on_opening_edge() {
        const Wall* w;
        const Opening* o;
        random_opening(w, o);
        const float h = b.thickness / 2;
        const int face = int(rng() % 3);
        const float across = face == 0 ? w->mid : face == 1 ? w->mid - h : w->mid + h;
        float u = between(o->u0, o->u1), y = between(o->y0, o->y1);
        switch (rng() % 4) {
            case 0:
                u = o->u0;
                break;
            case 1:
                u = o->u1;
                break;
            case 2:
                y = o->y0;
                break;
            default:
                y = o->y1;
                break;
        }
        const Vec3 q = on_wall(*w, u, y);
        return w->axis == 0 ? Vec3{across, q.y, q.z} : Vec3{q.x, q.y, across};
    }
    Vec3 direction(float pitch_range) {
        const float yaw = between(0, 6.2831853f), pitch = between(-pitch_range, pitch_range);
        return {std::cos(yaw) * std::cos(pitch), std::sin(pitch), std::sin(yaw) * std::cos(pitch)};
    }
};

struct Tally {
    long visible_points = 0, visible_through_portals = 0, hidden_in_frustum = 0, hidden_culled = 0, visible_boxes = 0,
         cases = 0, capped = 0;
    long cells = 0, cells_reached = 0;
    int failures = 0;
};

void check_point(const Building& b, const PortalCuller& culler, const FrustumPlanes& planes, Vec3 eye, Vec3 p,
                 Tally& tally, const char* kind, int case_index) {
    if (!in_some_cell(b, p)) return;
    const bool in_view = in_frustum(planes, dv(p));
    const bool seen = in_view && !blocked(b, dv(eye), dv(p));
    const bool reported = culler.box_visible({p, p});
    if (seen) {
        ++tally.visible_points;
        bool eye_cell = false;
        for (const Bounds& c : b.cells) eye_cell = eye_cell || (in_box(c, p) && in_box(c, eye));
        tally.visible_through_portals += !eye_cell;
        const bool reached = some_cell_reached(b, culler, p);
        if ((!reported || !reached) && ++tally.failures <= 5)
            ADD_FAILURE() << "case " << case_index << " (" << kind << "): visible point (" << p.x << ", " << p.y << ", "
                          << p.z << ") from eye (" << eye.x << ", " << eye.y << ", " << eye.z
                          << "): box_visible=" << reported << " cell reached=" << reached;
    } else if (in_view) {
        ++tally.hidden_in_frustum;
        tally.hidden_culled += !reported;
    }
}

void run_case(std::mt19937& rng, int case_index, Tally& tally) {
    std::uniform_real_distribution<float> unit(0, 1);
    Vec3 offset{0, 0, 0};
    if (case_index % 4 == 3) {
        auto sign = [&] { return rng() % 2 ? 1.0f : -1.0f; };
        offset = {sign() * (1e4f + 100 * unit(rng)), case_index % 8 == 7 ? 1e4f : 0.0f,
                  sign() * (1e4f + 100 * unit(rng))};
    }
    const Building b = random_building(rng, offset);
    Sampler s{b, rng};
    PortalLimits limits;
    if (case_index % 10 == 7) limits = {std::uint32_t(rng() % 3), 1 + std::uint32_t(rng() % 12)};
    PortalCuller culler(b.cells, b.portals, limits);

    // The eye: in a room, in a doorway, exactly on a portal's plane, exactly on a portal's edge, or
    // in a room looking through a point on an opening's edge (grazing).
    const float mode = unit(rng);
    const bool openings = s.has_openings();
    Vec3 eye = s.in_room(0.02f), grazing_target{};
    bool grazing = false;
    if (openings && mode < 0.15f)
        eye = s.in_doorway(false);
    else if (openings && mode < 0.22f)
        eye = s.in_doorway(true);
    else if (openings && mode < 0.27f)
        eye = s.in_doorway(false, true);
    else if (openings && mode < 0.32f) {
        eye = s.on_opening_edge();
    } else if (openings && mode < 0.57f) {
        grazing = true;
        grazing_target = s.on_opening_edge();
    }
    Vec3 dir = s.direction(0.5f);
    if (grazing)
        dir = grazing_target - eye;
    else if (openings && unit(rng) < 0.4f)
        dir = s.in_doorway(true) - eye + s.direction(0.3f) * 0.3f;
    if (std::fabs(dir.x) + std::fabs(dir.z) < 1e-3f * length(dir)) dir = s.direction(0.5f);  // look_at needs a yaw
    const ClipDepth depth = rng() % 2 ? ClipDepth::zero_to_one : ClipDepth::minus_one_to_one;
    const float fovy = s.between(0.2f, 2.2f), aspect = s.between(0.5f, 2.5f);
    const FrustumPlanes planes = camera_planes(eye, dir, fovy, aspect, s.between(0.01f, 0.5f), s.between(3, 60), depth);
    // Points along random view rays (most points of a building are hidden; these find the seen ones).
    const Vec3 forward = normalize(dir), right = normalize(cross(forward, {0, 1, 0})), up = cross(right, forward);
    auto along_view_ray = [&] {
        const float ty = std::tan(fovy / 2) * s.between(-1.05f, 1.05f),
                    tx = std::tan(fovy / 2) * aspect * s.between(-1.05f, 1.05f);
        const float near_first = s.between(0, 1);
        return eye + (forward + right * tx + up * ty) * (12 * near_first * near_first);
    };

    PortalStats stats;
    ASSERT_TRUE(culler.traverse(eye, planes, stats)) << "case " << case_index;
    ASSERT_GE(stats.start_cells, 1u);
    ++tally.cases;
    tally.capped += stats.capped;
    tally.cells += long(b.cells.size());
    tally.cells_reached += stats.cells_reached;

    for (int k = 0; k < 300; ++k) {
        const float r = unit(rng);
        Vec3 p;
        if (r < 0.35f)
            p = along_view_ray();
        else if (r < 0.65f || !openings)
            p = s.in_room(0);
        else if (r < 0.8f)
            p = s.in_doorway(false);
        else {
            // Beyond a point of an opening's edge, seen from the eye: rays that graze the edge.
            const Vec3 q = grazing && r < 0.9f ? grazing_target : s.on_opening_edge();
            p = eye + (q - eye) * s.between(1, 5);
        }
        check_point(b, culler, planes, eye, p, tally, "point", case_index);
    }
    // Small boxes: visible when one of their sampled points is.
    for (int k = 0; k < 30; ++k) {
        const float r = unit(rng);
        const Vec3 c = r < 0.5f ? along_view_ray() : r < 0.8f || !openings ? s.in_room(0) : s.in_doorway(false);
        const Vec3 h{0.3f * unit(rng), 0.3f * unit(rng), 0.3f * unit(rng)};
        const Bounds box{c - h, c + h};
        bool seen = false;
        for (int i = 0; i < 27 + 12 && !seen; ++i) {
            Vec3 p;
            if (i < 27) {
                const float t[3] = {0, 0.5f, 1};
                p = {box.min.x + t[i % 3] * (box.max.x - box.min.x), box.min.y + t[i / 3 % 3] * (box.max.y - box.min.y),
                     box.min.z + t[i / 9] * (box.max.z - box.min.z)};
            } else {
                p = {s.between(box.min.x, box.max.x), s.between(box.min.y, box.max.y), s.between(box.min.z, box.max.z)};
            }
            seen = in_some_cell(b, p) && visible(b, planes, eye, p);
        }
        if (!seen) continue;
        ++tally.visible_boxes;
        if (!culler.box_visible(box) && ++tally.failures <= 5)
            ADD_FAILURE() << "case " << case_index << ": visible box culled";
    }
    // Degenerate boxes: NaN is kept, an empty box has nothing to see.
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_TRUE(culler.box_visible({{nan, 0, 0}, {1, 1, 1}}));
    EXPECT_FALSE(culler.box_visible({eye + Vec3{0.01f, 0, 0}, eye - Vec3{0.01f, 0, 0}}));
}

TEST(PortalCulling, EveryVisiblePointOfRandomBuildingsIsInAReachedCellAndBoxVisible) {
    std::mt19937 rng(20240612);
    Tally tally;
    for (int c = 0; c < 600; ++c) {
        run_case(rng, c, tally);
        if (HasFatalFailure()) return;
    }
    EXPECT_EQ(tally.failures, 0);
    // The test must not be vacuous, and the culler must cull: most points hidden by walls inside
    // the view frustum are culled, and many cells are not reached.
    EXPECT_GT(tally.visible_points, 15000);
    EXPECT_GT(tally.visible_through_portals, 3000);
    EXPECT_GT(tally.visible_boxes, 1000);
    EXPECT_GT(tally.hidden_in_frustum, 20000);
    EXPECT_GT(double(tally.hidden_culled), 0.5 * double(tally.hidden_in_frustum));
    EXPECT_LT(double(tally.cells_reached), 0.8 * double(tally.cells));
    EXPECT_GT(tally.capped, 10);
    std::printf(
        "portal culling: %ld cases, %ld capped, %ld visible points (%ld through portals), %ld visible boxes, %ld of "
        "%ld hidden points "
        "in the frustum culled, %ld of %ld cells reached\n",
        tally.cases, tally.capped, tally.visible_points, tally.visible_through_portals, tally.visible_boxes,
        tally.hidden_culled, tally.hidden_in_frustum, tally.cells_reached, tally.cells);
    RecordProperty("visible_points", int(tally.visible_points));
    RecordProperty("hidden_culled_percent", int(100 * tally.hidden_culled / std::max(1L, tally.hidden_in_frustum)));
}

// ---- directed cases: a row of three rooms, 4 wide (x) and 6 deep (z) ----

Building row_of_three(bool door01, Opening o01, bool door12, Opening o12) {
    Building b = make_grid({4, 4, 4}, {6}, 3, 0.2f, {0, 0, 0});
    if (door01) add_opening(b, wall_index(b, 0, 1, 0), o01);
    if (door12) add_opening(b, wall_index(b, 0, 2, 0), o12);
    return b;
}

FrustumPlanes looking_along_x(Vec3 eye, float fovy) {
    return camera_planes(eye, {1, 0, 0}, fovy, 1.0f, 0.05f, 50, ClipDepth::zero_to_one);
}

TEST(PortalCulling, AlignedDoorsShowTheLastRoomThroughTheirConeOnly) {
    const Building b = row_of_three(true, {2.5f, 3.5f, 0, 2}, true, {2.5f, 3.5f, 0, 2});
    PortalCuller culler(b.cells, b.portals);
    const Vec3 eye{1, 1, 3};
    const FrustumPlanes planes = looking_along_x(eye, 1.0f);
    PortalStats stats;
    ASSERT_TRUE(culler.traverse(eye, planes, stats));
    EXPECT_EQ(stats.start_cells, 1u);
    EXPECT_EQ(stats.portals_passed, 2u);
    EXPECT_EQ(stats.reaches, 3u);
    EXPECT_EQ(stats.cells_reached, 3u);
    EXPECT_EQ(stats.capped, 0u);
    for (std::size_t c = 0; c < 3; ++c) EXPECT_TRUE(culler.cell_reached(c));
    EXPECT_FALSE(culler.cell_reached(3));  // out of range
    // Through both doors: seen and kept.
    const Vec3 through{10, 1, 3};
    ASSERT_TRUE(visible(b, planes, eye, through));
    EXPECT_TRUE(culler.box_visible({through, through}));
    // In the view frustum but off the doors' cone: hidden by the walls, and culled.
    for (Vec3 hidden : {Vec3{11.5f, 1, 0.5f}, Vec3{6, 1, 1.0f}, Vec3{10, 2.8f, 5.5f}}) {
        ASSERT_TRUE(in_frustum(planes, dv(hidden)));
        ASSERT_FALSE(visible(b, planes, eye, hidden));
        EXPECT_FALSE(culler.box_visible({hidden - Vec3{0.1f, 0.1f, 0.1f}, hidden + Vec3{0.1f, 0.1f, 0.1f}}));
    }
    // Behind the eye, in its own room: outside the view frustum.
    EXPECT_FALSE(culler.box_visible({{0.2f, 0.5f, 2.5f}, {0.4f, 0.7f, 3.5f}}));
    // A box spanning the door's cone is kept.
    EXPECT_TRUE(culler.box_visible({{9, 0.5f, 0.2f}, {9.5f, 1.5f, 5.8f}}));

    // The same doors with a depth cap of one portal: the traversal stops and culls by the view
    // frustum alone (conservative), and says so.
    PortalCuller capped(b.cells, b.portals, PortalLimits{1, 4096});
    PortalStats capped_stats;
    ASSERT_TRUE(capped.traverse(eye, planes, capped_stats));
    EXPECT_EQ(capped_stats.capped, 1u);
    EXPECT_EQ(capped_stats.cells_reached, 3u);
    EXPECT_TRUE(capped.box_visible({Vec3{11.5f, 1, 0.5f}, Vec3{11.5f, 1, 0.5f}}));
    EXPECT_FALSE(capped.box_visible({{0.2f, 0.5f, 2.5f}, {0.4f, 0.7f, 3.5f}}));
}

TEST(PortalCulling, MisalignedDoorsAndClosedWallsHideTheRoomsBehind) {
    {
        // The cone through the first door (z 0.4..1.2) spans z -0.1..1.7 at the second wall, whose
        // door is at z 4.8..5.6: the last room is not reached.
        const Building b = row_of_three(true, {0.4f, 1.2f, 0, 2}, true, {4.8f, 5.6f, 0, 2});
        PortalCuller culler(b.cells, b.portals);
        const Vec3 eye{1, 1, 0.8f};
        const FrustumPlanes planes = camera_planes(eye, {1, 0, 0.5f}, 1.2f, 1.0f, 0.05f, 50, ClipDepth::zero_to_one);
        PortalStats stats;
        ASSERT_TRUE(culler.traverse(eye, planes, stats));
        EXPECT_TRUE(culler.cell_reached(0));
        EXPECT_TRUE(culler.cell_reached(1));
        EXPECT_FALSE(culler.cell_reached(2));
        EXPECT_EQ(stats.portals_passed, 1u);
        const Vec3 last_room{10, 1, 5};
        ASSERT_TRUE(in_frustum(planes, dv(last_room)));
        ASSERT_FALSE(visible(b, planes, eye, last_room));
        EXPECT_FALSE(culler.box_visible({last_room - Vec3{0.5f, 0.5f, 0.5f}, last_room + Vec3{0.5f, 0.5f, 0.5f}}));
        // The middle room is seen through the first door.
        const Vec3 middle{5, 1, 1.2f};
        ASSERT_TRUE(visible(b, planes, eye, middle));
        EXPECT_TRUE(culler.box_visible({middle, middle}));
    }
    {
        // A closed wall between rooms 0 and 1 (room 1 opens to room 2): from room 0, looking at the
        // wall, neither room behind it is reached.
        const Building b = row_of_three(false, {}, true, {2.5f, 3.5f, 0, 2});
        PortalCuller culler(b.cells, b.portals);
        const Vec3 eye{1, 1, 3};
        const FrustumPlanes planes = looking_along_x(eye, 1.5f);
        PortalStats stats;
        ASSERT_TRUE(culler.traverse(eye, planes, stats));
        EXPECT_EQ(stats.portals_tested, 0u);
        EXPECT_TRUE(culler.cell_reached(0));
        EXPECT_FALSE(culler.cell_reached(1));
        EXPECT_FALSE(culler.cell_reached(2));
        EXPECT_FALSE(culler.box_visible({{5, 0.5f, 2}, {6, 1.5f, 4}}));
        EXPECT_FALSE(culler.box_visible({{9, 0.5f, 2}, {10, 1.5f, 4}}));
        EXPECT_TRUE(culler.box_visible({{3, 0.5f, 2}, {3.5f, 1.5f, 4}}));  // in front of the wall
    }
    {
        // An eye exactly in the first door's plane starts in both rooms.
        const Building b = row_of_three(true, {2.5f, 3.5f, 0, 2}, true, {2.5f, 3.5f, 0, 2});
        PortalCuller culler(b.cells, b.portals);
        const Vec3 eye{4, 1, 3};
        PortalStats stats;
        ASSERT_TRUE(culler.traverse(eye, looking_along_x(eye, 1.0f), stats));
        EXPECT_EQ(stats.start_cells, 2u);
        EXPECT_TRUE(culler.cell_reached(2));
        EXPECT_TRUE(culler.box_visible({Vec3{11, 1, 3}, Vec3{11, 1, 3}}));
    }
}

TEST(PortalCulling, PointsExactlyOnAConeThroughAPortalEdgeAreKept) {
    // Two cells meeting at x = 4, joined by a diamond window (edges not axis-aligned, so the planes
    // through the eye and its edges are rounded). Each p = 2 m - eye with m exactly on an edge (all
    // values dyadic: exact in float): the segment eye -> p crosses the window's boundary at m, so p
    // is visible and lies exactly on the narrowed frustum's boundary: only the margin keeps it.
    // Also 1e4 from the origin (a multiple of 1/64 there is still exact: 2^13 + k / 64 has 20 bits).
    std::mt19937 rng(99);
    int kept = 0, trials = 0;
    for (int k = 0; k < 600; ++k) {
        const Vec3 o = k % 2 ? Vec3{8192, -4096, -12288} : Vec3{0, 0, 0};
        auto dyadic = [&](int lo, int hi) { return float(lo + int(rng() % std::uint32_t(hi - lo + 1))) / 64.0f; };
        const std::vector<Bounds> cells = {{o + Vec3{0, 0, 0}, o + Vec3{4, 4, 4}},
                                           {o + Vec3{4, 0, 0}, o + Vec3{8, 4, 4}}};
        const float x = o.x + 4, yc = o.y + dyadic(96, 160), zc = o.z + dyadic(96, 160);
        const float dy = dyadic(16, 60), dz = dyadic(16, 60);
        CellPortal window;
        window.cell_a = rng() % 2, window.cell_b = 1 - window.cell_a;
        window.corners[0] = {x, yc - dy, zc}, window.corners[1] = {x, yc, zc + dz},
        window.corners[2] = {x, yc + dy, zc}, window.corners[3] = {x, yc, zc - dz};
        PortalCuller culler(cells, {window});
        const Vec3 eye = o + Vec3{dyadic(64, 224), dyadic(32, 224), dyadic(32, 224)};
        const FrustumPlanes planes =
            camera_planes(eye, Vec3{x, yc, zc} - eye, 2.0f, 1.0f, 0.01f, 50, ClipDepth::zero_to_one);
        PortalStats stats;
        ASSERT_TRUE(culler.traverse(eye, planes, stats));
        for (int e = 0; e < 4; ++e) {
            const Vec3 a = window.corners[e], b = window.corners[(e + 1) % 4];
            const float t = float(rng() % 9) / 8.0f;
            const Vec3 m = a + (b - a) * t;
            const Vec3 p = m * 2.0f - eye;
            if (!in_box(cells[1], p) || !in_frustum(planes, dv(p))) continue;
            ++trials;
            kept += culler.box_visible({p, p});
        }
    }
    EXPECT_GT(trials, 1000);
    EXPECT_EQ(kept, trials);
}

TEST(PortalCulling, EyeOutsideEveryCellCullsNothing) {
    const Building b = row_of_three(true, {2.5f, 3.5f, 0, 2}, true, {2.5f, 3.5f, 0, 2});
    PortalCuller culler(b.cells, b.portals);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-20, 20);
    auto everything_visible = [&] {
        for (std::size_t c = 0; c < 3; ++c) EXPECT_TRUE(culler.cell_reached(c));
        for (int k = 0; k < 200; ++k) {
            const Vec3 c{u(rng), u(rng), u(rng)};
            EXPECT_TRUE(culler.box_visible({c, c + Vec3{0.1f, 0.1f, 0.1f}}));
        }
    };
    everything_visible();  // before the first traverse
    PortalStats stats;
    const Vec3 outside{-5, 1, 3};
    const FrustumPlanes planes = looking_along_x(outside, 1.0f);
    EXPECT_FALSE(culler.traverse(outside, planes, stats));
    EXPECT_EQ(stats.start_cells, 0u);
    everything_visible();
    // A non-finite eye or frustum row: the same.
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_FALSE(culler.traverse({nan, 1, 3}, planes, stats));
    everything_visible();
    FrustumPlanes broken = looking_along_x({1, 1, 3}, 1.0f);
    broken.rows[2].w = nan;
    EXPECT_FALSE(culler.traverse({1, 1, 3}, broken, stats));
    everything_visible();
    // Back inside, culling resumes (the test above can fail).
    EXPECT_TRUE(culler.traverse({1, 1, 3}, looking_along_x({1, 1, 3}, 1.0f), stats));
    EXPECT_FALSE(culler.box_visible({{0.2f, 0.5f, 2.5f}, {0.4f, 0.7f, 3.5f}}));
}

TEST(PortalCulling, BadInputThrowsOneLineErrors) {
    const std::vector<Bounds> cells = {{{0, 0, 0}, {1, 1, 1}}, {{1, 0, 0}, {2, 1, 1}}};
    CellPortal good;
    good.cell_a = 0, good.cell_b = 1;
    good.corners[0] = {1, 0.2f, 0.2f}, good.corners[1] = {1, 0.2f, 0.8f}, good.corners[2] = {1, 0.8f, 0.8f},
    good.corners[3] = {1, 0.8f, 0.2f};
    EXPECT_NO_THROW(PortalCuller(cells, {good}));
    EXPECT_NO_THROW(PortalCuller({}, {}));
    auto expect_error = [&](std::vector<Bounds> c, CellPortal p, const std::string& needle) {
        try {
            PortalCuller culler(std::move(c), {good, p});
            ADD_FAILURE() << "no error for " << needle;
        } catch (const Error& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find(needle), std::string::npos) << what;
            EXPECT_TRUE(is_printable_line(what)) << what;
        }
    };
    CellPortal p = good;
    p.cell_b = 2;
    expect_error(cells, p, "portal 1: cell index 2 out of range");
    p = good;
    p.cell_a = 1;
    expect_error(cells, p, "portal 1 joins cell 1 to itself");
    p = good;
    p.corners[2].y = std::numeric_limits<float>::quiet_NaN();
    expect_error(cells, p, "portal 1: corner 2 is not finite");
    p = good;
    p.corners[1].z = std::numeric_limits<float>::infinity();
    expect_error(cells, p, "portal 1: corner 1 is not finite");
    p = good;
    for (Vec3& c : p.corners) c = {1, 0.5f, 0.5f};
    expect_error(cells, p, "portal 1 has no area");
    p = good;  // an arrowhead: the turn at corner 1 goes the other way
    p.corners[0] = {1, 0.2f, 0.2f}, p.corners[1] = {1, 0.5f, 0.35f}, p.corners[2] = {1, 0.8f, 0.2f},
    p.corners[3] = {1, 0.5f, 0.8f};
    expect_error(cells, p, "portal 1 is not convex");
    std::vector<Bounds> bad_cells = cells;
    bad_cells[1].max.y = std::numeric_limits<float>::quiet_NaN();
    expect_error(bad_cells, good, "cell 1: box has a non-finite coordinate");
    bad_cells = cells;
    bad_cells[0].min.x = 3;
    expect_error(bad_cells, good, "cell 0: box is empty");
}

}  // namespace
}  // namespace patchcull
