// patchcull/core/displaced_bounds.h: bounds of displaced bicubic patches and their frustum and Hi-Z
// occlusion tests (Niessner & Loop §4.2; the OOBB of Munkberg et al. 2010 as the comparison), CPU side.
//
// The GLSL twin is to be written from this header: every step below is defined exactly.
// Conventions are those of math.h, frustum.h and hiz.h: column-major matrices, right-handed view
// space looking down -z, clip space of glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE) in any of
// clip_space.h's depth conventions, depths taken as depth keys (larger = farther; the window depth,
// negated for reversed conventions), Hi-Z storing the max key of its footprint.
//
// ---- What is bounded --------------------------------------------------------------------------
// The displaced surface S(u,v) = B(u,v) + D(u,v) n(u,v) (displacement.h), n = (B_u x B_v)/|B_u x B_v|
// the unit normal of the patch's own derivatives, D(u,v) anywhere in [d_min, d_max] with
// d_min <= 0 <= d_max (DisplacementRange; a range without 0 is widened to include it). At points
// where B_u x B_v = 0 (collapsed edges) S = B. NOT bounded: a normal taken from other data, e.g.
// the ACC tangent patches of an extraordinary patch (TangentPatches); those patches need `full`,
// whose bound holds for any unit direction.
// Since B(u,v) lies in the convex hull of the control points P_k (positive weights) and the
// displacement vector d = D n lies in a set E that does not depend on (u,v), S lies in
// hull(P_k) + E = hull(P_k + E): every bound below is a convex set holding the 16 sets P_k + E.
//
// ---- Cones and per-axis extensions (Niessner & Loop §4.2) ---------------------------------------
// Cone kinds (NormalConeKind) bound the direction of n:
//   full: no cone; E = ball of radius R = max(|d_min|, |d_max|);
//   acon: tangent_normal_cone() of cones.h (Sederberg & Meyers; Loop, Niessner & Eisenacher's TCONE);
//   con:  normal_patch_cone() of cones.h (the normal patch, Shirman & Abi-Ezzi; Loop, Niessner &
//         Eisenacher's NCONE).
// An invalid cone (aperture >= 90deg, rational patch, degenerate vectors) falls back to full.
// For a unit direction r and a cone (unit axis a, half-angle alpha), with c = r.a = cos(theta)
// and s = |r x a| = sin(theta), the extreme values of r.n over unit n in the cone are
//   delta+(r) = max r.n = 1                           if c >= cos(alpha)   (theta <= alpha)
//                       = c cos(alpha) + s sin(alpha) otherwise             (= cos(theta - alpha))
//   delta-(r) = max (-r).n = delta+(-r): the same with -c in place of c.
// This is the seed's max(cos(acos(a_x) + alpha), cos(acos(a_x) - alpha)) without acos: for
// theta in [0, pi] and alpha in [0, pi/2] the max is always the theta - alpha term. The range of
// r.d = D (r.n) over D in [d_min, d_max] and r.n in [-delta-, delta+] is the product of the two
// intervals, whose ends are (Niessner & Loop §4.2; both >= 0 because D = 0 is allowed)
//   ext+(r) = max(d_max delta+, -d_min delta-),   ext-(r) = max(d_max delta-, -d_min delta+):
//   r.d lies in [-ext-(r), ext+(r)]. For full: ext+ = ext- = R.
// Float: delta+- get + kDisplacedDeltaSlack (capped at 1) and ext+- the factor kDisplacedExtScale,
// covering the rounding of c, s and of the cone's axis (cones.h already widens alpha for its own
// rounding).
// For a direction r of any length (a row of a non-rigid view matrix) the extension is |r| times
// that of r/|r|.
//
// ---- caf: the camera-aligned frustum (Niessner & Loop §4.2) -------------------------------------
// In view space (t = -z, the distance along the viewing direction; the seed's camera looks down
// +z, ours down -z) with V = object_to_view = [L | T]:
// 1. Q_k = V P_k (Cartesian: divided by the weight w_k > 0).
// 2. Extensions along the view axes: the rows r_x, r_y, r_z of L, so that the view-space
//    displacement L d has x in [-ext-(r_x), ext+(r_x)], and likewise y and z (any linear L, also
//    scaled or sheared: the displacement is a vector, mapped by L). Box k is
//    [x_k - ext-(r_x), x_k + ext+(r_x)] x [same for y] x [z_k - ext-(r_z), z_k + ext+(r_z)], so
//    its view depths are t in [t_k - ext+(r_z), t_k + ext-(r_z)].
// 3. Front and back planes: t_front = min_k t_k - ext+(r_z) (the seed's minZ),
//    t_back = max_k t_k + ext-(r_z). Projectable iff t_front > 2^-20 * s_max, s_max bounding the
//    magnitude of the computed t's terms (max_k |L_z2 X|+|L_z1 Y|+|L_z0 Z|+|T_z|, plus ext+(r_z)):
//    this proves the exact t_front > 0 despite rounding (as hiz.h step 3).
// 4. Side planes: every point of box k has x/t between
//    X_lo,k = x_lo / (x_lo >= 0 ? t_hi : t_lo) and X_hi,k = x_hi / (x_hi >= 0 ? t_lo : t_hi)
//    (x/t is monotone in x and in t on a box with t > 0, so its extremes are at corners). These
//    are exactly the min and max of the seed's corner projections onto the front plane
//    (x' = x * t_front / t) divided by t_front. X_min = min_k X_lo,k, X_max = max_k X_hi,k; same for
//    y. The CAF {t >= t_front, X_min <= x/t <= X_max, Y_min <= y/t <= Y_max} is convex (its side
//    planes contain the eye) and holds every box corner, hence hull(P_k + E).
// 5. To the screen (projection restricted below): ndc_x = P00 * (x/t) - P02, ndc_y = P11 * (y/t) -
//    P12, depth z/w = (P23 - P22 t) / t; computed as fma(P00, X, -P02), fma(P11, Y, -P12) and
//    fma(-P22, t, P23) / t (clip z over w, correctly rounded, as hiz.h step 4), with the min/max
//    taken after the mapping (signs of P00, P11, P23 are not assumed).
// The CAF truncated at t_back is still a bound; t_back gives depth_far (near-plane culls).
//
// ---- oobb: Munkberg et al. 2010 (HPG), "Efficient bounding of displaced Bezier patches" ------------
// Our reading of their object-oriented bounding box with the same cones: an orthonormal frame
// (e_u, e_v, e_n) in object space from the patch alone, the same for every cone kind (so a cone
// only ever shrinks the box): e_n = the normal of the corner diagonals (P30 - P03) x (P33 - P00)
// (+z if that vanishes), e_u = the u direction P30 + P33 - P00 - P03 made orthogonal to e_n (any
// perpendicular if that vanishes), e_v = e_n x e_u. Relative to O = P00 the control points'
// coordinates c_ik = e_i . (P_k - O) give [min_k c_ik - ext-(e_i), max_k c_ik + ext+(e_i)] per axis
// (with e_n near the cone axis: about [d_min, d_max] along it and +-R sin(alpha + theta) across),
// padded by kDisplacedFramePad of the box's size for the
// non-orthonormality of the rounded frame. Its 8 corners O + sum_i c_i e_i are transformed by V;
// if all have t > 2^-20 * s_k they give the NDC rectangle and depths as in step 5 (a perspective map
// sends a convex polytope in t > 0 to the hull of its vertices' images).
//
// ---- Non-projectable bounds and the frustum test ---------------------------------------------------
// A bound that reaches t <= 0 (the eye plane) has no bounded screen rectangle: it is culled
// only by the homogeneous plane test: the six clip planes as rows q over view-space points
// (make_frustum_planes(projection)); culled when for some plane every box (caf: the 16 boxes,
// value max_k q.(Q_k,1) + sum_i max(q_i ext+_i, -q_i ext-_i)) or every corner (oobb) is < 0. Such
// a bound is never occluded.
// For a projected bound the frustum test is: culled iff ndc_xmax < -1 or ndc_xmin > 1 or
// ndc_ymax < -1 or ndc_ymin > 1 or depth_near > key_far or depth_far < key_near (strict: points on a clip plane
// are inside). This equals the plane test of the same boxes/corners (the side planes of both the
// view frustum and the CAF contain the eye).
//
// ---- Occlusion test (hiz.h steps 5-9 on the bound's rectangle) ----------------------------------------
// Frustum test first (kHiZFrustumCulled). Then, for a projected bound only: window box
// xlo = fma(ndc_xmin, W/2, W/2), xhi = fma(ndc_xmax, W/2, W/2), ylo/yhi with H/2;
// rect = hiz_rect_from_window_box(...); h = hiz_rect_max(hiz, rect) (level chosen with the
// ceil rule so the rectangle meets at most 2x2 texels); kHiZOccluded iff h < depth_near.
//
// ---- Restrictions, precision, NaN -------------------------------------------------------------------
// - projection must be a (possibly off-centre) perspective matrix of the glFrustum form:
//   row 0 = (P00, 0, P02, 0), row 1 = (0, P11, P12, 0), row 2 = (0, 0, P22, P23), row 3 = (0, 0, -1, 0),
//   so that w_clip = t. perspective() of math.h qualifies. Otherwise make_displaced_cull_view
//   returns valid = false and nothing is ever culled.
// - Non-finite inputs (control points, range, matrices) or a weight <= 0: the bound is
//   kDisplacedBoundInvalid and never culled; so is a bound whose outputs overflow.
// - Like frustum.h and hiz.h, values are computed in float without padding for the rounding of the
//   transform itself (~1e-7 relative: far below a pixel); bounds are exact relative to it.
//
// Contracts: batch kernels take caller-owned buffers of patches.count entries (ranges: one
// DisplacementRange per patch, or null for no displacement); they never allocate or throw.
// A scalar implementation (one patch at a time) is all there is for now.
#pragma once

