// shaders/ptp_tables.h (GLSL only; include after ptp_schedule.h): where backpatch_ptp.comp.glsl
// reads the ptp schedule's tables. OpenGL: ptp_schedule.h's constant arrays. Vulkan (PC_VULKAN,
// shaders/api.h): a read-only storage buffer at kBindingPtpTables holding the same words, which
// the Vulkan PassContext fills once (src/vk/ptp_tables.cpp) - glslang compiles a dynamic index
// into a constant array as a copy of the whole array into function memory, which lavapipe does
// not fold back into constant data (the pass then ran about 100 times slower).
#ifndef PATCHCULL_SHADERS_PTP_TABLES_H
#define PATCHCULL_SHADERS_PTP_TABLES_H

#ifdef PC_VULKAN
// std430: each array tightly packed, in this order (src/vk/ptp_tables.cpp writes them so).
layout(std430, binding = kBindingPtpTables) readonly buffer PtpTables {
    uint pairs[66];
    uint steps[512];
    uint step_weights[512];
    uint dest_first[65];
    int corner_of_dest[64];
    uint corners[4];
    uint corner_weights[4];
    uint margin_weights[64];
    uint margin_weight_terms[64];
    uint edge_points[16];
} pc_ptp_tables;
#define kPtpPairs pc_ptp_tables.pairs
#define kPtpSteps pc_ptp_tables.steps
#define kPtpStepWeights pc_ptp_tables.step_weights
#define kPtpDestFirst pc_ptp_tables.dest_first
#define kPtpCornerOfDest pc_ptp_tables.corner_of_dest
#define kPtpCorners pc_ptp_tables.corners
#define kPtpCornerWeights pc_ptp_tables.corner_weights
#define kPtpMarginWeights pc_ptp_tables.margin_weights
#define kPtpMarginWeightTerms pc_ptp_tables.margin_weight_terms
#define kPtpEdgePoints pc_ptp_tables.edge_points
#endif

#endif  // PATCHCULL_SHADERS_PTP_TABLES_H
