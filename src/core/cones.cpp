// Cones of normals, the control-point sphere and the perspective back-facing test
// (patchcull/core/cones.h). The formulas live in cones_internal.h (shared with the scalar kernels of
// backpatch_cones.cpp and mirrored by backpatch_cones_simd.cpp); this file holds the public entry
// points and the derivations.
//
// ---- 1. Cone of a set of control vectors --------------------------------------------------------
// A Bezier vector field F(u,v) = sum_k w_k(u,v) f_k has Bernstein weights w_k >= 0, so F(u,v) is
// a non-negative combination of the control vectors f_k. If every non-zero f_k makes an angle
// <= alpha < 90deg with a unit axis a, then so does every non-zero F(u,v): the set
// {x : a.x >= cos(alpha) |x|} is a convex cone (it is a second-order cone), closed under
// non-negative combinations; zero vectors contribute nothing. Axis: the normalised centre of the
// box of the normalised non-zero control vectors (any axis is correct; of three cheap choices
// this one gave the narrowest cones on random sheets, about 10% narrower than the normalised sum
// of the normalised vectors: cones_test AxisChoice); half-angle: the largest angle to a non-zero
// control vector. cos(alpha) <= 0 (>= 90deg) or no non-zero vector -> invalid.
//
// ---- 2. TCONE: Sederberg & Meyers 1988 ("Loop detection in surface patch intersections", CAGD 5)
// B_u = 3 sum_{a<3,b<4} B2_a(u) B3_b(v) (P(a+1,b) - P(a,b)) and B_v likewise: cone (a_t, alpha_t)
// of the 12 u-differences and (a_b, alpha_b) of the 12 v-differences (section 1). Every normal
// n = B_u x B_v is t x b with t, b in those cones (or zero). Combined cone (derived here, it is
// the construction of S&M with |cos theta| in place of cos theta, which makes it hold for
// theta > 90deg as well): let theta = angle(a_t, a_b), c = cos theta, N = a_t x a_b / sin theta.
//   For unit t in cone t and unit x = t x b / |t x b|: x . t = 0 and angle(t, a_t) <= alpha_t,
//   so angle(x, a_t) is within 90deg +- alpha_t, i.e. |x . a_t| <= sin(alpha_t) =: s_t; likewise
//   |x . a_b| <= s_b. Write x = lambda N + y with y in span(a_t, a_b). With p = y.a_t, q = y.a_b
//   and the Gram matrix [[1, c], [c, 1]] of (a_t, a_b):
//       |y|^2 = (p^2 - 2 c p q + q^2) / (1 - c^2) <= (s_t^2 + 2 |c| s_t s_b + s_b^2) / sin^2 theta
//   (the maximum over the parallelogram |p| <= s_t, |q| <= s_b is at a vertex). So
//       sin angle(x, +-N) = |y| <= sin(alpha_n) := sqrt(s_t^2 + 2|c| s_t s_b + s_b^2) / sin theta.
//   If sin(alpha_n) < 1 then lambda != 0 for every admissible (t, b): in particular t != +-b
//   (else some unit x perpendicular to t and N would satisfy both bounds with lambda = 0, giving
//   |y| = 1), so t x b never vanishes, lambda has one sign on the connected set of (t, b), and at
//   (a_t, a_b) x = N: every normal lies within alpha_n of +N. sin(alpha_n) >= 1 covers exactly the
//   cases where the cones overlap (or overlap after negating one), contain a zero or are too wide:
//   then the combined cone is invalid. Tested with random vectors in random cones, including
//   vectors on the cones' boundaries (cones_test: SederbergMeyersCombinationHolds).
//   Munkberg et al. 2010 (HPG, "Efficient bounding of displaced Bezier patches") use the same
//   combination on the GPU; they approximate the tangent cones, we take them from the control
//   vectors as above.
//
// ---- 3. NCONE: Shirman & Abi-Ezzi 1993 (cone of the normal patch) ---------------------------------
// With U_ab = P(a+1,b) - P(a,b), V_cd = P(c,d+1) - P(c,d) and the product rule of Bernstein
// polynomials B^m_i(t) B^n_k(t) = C(m,i) C(n,k) / C(m+n,i+k) B^{m+n}_{i+k}(t):
//   N = B_u x B_v = 9 sum B2_a(u) B3_b(v) B3_c(u) B2_d(v) U_ab x V_cd
//     = sum_{i,j<=5} B5_i(u) B5_j(v) N_ij,
//   N_ij = 9 / (C(5,i) C(5,j)) sum_{a+c=i, b+d=j} C(2,a) C(3,b) C(3,c) C(2,d) U_ab x V_cd.
// The factor 9 / (C(5,i) C(5,j)) > 0 does not change directions, so the cone is built from
// N'_ij = sum U'_ab x V'_cd with U'_ab = C(2,a) C(3,b) U_ab, V'_cd = C(3,c) C(2,d) V_cd (144
// cross products). Checked against direct evaluation of B_u x B_v (cones_test:
// NormalPatchBezierFormMatchesDirectEvaluation). Cone of the 36 N'_ij as in section 1.
//
// ---- 4. Sphere and perspective runtime test (backpatch.h) ----------------------------------------
// Sphere: centre c of the control points' box, radius r = max |P_k - c|; a polynomial patch (and
// a rational one with positive weights) lies in the convex hull of its control points, hence in
// the sphere. For a patch point p, e - p = d - (p - c) with d = e - c and |p - c| <= r: when
// |d| > r the directions w = (e - p)/|e - p| lie within beta = asin(r/|d|) of d (the tangent cone
// from the origin to the ball of radius r around d). A normal n lies within alpha of a. By the
// triangle inequality for angles on the sphere,
//   angle(n, w) >= angle(a, d) - angle(a, n) - angle(w, d) >= angle(a, d) - alpha - beta,
// so if angle(a, d) >= 90deg + alpha + beta then angle(n, w) >= 90deg, n . (e - p) <= 0 at every
// point: back-facing. That needs alpha + beta <= 90deg (an angle is at most 180deg) and is then
//   cos angle(a, d) <= cos(90deg + alpha + beta) = -sin(alpha + beta)
//   <=>  a . d <= -|d| sin(alpha + beta),   with cos(alpha + beta) >= 0.
// The condition alpha + beta <= 90deg is required: without it (say alpha = beta = 80deg,
// -sin(160deg) = -0.34) the inequality alone would cull patches that face the eye. No asin/sin:
// sin b = r/|d|, cos b = sqrt(1 - sin^2 b) (as fma(-s, s, 1): accurate near s = 1),
// sin(alpha + beta) = sin a cos b + cos a sin b, cos(alpha + beta) = cos a cos b - sin a sin b.
// Rational patches (any w != 1): cones return invalid and the kernels never cull them.
//
// ---- 5. Floating point ----------------------------------------------------------------------------
// The cones are made conservative for the float computation, not only for exact arithmetic
// (u = 2^-24):
// - Control-vector cones: differences of the (exact) control points are correctly rounded
//   (relative error u); normalisation and dot products add a few u. cos(alpha) is computed as a
//   min of dot products (accurate in absolute terms), lowered by kCosSlack = 2e-6 (> 10 u), and
//   sin(alpha) = sqrt(fma(-c, c, 1)) from the lowered c, so (cos, sin) is a consistent pair of
//   an angle >= the true one. Cost: cones are never narrower than ~0.08deg.
// - S&M combination: sin(alpha_n) computed from consistent inputs, relative error < 10 u, plus
//   kSinSlack = 4e-6 absolute; cos from sin as above.
// - NCONE: the N'_ij come from sums of products that can cancel, so their rounding error is not
//   relative to |N'_ij|. Each component is at most 18 fma roundings over products of inputs that
//   carry <= 2 u each: |error| <= sqrt(3) (18 + 4 + 1) u M_ij <= kNormalRoundoff M_ij with
//   M_ij = sum over its terms of |U'|_1 |V'|_1. The exact N'_ij then lies within angle phi of the
//   computed one, sin phi <= kNormalRoundoff M_ij / |N'_ij|, and cos(angle + phi) >=
//   cos(angle) - 2 sin(phi): each vector's dot product is lowered by 2 kNormalRoundoff M_ij / |N'_ij|.
//   A computed zero N'_ij is skipped only when M_ij == 0 (every term has an exactly zero factor:
//   the collapsed edges of the teapot's lid and bottom); otherwise the cone is invalid.
// - Vectors with 0 < |v|^2 < 1e-30 or |v|^2 > 1e30, inf or NaN make the cone invalid (their
//   direction is not reliable): control-point differences from about 1e-15 to 1e15 for TCONE,
//   roughly 1e-7 to 1e6 for NCONE (whose vectors are products).
// - Sphere radius scaled by 1 + 2^-20 (the computed distances carry < 4 u).
// - Runtime test: errors of a.d, |d|, sin b, cos b and the sums are below 2e-6 in cos space
//   (with cos b taken as sqrt(fma(-s, s, 1)) the pair (sin b, cos b) is consistent, so an error in
//   sin b moves sin(alpha + beta) by at most that error); the test requires
//   a . d <= -|d| (sin(alpha + beta) + kFacingSlack), kFacingSlack = 1e-5. NaN anywhere -> no cull
//   (every comparison is written to fail on NaN).
#include "patchcull/core/cones.h"
#include "core/cones_internal.h"

namespace patchcull {

namespace {
NormalCone clean(const NormalCone& cone) { return cone.valid ? cone : NormalCone{}; }
}  // namespace

NormalCone tangent_normal_cone(const BezierPatch& patch) {
    if (!cones_detail::is_polynomial(patch)) return NormalCone{};
    return clean(cones_detail::tangent_cone_polynomial(patch));
}

NormalCone normal_patch_cone(const BezierPatch& patch) {
    if (!cones_detail::is_polynomial(patch)) return NormalCone{};
    return clean(cones_detail::normal_cone_polynomial(patch));
}

PatchSphere control_point_sphere(const BezierPatch& patch) { return cones_detail::sphere_of_points<true>(patch); }

bool cone_back_facing(const NormalCone& cone, const PatchSphere& sphere, Vec3 eye) {
    return cones_detail::back_facing(cone, sphere, eye);
}

}  // namespace patchcull
