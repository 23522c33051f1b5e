// patchcull/objects/backface_clusters.h: clustered back-face culling (Johannsen & Carter, "Clustered
// Backface Culling", 1998) and its hierarchy, as G. Zachmann's lecture "Advanced Visibility
// Computations" presents them, for clusters of triangles and, beyond the lecture, for
// clusters of bicubic patches bounded by their object-space tangent control planes (Loop,
// Niessner & Eisenacher, "Effective Back-Patch Culling for Hardware Tessellation").
//
// A cluster is a set of planes (n_i, p_i): triangles (face normal n = (p1 - p0) x (p2 - p0),
// a vertex p, backface.h's conventions) or patch control planes (n_k, w_k) with w_k = -n_k . p.
// A member is back-facing for the eye e when n_i . (e - p_i) <= 0 (for a patch: every control
// plane has the eye on its back side, so every tangent plane does, see patch_control_planes).
// In local test coordinates c (the lecture's remedy for clusters far from the origin), with
// x = e - c:
//   n_i . (e - p_i) = n_i . x - n_i . (p_i - c) <= f(x) - d,
//   f(x) = sum over axes a of max(n_a x_a, m_a x_a)  (the lecture's if(e - c; n, m) . (e - c)),
//   n = componentwise min of the n_i, m = componentwise max, d = min_i n_i . (p_i - c).
// So f(x) <= d means every member is back-facing. The culling volume {e : f(e - c) <= d} is
// bounded by 8 planes, one per octant around c: in the octant with signs s, the plane
// sum_a (s_a > 0 ? m_a : n_a) x_a = d; the 4 planes of the octants with x_a > 0 meet the a axis at
// c + (d / m_a) e_a (the lecture's point (d / m_x, 0, 0)). The front-face test of the hierarchy
// is the mirror image: g(x) = sum_a min(n_a x_a, m_a x_a) > D = max_i n_i . (p_i - c) means every
// member faces the eye (n_i . (e - p_i) >= g(x) - D > 0).
//
// Rounding. Clusters are built in double precision and stored in float rounded outward: n down,
// m up, d down, D up, after widening by a bound on the double computation's own error (normals
// by 1e-15 of their terms, plane values by 1e-14 of theirs; for patches the bound of
// patch_control_planes), so the stored cluster bounds the exact members. The float tests then
// decide with a margin of 8u (sum_a max(|n_a|, |m_a|) |x_a| + |d|) + 16 denorm_min, u = 2^-24,
// which exceeds the rounding of x = e - c and of the sums (<= ~5.1u of the same terms): a cluster
// is reported back-facing (front-facing) only when it is so in exact arithmetic. A non-finite
// member makes the cluster never back- or front-facing (d = -inf, D = +inf).
//
// Hierarchy (the lecture's "Hierarchical Clustered Backface Culling"): merging clusters a, b
// takes n^ = min, m^ = max, d^ = min, D^ = max after moving both into the merged cluster's c'
// (d_a' = d_a - f_a(c' - c_a), D_a' = D_a + f_a(c_a - c'); f is subadditive, so this is exact
// when c' = c_a and conservative otherwise). Then the merged culling volume lies inside both
// children's: merged back-facing => both children back-facing by their own tests, merged
// front-facing => both front-facing (exact arithmetic; the float margins of different nodes
// differ, so a parent within rounding of its boundary may decide where a child test would not,
// never wrongly). c' is chosen like a leaf's c: the centre or a corner of the union's bounding
// box, whichever gives the largest d^.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "patchcull/core/ground_truth.h"
#include "patchcull/core/math.h"
#include "patchcull/core/mesh.h"
#include "patchcull/core/patch.h"

