// Cull status pass (CullStatusPass, src/gl/cull_status_pass.cpp): the two ends of the flag chain
// (include/patchcull/gl/gl_passes.h), one invocation per patch.
// - kStatusBegin: clears the reason bits (kCullReasonMask) of every patch of the range and keeps
//   its status bits, so the frame's test passes start from "nothing culled" while the first
//   drawing pass still sees last frame's statuses.
// - kStatusEnd: turns the reasons the tests left into the temporal status of Niessner & Loop's
//   two-pass pipeline (Niessner & Loop §3): a patch no test culled gets kStatusVisible, plus
//   kStatusNewlyVisible when its word lacked kStatusVisible (it was not drawn in the first pass);
//   a culled patch keeps its reason alone. It adds the counts to the caller's counter buffer
//   (kBindingCullCounters, kCounterCount uints, cleared by the caller): one atomic add per work
//   group and counter, from shared-memory sums.
// - kStatusEnd with PC_STATUS_APPEND (CullStatusPass::end with a DrawListBuffers): also appends
//   the patches whose new word satisfies (word & mask) == value to the draw list
//   (kBindingDrawList) as compact.comp.glsl's kCompactAppend does, one atomicAdd per work group on
//   the total; the range's first list entry, mask and value are words of the pass's buffer at
//   kBindingCompactSums (shared.h's kStatusAppend*). compact.comp.glsl's kCompactFinish then
//   writes the commands and the draw count from the total. Without the define the shader is the
//   one above (no list, no extra barrier).
#version 450 core
#include "shared.h"
#include "pass_params.h"
#define PC_CULL_FLAGS
#define PC_MAX_DISPLACEMENT readonly
#include "patch_buffers.h"
#include "flag_chain.h"

layout(local_size_x = kCullGroupSize) in;

layout(std430, binding = kBindingCullCounters) buffer CullCounters {
    uint counters[];
};

shared uint s_counts[kCounterCount];

#ifdef PC_STATUS_APPEND
layout(std430, binding = kBindingDrawList) writeonly buffer DrawList {
    uint draw_list[];
};
layout(std430, binding = kBindingCompactSums) buffer StatusAppend {
    uint append_words[];  // kStatusAppendTotal .. kStatusAppendValue
};
shared uint s_append;  // the group's survivors, then their first slot after the total
#endif

void main() {
    const uint index = gl_GlobalInvocationID.x;
    const uint p = status.first_patch + index;
    const bool in_range = index < status.patch_count;
    if (status.mode == kStatusBegin) {
        if (in_range) cull_flags[p] &= ~kCullReasonMask;
        return;
    }
    if (gl_LocalInvocationIndex < kCounterCount) s_counts[gl_LocalInvocationIndex] = 0u;
#ifdef PC_STATUS_APPEND
    if (gl_LocalInvocationIndex == 0u) s_append = 0u;
    bool keep = false;
    uint slot = 0u;
#endif
    barrier();
    if (in_range) {
        const uint old_word = cull_flags[p];
        const uint reason = old_word & kCullReasonMask;
        const bool was_visible = (old_word & kStatusVisible) != 0u;
        uint word = reason;
        if (reason == 0u) word = kStatusVisible | (was_visible ? 0u : kStatusNewlyVisible);
        cull_flags[p] = word;
#ifdef PC_STATUS_APPEND
        keep = (word & append_words[kStatusAppendMask]) == append_words[kStatusAppendValue];
        if (keep) slot = atomicAdd(s_append, 1u);
#endif
        if (was_visible) atomicAdd(s_counts[kCounterWasVisible], 1u);
        if (reason == kCullFrustum) atomicAdd(s_counts[kCounterFrustum], 1u);
        if (reason == kCullBackPatch) atomicAdd(s_counts[kCounterBackPatch], 1u);
        if (reason == kCullOcclusion) {
            atomicAdd(s_counts[kCounterOcclusion], 1u);
            if (pc_margin(p, status.has_margins) > 0.0) atomicAdd(s_counts[kCounterDisplacedOcclusion], 1u);
        }
        if (reason == 0u) {
            atomicAdd(s_counts[kCounterVisible], 1u);
            if (!was_visible) atomicAdd(s_counts[kCounterNewlyVisible], 1u);
        }
    }
    barrier();
    if (gl_LocalInvocationIndex < kCounterCount && s_counts[gl_LocalInvocationIndex] != 0u)
        atomicAdd(counters[gl_LocalInvocationIndex], s_counts[gl_LocalInvocationIndex]);
#ifdef PC_STATUS_APPEND
    // The group's slots: one atomicAdd on the range's total, then each survivor at its slot.
    if (gl_LocalInvocationIndex == 0u && s_append != 0u)
        s_append = atomicAdd(append_words[kStatusAppendTotal], s_append);
    barrier();
    if (keep) draw_list[append_words[kStatusAppendListFirst] + s_append + slot] = p;
#endif
}
