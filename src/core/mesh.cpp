// Control-mesh helpers (patchcull/core/mesh.h).
#include "patchcull/core/mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace patchcull {

bool ControlMesh::all_quads() const {
    for (std::size_t f = 0; f < face_count(); ++f)
        if (face_size(f) != 4) return false;
    return true;  // vacuously true for a mesh without faces
}

bool ControlMesh::is_closed() const {
    if (face_count() == 0) return false;
    // Directed edges (from, to): closed and consistently oriented iff each occurs exactly once
    // and its reverse occurs too.
    std::vector<std::uint64_t> directed;
    directed.reserve(face_vertices.size());
    for (std::size_t f = 0; f < face_count(); ++f) {
        const std::uint32_t first = face_offsets[f], n = face_size(f);
        for (std::uint32_t i = 0; i < n; ++i) {
            const std::uint64_t from = face_vertices[first + i], to = face_vertices[first + (i + 1) % n];
            directed.push_back(from << 32 | to);
        }
    }
    std::sort(directed.begin(), directed.end());
    if (std::adjacent_find(directed.begin(), directed.end()) != directed.end()) return false;
    for (const std::uint64_t e : directed) {
        const std::uint64_t reverse = (e & 0xFFFFFFFFu) << 32 | e >> 32;
        if (!std::binary_search(directed.begin(), directed.end(), reverse)) return false;
    }
    return true;
}

double ControlMesh::signed_volume() const {
    if (positions.empty()) return 0;
    // Sum over fan triangles (a, b, c) of det[a-o, b-o, c-o] / 6, o = positions[0]: translation
    // invariant for a closed mesh, and relative coordinates keep far-away meshes exact enough.
    const Vec3 o = positions[0];
    auto rel = [&](std::uint32_t v) {
        const Vec3 p = positions[v];
        return std::array<double, 3>{double(p.x) - o.x, double(p.y) - o.y, double(p.z) - o.z};
    };
    double six_volume = 0;
    for (std::size_t f = 0; f < face_count(); ++f) {
        const std::uint32_t first = face_offsets[f], n = face_size(f);
        const auto a = rel(face_vertices[first]);
        for (std::uint32_t i = 1; i + 1 < n; ++i) {
            const auto b = rel(face_vertices[first + i]), c = rel(face_vertices[first + i + 1]);
            six_volume += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                          a[2] * (b[0] * c[1] - b[1] * c[0]);
        }
    }
    return six_volume / 6.0;
}

void ControlMesh::reverse_faces() {
    for (std::size_t f = 0; f < face_count(); ++f) {
        const auto begin = static_cast<std::ptrdiff_t>(face_offsets[f]),
                   end = static_cast<std::ptrdiff_t>(face_offsets[f + 1]);
        std::reverse(face_vertices.begin() + begin, face_vertices.begin() + end);
        if (has_texcoords()) std::reverse(face_texcoords.begin() + begin, face_texcoords.begin() + end);
    }
}

