// ncone back-patch cull pass, one invocation per patch: the GPU twin of cull_ncone_scalar
// (include/patchcull/backpatch.h, src/core/backpatch_cones.cpp): NCONE, the cone of the 36
// control vectors of the normal patch (Shirman & Abi-Ezzi). The pass itself is cone_pass.h; the
// cone and the test are backpatch_cones.h (the operation-by-operation mirror of
// src/core/cones_internal.h).
#version 450 core
#include "shared.h"
#include "backpatch_shared.h"
#include "exact_fma.h"
#include "backpatch_exact.h"
#include "backpatch_cones.h"
#define PC_PASS_CONE pc_normal_cone
#include "cone_pass.h"