#include <cstddef>
#include <cstdint>

#include "patchcull/core/cones.h"
#include "patchcull/core/displacement.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/hiz.h"
#include "patchcull/core/math.h"
#include "patchcull/core/patch.h"

namespace patchcull {

/// Which bounding volume: Munkberg et al.'s object-oriented box, or the camera-aligned frustum.
enum class DisplacedBoundKind : std::uint8_t { oobb, caf };
/// Which cone of normals shapes the displacement extension.
enum class NormalConeKind : std::uint8_t { full, acon, con };

/// "oobb", "caf".
const char* displaced_bound_name(DisplacedBoundKind kind);
/// "full", "acon", "con".
const char* normal_cone_name(NormalConeKind kind);
/// Parses the names above; false (kind untouched) for anything else.
bool parse_displaced_bound(const char* text, DisplacedBoundKind& kind);
bool parse_normal_cone(const char* text, NormalConeKind& kind);

/// Added to delta+- (cos space) for the rounding of c = r.a and s = |r x a| (a few 1e-7).
inline constexpr float kDisplacedDeltaSlack = 1e-5f;
/// Scale of ext+- covering the rounding of the products and of |r| (a few ulp).
inline constexpr float kDisplacedExtScale = 1.0f + 0x1p-18f;
/// OOBB slabs are padded by this fraction of the box's largest coordinate magnitude: the rounded
/// frame is orthonormal only to ~1e-7, so corners O + sum c_i e_i are off by about that much.
inline constexpr float kDisplacedFramePad = 4e-6f;
/// A bound is projectable when its nearest view depth exceeds this times the magnitude of the terms
/// it was computed from (hiz.h step 3).
inline constexpr float kDisplacedDepthSafety = 0x1p-20f;

/// Per-frame constants of the bounds: build once per view with make_displaced_cull_view.
struct DisplacedCullView {
    Mat4 object_to_view;        ///< V = [L | T]
    Mat4 projection;            ///< glFrustum form (see the header), as to_depth_key(projection, depth)
    FrustumPlanes view_planes;  ///< clip planes over view-space points (make_frustum_planes(projection, depth))
    ClipDepth depth = ClipDepth::zero_to_one;  ///< the projection's convention
    float key_near = 0, key_far = 1;           ///< depth keys of the near and far planes (key_far = +inf: none)
    Vec3 axis_unit[3];                         ///< rows of L normalised (view x, y, z directions in object space)
    float axis_length[3];                      ///< |rows of L|
    float abs_row_z[4];                        ///< |V(2, c)|, for the projectability margin
    bool valid = false;                        ///< finite matrices, projection of the required form, L rows non-zero
};

/// Prepares the per-frame constants. object_to_view = view * model (any affine matrix with
/// non-degenerate rows); projection as described above, in convention depth (clip_space.h;
/// stored as its depth-key form, so depths below are keys: window depth, negated for reversed
/// conventions; the pyramid must be built in the same direction). Throws Error when the
/// projection contradicts depth (check_clip_depth).
DisplacedCullView make_displaced_cull_view(const Mat4& object_to_view, const Mat4& projection, ClipDepth depth);
struct CullView;  // cull_view.h
/// The same from one view's CullView (view.view, view.projection, view.depth).
DisplacedCullView make_displaced_cull_view(const CullView& view);

/// Status of a computed bound.
enum DisplacedBoundStatus : std::uint8_t {
    kDisplacedBoundProjected = 0,      ///< in front of the eye: ndc rectangle and depths are valid
    kDisplacedBoundOutsidePlane = 1,   ///< reaches t <= 0, and lies outside one clip plane: culled
    kDisplacedBoundUnprojectable = 2,  ///< reaches t <= 0 and meets every clip plane's inside
    kDisplacedBoundInvalid = 3,        ///< non-finite input or output, weight <= 0, invalid view
};

/// Screen-space summary of a displaced patch's bound (caf or oobb).
struct DisplacedBound {
    float ndc_xmin = -1, ndc_xmax = 1, ndc_ymin = -1, ndc_ymax = 1;  ///< valid when projected
    float depth_near = 0;             ///< depth key of the bound's nearest point (the CAF front plane); projected only
    float depth_far = 1;              ///< depth key of its farthest point (CAF: the back plane); projected only
    float key_near = 0, key_far = 1;  ///< the view's clip depth range in keys (DisplacedCullView)
    std::uint8_t status = kDisplacedBoundInvalid;
};

/// The cone of the given kind for a patch (full: an invalid cone; acon/con: cones.h).
NormalCone displaced_normal_cone(const BezierPatch& patch, NormalConeKind cone);

/// The bound of one patch with an explicit cone (invalid cone = full). For static patches whose
/// cone is precomputed (Niessner & Loop: CoN for static objects), and for tests.
DisplacedBound compute_displaced_bound_with_cone(const BezierPatch& patch, DisplacementRange range,
                                                 const NormalCone& cone, DisplacedBoundKind kind,
                                                 const DisplacedCullView& view);

/// The bound of one patch: displaced_normal_cone + compute_displaced_bound_with_cone.
DisplacedBound compute_displaced_bound(const BezierPatch& patch, DisplacementRange range, DisplacedBoundKind kind,
                                       NormalConeKind cone, const DisplacedCullView& view);

/// Frustum decision of a bound: true = provably outside the view volume.
bool displaced_bound_outside_frustum(const DisplacedBound& bound);

/// Occlusion decision (HiZDecision of hiz.h) of a bound against a Hi-Z pyramid whose depth buffer
/// is the viewport (0, 0, W, H): frustum first, then the Hi-Z test of a projected bound.
std::uint8_t displaced_bound_hiz_decision(const DisplacedBound& bound, const HiZPyramid& hiz);

/// Batch: bounds of every patch. ranges: patches.count entries or null (no displacement);
/// out: patches.count entries.
void compute_displaced_bounds(const PatchBatchView& patches, const DisplacementRange* ranges, DisplacedBoundKind kind,
                              NormalConeKind cone, const DisplacedCullView& view, DisplacedBound* out);

/// Batch frustum kernel: culled[i] = 1 when patch i's bound is outside the view volume, else 0.
void cull_displaced_frustum(const PatchBatchView& patches, const DisplacementRange* ranges, DisplacedBoundKind kind,
                            NormalConeKind cone, const DisplacedCullView& view, std::uint8_t* culled);

/// Batch frustum + occlusion kernel: decision[i] is a HiZDecision. The screen is the pyramid's
/// depth buffer.
void cull_displaced_occlusion(const PatchBatchView& patches, const DisplacementRange* ranges, DisplacedBoundKind kind,
                              NormalConeKind cone, const DisplacedCullView& view, const HiZPyramid& hiz,
                              std::uint8_t* decision);

}  // namespace patchcull
