// patchcull/objects/backface.h: back-face culling of triangles: the per-triangle test and normal masks
// (G. Zachmann's lecture "Advanced Visibility Computations", "Back-Face Culling" and
// "Normal Masks"; normal masks are Zhang & Hoff, "Fast backface culling using normal masks",
// 1997). Clustered back-face culling (Johannsen & Carter 1998) is in backface_clusters.h.
//
// Conventions (the renderer draws one-sided triangle objects with glCullFace(GL_BACK) and GL's
// default front face GL_CCW):
// - A triangle (p0, p1, p2) is counter-clockwise seen from its front; its normal is
//   n = (p1 - p0) x (p2 - p0), unnormalized.
// - It is back-facing for the eye e when n . (e - p0) <= 0. n . (e - p) is the same for every
//   point p of the triangle's plane, so the decision is one number per triangle. With the eye as
//   the projection centre GL rasterizes no pixel of such a triangle with back faces culled (its
//   window-space area is <= 0), zero-area triangles included.
// - Everything is in one frame: the eye in the frame of the vertices. For an object with its own
//   frame, move the eye into it (inverse of object_to_world). A mirroring object_to_world
//   (det < 0) reverses window-space winding: GL then needs glFrontFace(GL_CW) for that object to
//   agree with these object-space decisions.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "patchcull/core/clip_space.h"
#include "patchcull/core/math.h"

namespace patchcull {

// ---- per-triangle test ---------------------------------------------------------------------

/// Relative rounding-error bound of the per-triangle test (10 u, u = 2^-24; see below).
inline constexpr float kTriangleTestErrorBound = 5.97e-7f;

/// Per-triangle back-face test (the lecture's n . v test, perspective: v = p - eye):
/// culled[t] = 1 when triangle t (vertices[indices[3t + k]], k = 0..2) is back-facing for eye.
/// Float rounding: with e1 = p1 - p0, e2 = p2 - p0, w = eye - p0, n = e1 x e2 (each component
/// fma(a, b, -(c * d))) and s = n . w (fma chain), the triangle is culled when
///   s <= -(kTriangleTestErrorBound * P + 32 * denorm_min),  P = sum |e1_a e2_b w_c| over the
///   six terms of the determinant (the permanent, computed with the same fma order),
/// and P finite. 10 u P bounds |s - exact n . (eye - p0)| (differences, cross product and dot
/// product, as Shewchuk's orient3d bound (7u + 56u^2) P, which this order exceeds by u), so a
/// triangle is culled only when it is back-facing in exact arithmetic: the float decision errs
/// only toward "not culled" (eyes within rounding of the plane keep the triangle). A triangle
/// with two equal vertices (coordinates compared exactly) has zero area and is culled. A
/// non-finite value anywhere keeps the triangle.
/// Contracts: indices holds 3 * triangle_count entries, each < the vertex count; culled holds
/// triangle_count bytes. Never allocates or throws.
void cull_backfacing_triangles_scalar(const Vec3* vertices, const std::uint32_t* indices, std::size_t triangle_count,
                                      Vec3 eye, std::uint8_t* culled);
/// The same test, SIMD (Highway, best instruction set chosen once at run time): decisions
/// identical to the scalar reference, bit for bit (same operations in the same order).
void cull_backfacing_triangles_simd(const Vec3* vertices, const std::uint32_t* indices, std::size_t triangle_count,
                                    Vec3 eye, std::uint8_t* culled);

// ---- normal masks (Zhang & Hoff 1997) ------------------------------------------------------

/// The direction cube with N x N cells per face: 6 N^2 classes of normal directions. Face
/// f = 2 a + (s < 0) holds the directions whose largest |component| is axis a with sign s; cell
/// (i, j) of a face holds the directions s e_a + u e_b + v e_c (b = (a+1) % 3, c = (a+2) % 3) with
/// u in [-1 + 2i/N, -1 + 2(i+1)/N] and v likewise for j: a convex cone spanned by its 4 corner
/// directions. Class index = f N^2 + j N + i.
class NormalMaskGrid {
public:
    /// Largest N whose 6 N^2 classes, plus the unclassified one, fit a std::uint16_t.
    static constexpr int kMaxDivisions = 104;
    /// Cells are treated as grown by this much (in u, v units) on every side when masks are built,
    /// so a direction that rounding puts into a neighbouring cell still lies in its class's cone.
    static constexpr double kCellGrowth = 1e-5;

    /// N cells per face side. Throws patchcull::Error unless 1 <= divisions <= kMaxDivisions.
    explicit NormalMaskGrid(int divisions);

