// patchcull/core/cones.h: cones bounding the normals of a bicubic patch, computed per frame from the
// control points alone (patches are animated). Shared by back-patch culling (tcone, ncone;
// Loop, Niessner & Eisenacher §2) and by the displaced-patch bounds of Niessner & Loop §4.2 (ACoN, CoN).
//
// A cone (axis a, unit; half-angle alpha) bounds a vector field when every non-zero vector of
// the field makes an angle <= alpha with a. valid is false when no cone under 90 degrees exists
// (then nothing may be concluded from it).
#pragma once

#include "patchcull/core/math.h"
#include "patchcull/core/patch.h"

namespace patchcull {

struct NormalCone {
    Vec3 axis;            ///< unit
    float cos_angle = 0;  ///< cos(alpha)
    float sin_angle = 1;  ///< sin(alpha)
    bool valid = false;
};

/// Approximate cone of normals (ACoN / TCONE): from the cones of the tangent patch B_u and the
/// bitangent patch B_v (Sederberg & Meyers 1988). Polynomial patches only (w = 1).
NormalCone tangent_normal_cone(const BezierPatch& patch);

/// Accurate cone of normals (CoN / NCONE): bounds the 36 Bezier control vectors of the normal
/// patch N = B_u x B_v (bidegree 5). Polynomial patches only (w = 1).
NormalCone normal_patch_cone(const BezierPatch& patch);

/// Sphere holding every control point (hence the patch): centre of the control points' box.
struct PatchSphere {
    Vec3 center;
    float radius = 0;
};
PatchSphere control_point_sphere(const BezierPatch& patch);

/// The conservative perspective back-facing test of backpatch.h for a cone and a sphere.
bool cone_back_facing(const NormalCone& cone, const PatchSphere& sphere, Vec3 eye);

}  // namespace patchcull