namespace patchcull {

/// One cluster: the bounds n_min <= n_i <= m_max, d (back test) and d_front (front test) in local
/// coordinates c, the members' bounding box (box: candidates for c), and the member range
/// [first, first + count) (triangles in ClusterHierarchy::indices order, or patches in input order).
struct BackfaceCluster {
    Vec3 n_min, m_max;
    float d = 0;
    Vec3 c;
    std::uint32_t first = 0, count = 0;
    float d_front = 0;  ///< D = max_i n_i . (p_i - c), rounded up
    Bounds box;         ///< bounding box of the members' points (vertices / control points)
};

/// The cluster of triangles [first_triangle, first_triangle + count) of an indexed mesh, c chosen
/// among the centre and the 8 corners of the triangles' bounding box as the one with the largest d
/// (the lecture's practice). Triangles with two equal vertices (zero area, never drawn) are
/// skipped as planes but counted as members. first/count are set to the arguments.
/// Contracts: indices covers the range; count >= 1. Never throws.
BackfaceCluster make_triangle_cluster(const Vec3* vertices, const std::uint32_t* indices, std::uint32_t first_triangle,
                                      std::uint32_t count);

/// d of the triangle range for local coordinates c (as make_triangle_cluster computes it, before
/// rounding to float): for tests of the choice of c.
double triangle_cluster_d(const Vec3* vertices, const std::uint32_t* indices, std::uint32_t first_triangle,
                          std::uint32_t count, Vec3 c);

/// True only when every member is back-facing for eye: f(eye - c) <= d by the float test above.
/// Never throws.
bool cluster_backfacing(const BackfaceCluster& cluster, Vec3 eye);
/// True only when every member faces eye (n_i . (eye - p_i) > 0): g(eye - c) > D. Never throws.
bool cluster_frontfacing(const BackfaceCluster& cluster, Vec3 eye);

/// The merged cluster of a and b (see "Hierarchy" above): its back test implies both children's.
/// first = min(a.first, b.first), count = a.count + b.count (callers merge adjacent ranges).
BackfaceCluster merge_clusters(const BackfaceCluster& a, const BackfaceCluster& b);

/// The lecture's culling probability P = Vol(C ∩ U) / Vol(U): the fraction of viewpoints in the
/// box U for which the cluster's test culls (in exact arithmetic on the stored cluster), C the
/// culling volume. Computed exactly per octant around c as the volume of a box cut by a
/// half-space (inclusion-exclusion), in double; coefficients below 1e-5 of an octant's largest
/// are taken as 0 (absolute error <= ~3e-5). 0 when Vol(U) is 0 or the cluster is never culled.
double culling_probability(const BackfaceCluster& cluster, const Bounds& viewpoints);

/// The merge criterion from the lecture's cost model T(X) = tC + (1 - P(X)) n_X r (tC: one
/// cluster test, r: drawing one member): merging A and B into C pays when T(C) < T(A) + T(B), i.e.
///   P(C) > (P(A) n_A + P(B) n_B - tC / r) / (n_A + n_B).
/// Note the sign of tC / r: the merged cluster saves one test. The extracted lecture text shows
/// "+ tC/r", which contradicts its own previous line; this is the derivation redone (and
/// tests/core/backface_clusters_test.cpp checks it against T(C) < T(A) + T(B) directly).
/// False when n_a + n_b == 0.
bool merge_pays(double p_merged, double p_a, std::size_t n_a, double p_b, std::size_t n_b, double tc_over_r);

/// A cluster hierarchy over one mesh (triangles) or one patch list.
/// - nodes are in depth-first preorder; node i's subtree is [i, skip[i]); an internal node's
///   first child is i + 1, its second child skip[i + 1]. Roots follow each other in range order.
/// - leaves: node index of each leaf, in range order; leaf l covers members
///   [nodes[leaves[l]].first, + count), contiguous and in order, together all members once.
///   Node i covers leaves [leaf_begin[i], leaf_end[i]); it is a leaf when that span has one.
/// - indices (triangles only): the input triangles reordered so that each leaf is a contiguous
///   range of triangles of this list (draw ranges); triangle_order[t] is the input triangle of
///   triangle t of the list. Both empty for patches (their order is kept).
struct ClusterHierarchy {
    std::vector<std::uint32_t> indices;
    std::vector<std::uint32_t> triangle_order;
    std::vector<BackfaceCluster> nodes;
    std::vector<std::uint32_t> skip;
    std::vector<std::uint32_t> leaf_begin, leaf_end;
    std::vector<std::uint32_t> leaves;
    std::vector<std::uint32_t> roots;
};

/// Number of leaves. Never throws.
inline std::size_t cluster_leaf_count(const ClusterHierarchy& h) { return h.leaves.size(); }
/// Leaf l's cluster. Contracts: l < cluster_leaf_count(h).
inline const BackfaceCluster& cluster_leaf(const ClusterHierarchy& h, std::size_t l) { return h.nodes[h.leaves[l]]; }

/// Build parameters. viewpoints: the box U of culling_probability used by the merge criterion;
/// empty (min > max, the default) means the members' bounding box grown by its largest side on
/// every side (the lecture's "near field" around the object).
/// tC / r is the cost of one cluster test over the cost of drawing one member. A triangle costs
/// about one cluster test (1 - 16 here); a patch costs its per-patch cull tests and tessellation,
/// hundreds of cluster tests (0.01 - 0.1): with tC / r >= 1 BigGuy's patches merge into clusters
/// that cull little (bench/backface_bench.cpp, backface/hierarchy/bigguy_acc_*).
struct ClusterBuildOptions {
    double tc_over_r = 4.0;                 ///< tC / r of merge_pays
    std::uint32_t max_leaf = 64;            ///< members per leaf at most (>= 1)
    double max_leaf_normal_angle = 0.5236;  ///< radians (30 deg): a leaf's normals stay within it of its seed's
    Bounds viewpoints{{1, 1, 1}, {0, 0, 0}};
};

/// Triangle clusters: leaves grown greedily from seeds taken in Morton order of the triangles'
/// centroids, each absorbing the edge- or vertex-adjacent unassigned triangle whose unit normal is
/// closest to the seed's while within max_leaf_normal_angle of it, up to max_leaf triangles
/// (normal and spatial coherence); leaves ordered by their normal's cube face then Morton order;
/// then adjacent nodes merged bottom-up, always the pair with the largest gain
/// T(A) + T(B) - T(C), while merge_pays holds. Zero-area triangles join any leaf. Precisely: the
/// grown regions are the units of merge_into_leaves (adjacent regions merged into leaves of at
/// most max_leaf triangles while merge_pays holds), each leaf recomputed from its triangles, then
/// build_cluster_hierarchy.
/// Contracts: indices.size() % 3 == 0 and every index < vertices.size(), else throws
/// patchcull::Error; max_leaf >= 1 else throws. Empty input gives an empty hierarchy.
ClusterHierarchy build_triangle_clusters(const std::vector<Vec3>& vertices, const std::vector<std::uint32_t>& indices,
                                         const ClusterBuildOptions& options);
/// The same with default options except tc_over_r and max_leaf.
ClusterHierarchy build_triangle_clusters(const std::vector<Vec3>& vertices, const std::vector<std::uint32_t>& indices,
                                         double tc_over_r, std::uint32_t max_leaf_triangles);

/// Hierarchical test (the lecture's): from each root, a node found back-facing marks all its
/// leaves culled and a node found front-facing marks them kept, without testing below; otherwise
/// a leaf is kept and an internal node's children are tested. leaf_culled[l] = 1 means every
/// member of leaf l is back-facing for eye. Adds the number of nodes tested to cluster_tests.
/// The result equals testing every leaf alone (cluster_backfacing) except for a parent within
/// float rounding of its culling volume's boundary (see "Hierarchy" above).
/// Contracts: leaf_culled holds cluster_leaf_count(h) bytes. Never allocates or throws.
void cull_cluster_hierarchy(const ClusterHierarchy& h, Vec3 eye, std::uint8_t* leaf_culled,
                            std::uint32_t& cluster_tests);

// ---- building blocks (shared by the triangle and patch builders; usable for other members) ----

/// One member plane in double precision with its error bounds: the member's value
/// n . (p - c) = a - n . (c - o) for local coordinates c (a triangle: a = 0, o = a vertex; a
/// patch control plane t: n = t.xyz, a = -t.w, o = the planes' origin), the exact plane within
/// en of n (each component) and ea of a.
struct ClusterPlane {
    double n[3] = {0, 0, 0};
    double a = 0;
    Vec3 o;
    double en = 0, ea = 0;
};

/// The cluster of the given planes for members [first, first + count) whose points lie in box:
/// n, m, d, D rounded outward as described at the top, c the best of box's centre and corners.
/// No planes: d = FLT_MAX (always back-facing: only members that face nothing), D = FLT_MAX.
/// valid = false (a non-finite member): never back- or front-facing. Never throws.
BackfaceCluster make_cluster_from_planes(const ClusterPlane* planes, std::size_t n, const Bounds& box,
                                         std::uint32_t first, std::uint32_t count, bool valid);

/// The default viewpoint box U for members inside box: box grown by its largest side (1 if that
/// is 0) on every side. Never throws.
Bounds near_field_viewpoints(const Bounds& box);

/// The lecture's cluster generation: adjacent units (in range order) merged greedily, always the
/// pair with the largest gain T(A) + T(B) - T(C), while merge_pays holds and the merged cluster has
/// at most options.max_leaf members; returns the merged clusters in range order (first/count
/// exact; bounds relaxed as merge_clusters makes them: recompute each from its members for
/// leaves). Never throws except bad_alloc.
std::vector<BackfaceCluster> merge_into_leaves(const std::vector<BackfaceCluster>& units,
                                               const ClusterBuildOptions& options, const Bounds& default_viewpoints);

/// The hierarchy over leaves given in range order (their first/count adjacent and increasing):
/// adjacent nodes merged bottom-up by the largest gain while merge_pays holds (tC / r and the
/// viewpoint box U from options; an empty options.viewpoints means default_viewpoints). indices
/// and triangle_order are left empty. Never throws except bad_alloc.
ClusterHierarchy build_cluster_hierarchy(const std::vector<BackfaceCluster>& leaves, const ClusterBuildOptions& options,
                                         const Bounds& default_viewpoints);

// ---- clusters of patches (beyond the lecture) ------------------------------------------------

/// The 64 Bezier control planes t_k (k = 8 jv + iu, bidegree 7) of the parametric tangent plane
/// T(u, v) = cross4(B, B_u, B_v) = sum B7_iu(u) B7_jv(v) t_k of the patch, in object space
/// translated by -origin: the plane value of a point x is t.x * (x - origin).x + ... + t.w (for
/// origin = 0 the object-space planes; ground_truth.h's sample_tangent_planes are their Bernstein
/// combinations). Since the Bernstein weights are >= 0, e . T(u, v) <= max_k e . t_k: every
/// tangent plane has the eye on its back side when every control plane does. Computed in double
/// from Loop, Niessner & Eisenacher's table (src/core/ptp_table.inc); terms with two equal control points (a
/// collapsed edge) are exact zeros and skipped, so such planes come out exactly 0 with bound 0.
/// error[k] (if not null) bounds |computed - exact| of plane k, component by component.
/// Never throws.
void patch_control_planes(const BezierPatch& patch, Vec3 origin, PlaneD planes[64], PlaneD* error);

/// The cluster of patches [first, first + count) (their control planes; planes that are exactly
/// zero are skipped: they face nothing), c chosen as for triangles among the control points'
/// bounding box centre and corners. Contracts: count >= 1. Never throws.
BackfaceCluster make_patch_cluster(const BezierPatch* patches, std::uint32_t first, std::uint32_t count);

/// Patch clusters of one object, built once at rest in the object's space: every patch a unit,
/// adjacent units (input order) merged into leaves by merge_into_leaves (merge_pays, at most
/// max_leaf patches; max_leaf_normal_angle is not used), each leaf recomputed from its patches'
/// control planes; then the hierarchy as for triangles (build_cluster_hierarchy). For an object moving rigidly, test
/// each frame with the eye moved into object space (inverse of the rigid transform). indices and triangle_order stay
/// empty. Contracts: max_leaf >= 1, else throws patchcull::Error.
ClusterHierarchy build_patch_clusters(const BezierPatch* patches, std::size_t n, const ClusterBuildOptions& options);
/// The same with default options except tc_over_r and max_leaf.
ClusterHierarchy build_patch_clusters(const BezierPatch* patches, std::size_t n, double tc_over_r,
                                      std::uint32_t max_leaf_patches);

}  // namespace patchcull