namespace {

// One connected component of a closed mesh over shared edges, with what orientation needs.
struct Shell {
    std::vector<std::uint32_t> faces;
    std::vector<std::uint32_t> samples;  // up to kShellSamples of its vertices, spread over it
    double volume = 0;                   // signed, relative to its own first vertex
    double area = 0;
    std::array<double, 3> lo{}, hi{};  // bounds of its vertices
    std::size_t triangles = 0;         // fan triangles
    bool flat = false;
};

constexpr std::size_t kShellSamples = 64;
// Work the nesting test may spend, in fan triangles a ray passes (a solid angle counts as
// kWindingCost of them), before the mesh is called undecided: about a second.
constexpr double kNestingWorkLimit = 2e8;
// A solid angle costs about as much as this many triangles a ray passes by.
constexpr double kWindingCost = 10;

std::size_t find_root(std::vector<std::uint32_t>& parent, std::uint32_t f) {
    while (parent[f] != f) f = parent[f] = parent[parent[f]];
    return f;
}

// The shells of a closed mesh (is_closed: every directed edge's reverse is there), faces in
// order, shells in the order of their first face.
std::vector<Shell> find_shells(const ControlMesh& mesh) {
    const std::size_t faces = mesh.face_count();
    // Each vertex's outgoing edges (to, face), counting-sorted by vertex: the face across the
    // edge (from, to) is the one whose edge (to, from) leaves to.
    std::vector<std::uint32_t> first_out(mesh.positions.size() + 1, 0);
    for (const std::uint32_t v : mesh.face_vertices) ++first_out[v + 1];
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) first_out[v + 1] += first_out[v];
    std::vector<std::pair<std::uint32_t, std::uint32_t>> out(mesh.face_vertices.size());
    {
        std::vector<std::uint32_t> fill(first_out.begin(), first_out.end() - 1);
        for (std::size_t f = 0; f < faces; ++f) {
            const std::uint32_t first = mesh.face_offsets[f], n = mesh.face_size(f);
            for (std::uint32_t i = 0; i < n; ++i)
                out[fill[mesh.face_vertices[first + i]]++] = {mesh.face_vertices[first + (i + 1) % n],
                                                              static_cast<std::uint32_t>(f)};
        }
    }
    std::vector<std::uint32_t> parent(faces);
    for (std::size_t f = 0; f < faces; ++f) parent[f] = static_cast<std::uint32_t>(f);
    for (std::size_t f = 0; f < faces; ++f) {
        const std::uint32_t first = mesh.face_offsets[f], n = mesh.face_size(f);
        for (std::uint32_t i = 0; i < n; ++i) {
            const std::uint32_t from = mesh.face_vertices[first + i], to = mesh.face_vertices[first + (i + 1) % n];
            for (std::uint32_t e = first_out[to]; e < first_out[to + 1]; ++e) {
                if (out[e].first != from) continue;
                const std::size_t a = find_root(parent, static_cast<std::uint32_t>(f)),
                                  b = find_root(parent, out[e].second);
                if (a != b) parent[std::max(a, b)] = static_cast<std::uint32_t>(std::min(a, b));
                break;
            }
        }
    }
    std::vector<Shell> shells;
    std::vector<std::uint32_t> shell_of_root(faces, UINT32_MAX);
    for (std::size_t f = 0; f < faces; ++f) {
        std::uint32_t& s = shell_of_root[find_root(parent, static_cast<std::uint32_t>(f))];
        if (s == UINT32_MAX) {
            s = static_cast<std::uint32_t>(shells.size());
            shells.emplace_back();
        }
        shells[s].faces.push_back(static_cast<std::uint32_t>(f));
    }
    // Volume, area, bounds and sample vertices, in double relative to each shell's first vertex.
    // (Shells may share a vertex without sharing an edge: seen is per shell.)
    std::vector<std::uint32_t> seen(mesh.positions.size(), UINT32_MAX);
    for (std::size_t s = 0; s < shells.size(); ++s) {
        Shell& shell = shells[s];
        const Vec3 o = mesh.positions[mesh.face_vertices[mesh.face_offsets[shell.faces[0]]]];
        auto rel = [&](std::uint32_t v) {
            const Vec3 p = mesh.positions[v];
            return std::array<double, 3>{double(p.x) - o.x, double(p.y) - o.y, double(p.z) - o.z};
        };
        std::vector<std::uint32_t> vertices;
        double six_volume = 0;
        for (const std::uint32_t f : shell.faces) {
            const std::uint32_t first = mesh.face_offsets[f], n = mesh.face_size(f);
            for (std::uint32_t i = 0; i < n; ++i) {
                const std::uint32_t v = mesh.face_vertices[first + i];
                if (seen[v] != s) seen[v] = static_cast<std::uint32_t>(s), vertices.push_back(v);
            }
            const auto a = rel(mesh.face_vertices[first]);
            for (std::uint32_t i = 1; i + 1 < n; ++i) {
                const auto b = rel(mesh.face_vertices[first + i]), c = rel(mesh.face_vertices[first + i + 1]);
                six_volume += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                              a[2] * (b[0] * c[1] - b[1] * c[0]);
                const std::array<double, 3> u{b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                    w{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
                const double cx = u[1] * w[2] - u[2] * w[1], cy = u[2] * w[0] - u[0] * w[2],
                             cz = u[0] * w[1] - u[1] * w[0];
                shell.area += 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
                ++shell.triangles;
            }
        }
        shell.volume = six_volume / 6.0;
        // Flat against the shell's own surface (|V| <= 1e-9 A^1.5; a sphere has V = 0.094 A^1.5),
        // not against its bounding box, so that a thin but real solid (a squashed character, a
        // plate of 1e-5 relative thickness) keeps its orientation while a zero-volume sheet (two
        // coincident layers, a flattened mesh, whose volume is rounding noise ~1e-16 A^1.5) does not.
        shell.flat = !(std::abs(shell.volume) > 1e-9 * shell.area * std::sqrt(shell.area));
        shell.lo = shell.hi = {double(o.x), double(o.y), double(o.z)};
        for (const std::uint32_t v : vertices) {
            const Vec3 p = mesh.positions[v];
            const double c[3] = {p.x, p.y, p.z};
            for (int k = 0; k < 3; ++k)
                shell.lo[k] = std::min(shell.lo[k], c[k]), shell.hi[k] = std::max(shell.hi[k], c[k]);
        }
        const std::size_t count = std::min(kShellSamples, vertices.size());
        for (std::size_t i = 0; i < count; ++i) shell.samples.push_back(vertices[i * vertices.size() / count]);
    }
    return shells;
}

// Winding number of the closed shell around p (the sum of its fan triangles' signed solid
// angles over 4 pi, Van Oosterom & Strackee's formula, in double): +-1 inside, 0 outside, a
// non-integer only on or next to the surface. NaN when p is one of its vertices.
double winding_number(const ControlMesh& mesh, const Shell& shell, const std::array<double, 3>& p) {
    auto rel = [&](std::uint32_t v) {
        const Vec3 q = mesh.positions[v];
        return std::array<double, 3>{double(q.x) - p[0], double(q.y) - p[1], double(q.z) - p[2]};
    };
    auto dot = [](const std::array<double, 3>& a, const std::array<double, 3>& b) {
        return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    };
    double total = 0;
    for (const std::uint32_t f : shell.faces) {
        const std::uint32_t first = mesh.face_offsets[f], n = mesh.face_size(f);
        const auto a = rel(mesh.face_vertices[first]);
        const double la = std::sqrt(dot(a, a));
        for (std::uint32_t i = 1; i + 1 < n; ++i) {
            const auto b = rel(mesh.face_vertices[first + i]), c = rel(mesh.face_vertices[first + i + 1]);
            const double lb = std::sqrt(dot(b, b)), lc = std::sqrt(dot(c, c));
            if (la == 0 || lb == 0 || lc == 0) return std::nan("");
            const double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                               a[2] * (b[0] * c[1] - b[1] * c[0]);
            const double denominator = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
            total += 2 * std::atan2(det, denominator);
        }
    }
    return total / (4 * 3.14159265358979323846);
}

// Parity of the crossings of the ray from p towards +z with the shell's fan triangles (1:
// inside, 0: outside), in double; -1 when the ray passes within rounding distance of a
// triangle's edge or vertex (or p is on the surface), where counting could err.
int ray_parity(const ControlMesh& mesh, const Shell& shell, const std::array<double, 3>& p) {
    int crossings = 0;
    for (const std::uint32_t f : shell.faces) {
        const std::uint32_t first = mesh.face_offsets[f], n = mesh.face_size(f);
        const Vec3 a = mesh.positions[mesh.face_vertices[first]];
        for (std::uint32_t i = 1; i + 1 < n; ++i) {
            const Vec3 b = mesh.positions[mesh.face_vertices[first + i]],
                       c = mesh.positions[mesh.face_vertices[first + i + 1]];
            if (std::max({a.x, b.x, c.x}) < p[0] || std::min({a.x, b.x, c.x}) > p[0] ||
                std::max({a.y, b.y, c.y}) < p[1] || std::min({a.y, b.y, c.y}) > p[1])
                continue;
            const double ax = a.x - p[0], ay = a.y - p[1], bx = b.x - p[0], by = b.y - p[1];
            const double cx = c.x - p[0], cy = c.y - p[1];
            // Twice the signed areas of (p, a, b), (p, b, c), (p, c, a) seen from +z: p's
            // barycentric weights of c, a, b.
            const double dab = ax * by - ay * bx, dbc = bx * cy - by * cx, dca = cx * ay - cy * ax;
            const double tolerance = 1e-12 * (ax * ax + ay * ay + bx * bx + by * by + cx * cx + cy * cy);
            const bool positive = dab > tolerance && dbc > tolerance && dca > tolerance;
            const bool negative = dab < -tolerance && dbc < -tolerance && dca < -tolerance;
            if (!positive && !negative) {
                const bool outside = std::max({dab, dbc, dca}) > tolerance && std::min({dab, dbc, dca}) < -tolerance;
                if (outside) continue;
                return -1;  // on an edge or vertex of the triangle's shadow
            }
            const double az = a.z - p[2], bz = b.z - p[2], cz = c.z - p[2];
            const double z = (dbc * az + dca * bz + dab * cz) / (dab + dbc + dca);
            if (!(std::abs(z) > 1e-9 * (std::abs(az) + std::abs(bz) + std::abs(cz)))) return -1;  // p on it
            if (z > 0) ++crossings;
        }
    }
    return crossings & 1;
}

// Whether shell inner lies inside shell outer. Of disjoint closed surfaces one point of inner
// decides, but shells may touch or intersect (a character's teeth or eyes sunk into its head):
// up to 64 of inner's vertices, spread over it, are tried, and inner is inside only when none
// is outside (vertices on outer's surface, at rounding distance, do not count), so a shell that
// pokes out counts as not nested. Strictly nested bounds are required first (a point inside a
// closed surface is strictly inside its bounds). Each vertex is decided by a ray's parity, or
// where the ray grazes an edge, by the winding number. work counts the cost (kNestingWorkLimit).
bool inside(const ControlMesh& mesh, const Shell& inner, const Shell& outer, double& work) {
    for (int k = 0; k < 3; ++k)
        if (!(outer.lo[k] < inner.lo[k] && inner.hi[k] < outer.hi[k])) return false;
    bool any_inside = false;
    for (const std::uint32_t v : inner.samples) {
        const Vec3 q = mesh.positions[v];
        const std::array<double, 3> p{q.x, q.y, q.z};
        work += double(outer.triangles);
        int parity = ray_parity(mesh, outer, p);
        if (parity < 0) {  // the ray grazes an edge or p is on the surface: the solid angles decide
            work += kWindingCost * double(outer.triangles);
            const double w = winding_number(mesh, outer, p);
            const double nearest = std::round(w);
            if (!(std::abs(w - nearest) < 0.25)) continue;  // on (or at rounding distance of) the surface
            parity = std::fmod(std::abs(nearest), 2.0) == 1.0 ? 1 : 0;
        }
        if (parity == 0) return false;
        any_inside = true;
    }
    return any_inside;
}

// Whether box (lo, hi) strictly contains box (inner_lo, inner_hi) on every axis.
bool strictly_contains(const std::array<double, 3>& lo, const std::array<double, 3>& hi,
                       const std::array<double, 3>& inner_lo, const std::array<double, 3>& inner_hi) {
    for (int k = 0; k < 3; ++k)
        if (!(lo[k] < inner_lo[k] && inner_hi[k] < hi[k])) return false;
    return true;
}

// A bounding-volume tree over the shells' bounds (median splits of the longest axis, leaves of
// up to 4 shells), to list the shells whose bounds strictly contain a given shell's.
class ShellBoxTree {
public:
    explicit ShellBoxTree(const std::vector<Shell>& shells) : shells_(shells), order_(shells.size()) {
        for (std::size_t i = 0; i < order_.size(); ++i) order_[i] = static_cast<std::uint32_t>(i);
        if (!order_.empty()) build(0, static_cast<std::uint32_t>(order_.size()));
    }

    // The shells (by index) whose bounds strictly contain inner's; work counts the boxes tested.
    void containing(const Shell& inner, std::vector<std::uint32_t>& out, double& work) const {
        out.clear();
        if (nodes_.empty()) return;
        std::vector<std::uint32_t> stack{0};
        while (!stack.empty()) {
            const Node& node = nodes_[stack.back()];
            stack.pop_back();
            work += 1;
            if (!strictly_contains(node.lo, node.hi, inner.lo, inner.hi)) continue;
            if (node.left == 0) {
                for (std::uint32_t i = node.begin; i < node.end; ++i) {
                    const Shell& s = shells_[order_[i]];
                    if (strictly_contains(s.lo, s.hi, inner.lo, inner.hi)) out.push_back(order_[i]);
                }
                work += node.end - node.begin;
            } else {
                stack.push_back(node.left);
                stack.push_back(node.right);
            }
        }
        std::sort(out.begin(), out.end());
    }

private:
    struct Node {
        std::array<double, 3> lo{}, hi{};
        std::uint32_t begin = 0, end = 0;   // shells order_[begin, end)
        std::uint32_t left = 0, right = 0;  // children; 0 for a leaf (the root is no child)
    };

    std::uint32_t build(std::uint32_t begin, std::uint32_t end) {
        Node node;
        node.begin = begin, node.end = end;
        node.lo = shells_[order_[begin]].lo, node.hi = shells_[order_[begin]].hi;
        for (std::uint32_t i = begin; i < end; ++i)
            for (int k = 0; k < 3; ++k) {
                node.lo[k] = std::min(node.lo[k], shells_[order_[i]].lo[k]);
                node.hi[k] = std::max(node.hi[k], shells_[order_[i]].hi[k]);
            }
        const auto index = static_cast<std::uint32_t>(nodes_.size());
        nodes_.push_back(node);
        if (end - begin > 4) {
            int axis = 0;
            for (int k = 1; k < 3; ++k)
                if (node.hi[k] - node.lo[k] > node.hi[axis] - node.lo[axis]) axis = k;
            const std::uint32_t middle = begin + (end - begin) / 2;
            std::nth_element(order_.begin() + begin, order_.begin() + middle, order_.begin() + end,
                             [&](std::uint32_t x, std::uint32_t y) {
                                 return shells_[x].lo[axis] + shells_[x].hi[axis] <
                                        shells_[y].lo[axis] + shells_[y].hi[axis];
                             });
            const std::uint32_t left = build(begin, middle), right = build(middle, end);
            nodes_[index].left = left, nodes_[index].right = right;
        }
        return index;
    }

    const std::vector<Shell>& shells_;
    std::vector<std::uint32_t> order_;
    std::vector<Node> nodes_;
};

// Orientation of a mesh, and which shells orient_outward reverses.
struct OrientationAnalysis {
    SurfaceOrientation orientation = SurfaceOrientation::open;
    std::vector<Shell> shells;
    std::vector<bool> reverse;  // per shell: oriented against its nesting parity
    std::size_t reversed = 0;
};

OrientationAnalysis analyse_orientation(const ControlMesh& mesh) {
    OrientationAnalysis r;
    if (!mesh.is_closed()) return r;
    r.shells = find_shells(mesh);
    // Flat shells first: a shell whose orientation is rounding noise makes the mesh two-sided.
    for (const Shell& s : r.shells)
        if (s.flat) {
            r.orientation = SurfaceOrientation::flat;
            return r;
        }
    // Nesting depth: the number of other shells around each. The solid is the region inside an
    // odd number of shells, so a shell at even depth bounds it from outside (faces out, positive
    // volume) and one at odd depth bounds a cavity (faces into it, negative volume).
    // Only shells whose bounds strictly contain a shell's bounds can hold it: a tree of the
    // shells' bounds finds those without comparing every pair (a voxel model of 1e5 cubes).
    const std::size_t n = r.shells.size();
    const ShellBoxTree tree(r.shells);
    double work = 0;
    r.reverse.assign(n, false);
    std::vector<std::uint32_t> around;
    for (std::size_t a = 0; a < n; ++a) {
        std::size_t depth = 0;
        tree.containing(r.shells[a], around, work);
        for (const std::uint32_t b : around) {
            if (b == a) continue;
            if (inside(mesh, r.shells[a], r.shells[b], work)) ++depth;
            if (work > kNestingWorkLimit) {
                r.orientation = SurfaceOrientation::undecided;
                r.reverse.assign(n, false);
                r.reversed = 0;
                return r;
            }
        }
        const bool wants_positive = depth % 2 == 0;
        r.reverse[a] = (r.shells[a].volume > 0) != wants_positive;
        r.reversed += r.reverse[a] ? 1 : 0;
    }
    r.orientation = r.reversed ? SurfaceOrientation::inward : SurfaceOrientation::outward;
    return r;
}

void reverse_face(ControlMesh& mesh, std::size_t f) {
    const auto begin = static_cast<std::ptrdiff_t>(mesh.face_offsets[f]),
               end = static_cast<std::ptrdiff_t>(mesh.face_offsets[f + 1]);
    std::reverse(mesh.face_vertices.begin() + begin, mesh.face_vertices.begin() + end);
    if (mesh.has_texcoords()) std::reverse(mesh.face_texcoords.begin() + begin, mesh.face_texcoords.begin() + end);
}

}  // namespace

SurfaceOrientation classify_orientation(const ControlMesh& mesh) { return analyse_orientation(mesh).orientation; }

SurfaceOrientation orient_outward(ControlMesh& mesh) {
    const OrientationAnalysis a = analyse_orientation(mesh);
    const std::size_t shells = a.shells.size();
    switch (a.orientation) {
        case SurfaceOrientation::inward:
            for (std::size_t s = 0; s < shells; ++s)
                if (a.reverse[s])
                    for (const std::uint32_t f : a.shells[s].faces) reverse_face(mesh, f);
            if (a.reversed == shells && shells == 1) {
                mesh.warnings.push_back(mesh.name +
                                        ": closed surface oriented inward (negative signed volume): "
                                        "faces reversed, so that its outside faces out");
            } else {
                mesh.warnings.push_back(mesh.name + ": " + std::to_string(a.reversed) + " of " +
                                        std::to_string(shells) +
                                        " closed shells oriented inward (facing into the solid; a shell inside an odd "
                                        "number of others bounds a cavity): their faces reversed, so that every shell "
                                        "faces out of the solid");
            }
            return SurfaceOrientation::outward;
        case SurfaceOrientation::flat:
            mesh.warnings.push_back(mesh.name + (shells > 1 ? ": a closed shell" : ": closed surface") +
                                    " encloses no volume: drawn two-sided, no back-patch culling");
            return a.orientation;
        case SurfaceOrientation::undecided:
            mesh.warnings.push_back(mesh.name + ": " + std::to_string(shells) +
                                    " closed shells whose bounds nest too often to decide their nesting: drawn "
                                    "two-sided, no back-patch culling");
            return a.orientation;
        case SurfaceOrientation::open:
        case SurfaceOrientation::outward:
            break;
    }
    return a.orientation;
}

Bounds compute_bounds(const std::vector<Vec3>& points) {
    // An empty point set has the empty-at-origin box {0, 0}: callers get a finite box (radius 0)
    // instead of +-infinity.
    if (points.empty()) return Bounds{};
    Bounds b{points[0], points[0]};
    for (const Vec3& p : points) {
        b.min = {std::min(b.min.x, p.x), std::min(b.min.y, p.y), std::min(b.min.z, p.z)};
        b.max = {std::max(b.max.x, p.x), std::max(b.max.y, p.y), std::max(b.max.z, p.z)};
    }
    return b;
}

}  // namespace patchcull