    /// Class of a normal (taken as exact), in [0, class_count()); unclassified() for a zero or
    /// non-finite normal. Ties between axes go to the lower axis (the direction then lies on the
    /// cell's edge, inside the grown cell).
    std::uint16_t classify(Vec3 normal) const;
    /// Class of each triangle's normal computed in double precision from the float vertices:
    /// classes[t] for triangle t (indices as cull_backfacing_triangles_*). A triangle whose normal
    /// direction the double computation cannot place within kCellGrowth / 4 of its cell (zero or
    /// near-zero area, non-finite coordinates) gets unclassified(), never culled by a mask.
    /// Contracts: classes holds triangle_count entries. Never throws.
    void classify_triangles(const Vec3* vertices, const std::uint32_t* indices, std::size_t triangle_count,
                            std::uint16_t* classes) const;

    int divisions() const { return n_; }
    /// 6 N^2.
    int class_count() const { return 6 * n_ * n_; }
    /// The class index of unclassifiable normals, == class_count(); no mask ever marks it.
    std::uint16_t unclassified() const { return static_cast<std::uint16_t>(class_count()); }
    /// The 4 corner directions of class cls's cell grown by kCellGrowth (double precision, not
    /// normalized; their convex cone holds every direction classify puts into cls).
    void class_corners(std::uint16_t cls, double corners[4][3]) const;

private:
    int n_;
};

/// One bit per class: set when every normal of the class is back-facing for every point whose
/// view ray lies in the (sub-)frustum the mask was made for.
struct BackMask {
    std::vector<std::uint64_t> bits;
    int class_count = 0;  ///< classes >= class_count test false
    /// True when class cls is marked back-facing. Never throws.
    bool test(std::uint16_t cls) const {
        return cls < class_count && (cls >> 6) < bits.size() && ((bits[cls >> 6] >> (cls & 63)) & 1u) != 0;
    }
    /// Number of classes marked.
    int marked() const;
};

/// The back mask of the sub-frustum of world_to_clip (depth: its clip-depth convention) that
/// covers screen sector (sector_x, sector_y) of a sectors x sectors grid (NDC x in
/// [-1 + 2 sx / S, -1 + 2 (sx + 1) / S], y likewise, each grown by 1e-5 of the NDC range;
/// sectors = 1, sector 0 0: the whole frustum). Built as the lecture describes: a class is marked
/// when n_i . v_j > 0 for every corner direction n_i of its grown cell and every corner ray v_j
/// of the sub-frustum (the eye is world_to_clip's projection centre; v_j = corner - eye), with
/// a 1e-12 relative margin, in double precision. The test is exact for the cones: n . v is
/// bilinear, so n = sum a_i n_i and v = sum b_j v_j (a, b >= 0) give n . v = sum a_i b_j
/// n_i . v_j > 0, and a corner pair with n_i . v_j <= 0 is itself a normal of the (grown) class
/// facing a ray of the sub-frustum, so the test loses nothing beyond the growth and the margin. n . v > 0 is n . (p -
/// eye) > 0: back-facing at every point on the ray. An orthographic world_to_clip (projection centre at infinity) uses
/// its one view direction. A matrix that is singular, non-finite, or whose frustum corners lie behind its centre marks
/// nothing (conservative).
///
/// Which primitives may use a mask: a triangle's facing is one number for its whole plane, so a
/// triangle is correctly judged by the mask of any sub-frustum whose cone holds one point of the
/// triangle (e.g. a vertex in front of the eye that projects into the sector: sector_of_point).
/// With the whole-frustum mask every triangle is judged correctly: one that has no point in the
/// frustum has no pixel either. Non-planar primitives (clusters, patches) need all their points in
/// the sub-frustum (e.g. their bounding box's projection inside the sector, in front of the eye).
/// Contracts: 1 <= sectors, 0 <= sector_x, sector_y < sectors, else throws patchcull::Error.
/// out.bits is resized (the only allocation).
void make_back_mask(const NormalMaskGrid& grid, const Mat4& world_to_clip, ClipDepth depth, int sector_x, int sector_y,
                    int sectors, BackMask& out);

/// The screen sector (sy * sectors + sx) into which point p projects, computed in double: p must
/// be in front of the eye (clip w > 0) and project into [-1, 1]^2 in NDC, else -1. A point on a
/// sector edge goes to the higher sector (both sub-frusta hold it). Never throws.
int sector_of_point(const Mat4& world_to_clip, Vec3 p, int sectors);

/// culled[i] = mask.test(classes[i]) (the lecture's BackMask[byteOffset] & bitMask lookup).
/// Contracts: classes and culled hold n entries. Never allocates or throws.
void cull_by_normal_mask_scalar(const std::uint16_t* classes, std::size_t n, const BackMask& mask,
                                std::uint8_t* culled);
/// The same lookup with a SIMD gather of 32-bit mask words (Highway; identical results). Whether
/// the gather pays is measured in bench/backface_bench.cpp.
void cull_by_normal_mask_simd(const std::uint16_t* classes, std::size_t n, const BackMask& mask, std::uint8_t* culled);

}  // namespace patchcull
