// Stencil posing pass (gl::StencilPoser, include/patchcull/gl/gl_posing.h, src/gl/stencil_poser.cpp):
// the GPU twin of ScenePoser::pose (include/patchcull/import/default_scene.h). One invocation per output
// row: first 16 per patch, its control points (patch.h order), then 24 per patch that has ACC
// tangent patches, its tangent vectors (du[0..11], dv[0..11], shared.h's kTangentVec4s layout).
// (Only the patches with tangents get tangent rows: with a fixed 40 rows per patch, llvmpipe ran
// the idle lanes of the patches without them, about half of its time on ACC models.)
//
// Exactness (why the output is bit-identical to the CPU's):
// - A stencil row is summed as the CPU's apply_row (src/import/subdivision.cpp) sums it: in
//   double, from offsets[r] to offsets[r+1] in order, starting at 0. Each product of a float weight
//   and a float coordinate is exact in double (24 + 24 significant bits), so whether the compiler
//   fuses it into the add or not, every step is one double rounding of the same exact value.
//   The sum is then rounded once to float (round to nearest, as static_cast<float>).
// - The instance transform is the CPU's Mat4 * Vec4 in float: per output coordinate the dot
//   product ((m0 x + m1 y) + m2 z) + m3 w, left to right, each operation rounded (the CPU builds
//   with -ffp-contract=off; `precise` forbids fusing here). Tangent vectors go through the same
//   dot product with w = 0 (the CPU's `linear`, including its + m3 * 0).
// Mirrored instances read their rows transposed (default_scene.cpp's derivation): only the row
// read changes, never the arithmetic.
#version 450 core

layout(local_size_x = 256) in;

#include "shared.h"

// Outputs at the renderer's own binding points (patch_buffers.h's control_points, 16 per patch,
// and patch_tangents, kTangentVec4s = 24 per patch), inputs at this pass's own binding points
// (shared.h).
#define PC_CONTROL_POINTS writeonly
#define PC_PATCH_TANGENTS writeonly
#include "patch_buffers.h"
// The posed control meshes: StencilPoser's own buffer (packed Vec3: base 0, stride 3) or the
// caller's (gl_posing.h's GpuVertices, bound whole: float3 or float4 at any 4-byte-aligned stride
// and offset; w is not read). Vertex v's x y z are vertices[u_vertex_base + v * u_vertex_stride + 0..2].
layout(std430, binding = kBindingPoseVertices) readonly buffer Vertices {
    float vertices[];
};
struct Instance {
    mat4 to_world;     // column-major, as Mat4
    uvec4 info;        // first_vertex, first_patch, mirrored, first patch row of its model
};
layout(std430, binding = kBindingPoseInstances) readonly buffer Instances {
    Instance instances[];
};
layout(std430, binding = kBindingPosePatchTable) readonly buffer PatchTable {
    uint patch_instance[];  // per output patch: its instance
};
layout(std430, binding = kBindingPoseTangentTable) readonly buffer TangentTable {
    uvec2 tangent_table[];  // per output patch with tangents: (patch, first row of its tangent block)
};
layout(std430, binding = kBindingPoseOffsets) readonly buffer Offsets {
    uint offsets[];  // rows + 1: row r's terms are [offsets[r], offsets[r+1])
};
layout(std430, binding = kBindingPoseTerms) readonly buffer Terms {
    uvec2 terms[];  // (model-local vertex index, floatBitsToUint(weight))
};

uniform uint u_patch_count;
uniform uint u_tangent_count;  // entries of tangent_table
uniform uint u_vertex_base;    // floats before vertex 0 in vertices[]
uniform uint u_vertex_stride;  // floats from one vertex to the next (>= 3)

vec3 stencil_row(uint row, uint first_vertex) {
    precise dvec3 s = dvec3(0.0lf);
    const uint end = offsets[row + 1u];
    for (uint k = offsets[row]; k < end; ++k) {
        const uvec2 t = terms[k];
        const uint v = u_vertex_base + u_vertex_stride * (first_vertex + t.x);
        const double w = double(uintBitsToFloat(t.y));
        s.x += w * double(vertices[v]);
        s.y += w * double(vertices[v + 1u]);
        s.z += w * double(vertices[v + 2u]);
    }
    return vec3(float(s.x), float(s.y), float(s.z));
}

// Row r of m times p, as math.h's dot(a.row(r), p): left to right, each step rounded.
float transform_row(mat4 m, int r, vec4 p) {
    precise float a = m[0][r] * p.x;
    precise float b = m[1][r] * p.y;
    precise float c = m[2][r] * p.z;
    precise float d = m[3][r] * p.w;
    precise float s = a + b;
    precise float t = s + c;
    precise float u = t + d;
    return u;
}

vec4 transform(mat4 m, vec4 p) {
    return vec4(transform_row(m, 0, p), transform_row(m, 1, p), transform_row(m, 2, p), transform_row(m, 3, p));
}

void main() {
    const uint index = gl_GlobalInvocationID.y * (gl_NumWorkGroups.x * gl_WorkGroupSize.x) + gl_GlobalInvocationID.x;
    if (index < 16u * u_patch_count) {
        const uint p = index / 16u, k = index % 16u;
        const Instance inst = instances[patch_instance[p]];
        const uint model_patch = p - inst.info.y;
        // Transposed (mirrored): world point 4j + i is the model's point 4i + j.
        const uint source = inst.info.z != 0u ? 4u * (k % 4u) + k / 4u : k;
        const vec3 c = stencil_row(inst.info.w + 16u * model_patch + source, inst.info.x);
        control_points[16u * p + k] = transform(inst.to_world, vec4(c, 1.0));
        return;
    }
    const uint row = index - 16u * u_patch_count;
    const uint q = row / 24u;
    if (q >= u_tangent_count) return;
    const uint t = row % 24u;  // 0-11: du[t], 12-23: dv[t - 12]
    const uvec2 entry = tangent_table[q];
    const Instance inst = instances[patch_instance[entry.x]];
    uint source = t;
    if (inst.info.z != 0u) {
        if (t < 12u) {
            // du'[3j + i] = dv[4i + j] (i < 3, j < 4)
            const uint j = t / 3u, i = t % 3u;
            source = 12u + 4u * i + j;
        } else {
            // dv'[4j + i] = du[3i + j] (i < 4, j < 3)
            const uint j = (t - 12u) / 4u, i = (t - 12u) % 4u;
            source = 3u * i + j;
        }
    }
    const vec3 d = stencil_row(entry.y + source, inst.info.x);
    const vec4 mapped = transform(inst.to_world, vec4(d, 0.0));
    patch_tangents[24u * entry.x + t] = vec4(mapped.xyz, t == 0u ? 1.0 : 0.0);
}
