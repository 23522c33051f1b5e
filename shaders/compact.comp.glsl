// Compaction pass (CompactPass, src/gl/compact_pass.cpp; include/patchcull/gl/gl_compaction.h): the
// patches p of the range [first_patch, first_patch + patch_count) whose flag word satisfies
// (flag & mask) == value go into the draw list (kBindingDrawList) from entry list_first on; their
// count n goes to a word of the pass's own buffer (kBindingCompactSums); then kCompactFinish
// writes the range's C = max(1, ceil(patch_count / K)) DrawArraysIndirectCommands (K =
// patches_per_command): command c = {16 m_c, 1, 16 (list_first + c K), 0}, m_c = min(K, n - c K)
// where positive, else 0, and the draw count ceil(n / K), for an indirect draw that pulls point
// gl_VertexID % 16 of patch list[gl_VertexID / 16].
// The atomic append (order not stable):
// - kCompactInit (one invocation): the total sums[0] = 0.
// - kCompactAppend: each work group counts its survivors in shared memory, reserves their slots
//   with one atomicAdd on sums[0] and writes them.
// The prefix scan (ascending patch order, the same every frame):
// - kCompactGroupCounts: group g's survivor count into sums[g]; in the
//   scan's modes each invocation holds kCompactScanRun consecutive patches (a group
//   kCompactGroupSize kCompactScanRun of them: fewer groups, fewer barriers).
// - kCompactScanSums (one work group): sums -> their exclusive prefix sums, looping over the
//   groups kCompactGroupSize at a time; the total n into sums[group_count].
// - kCompactScatter: each survivor at list[list_first + sums[g] + its rank within group g]
//   (a scan of the invocations' counts, then each writes its run's survivors in order).
// - kCompactSingleGroup (one work group, a range of at most kCompactSingleGroupPatches): the
//   three above in a loop over the range 2048 patches at a time, then the finish: one dispatch.
// Both end with kCompactFinish: one invocation per command (group_base: the dispatch's first
// command; group_count: the word of sums holding n). CullStatusPass's fused append
// (cull_status.comp.glsl's PC_STATUS_APPEND) ends with it too, its total at word 0 of its own
// buffer bound at kBindingCompactSums.
// Two programs: the scan's modes with PC_COMPACT_SCAN, the append's without (on llvmpipe the
// append ran several times slower in one program with the scan's code: 39-76 ms against 14-17 ms
// per 1M patches, bench/compaction_bench.cpp under varying load).
#version 450 core
#include "shared.h"
#include "pass_params.h"
#define PC_CULL_FLAGS readonly
#include "patch_buffers.h"

layout(local_size_x = kCompactGroupSize) in;

layout(std430, binding = kBindingDrawList) writeonly buffer DrawList {
    uint draw_list[];
};
layout(std430, binding = kBindingDrawCommands) writeonly buffer DrawCommands {
    uint draw_commands[];  // count, instanceCount, first, baseInstance from command_word on
};
layout(std430, binding = kBindingDrawCount) writeonly buffer DrawCount {
    uint draw_count[];
};
layout(std430, binding = kBindingCompactSums) buffer CompactSums {
    uint group_sums[];
};

shared uint s_scan[kCompactGroupSize];
shared uint s_total;

// Command c of the range: m patches from list entry first_entry on.
void write_command(uint c, uint m, uint first_entry) {
    const uint w = compact.command_word + 4u * c;
    draw_commands[w] = kDrawListPatchVertices * m;
    draw_commands[w + 1u] = 1u;
    draw_commands[w + 2u] = kDrawListPatchVertices * first_entry;
    draw_commands[w + 3u] = 0u;
}

#ifndef PC_COMPACT_SCAN
// Survivors of the work group: s_total their count, the return value this invocation's slot
// (an order that depends on the atomics' order).
uint group_count(bool keep) {
    if (gl_LocalInvocationIndex == 0u) s_total = 0u;
    barrier();
    uint slot = 0u;
    if (keep) slot = atomicAdd(s_total, 1u);
    barrier();
    return slot;
}
#endif

#ifdef PC_COMPACT_SCAN
// Inclusive prefix sum of v over the work group (Hillis-Steele); s_scan[last] is the total after.
uint group_inclusive_scan(uint v) {
    const uint i = gl_LocalInvocationIndex;
    s_scan[i] = v;
    barrier();
    for (uint offset = 1u; offset < kCompactGroupSize; offset <<= 1u) {
        uint sum = s_scan[i];
        if (i >= offset) sum += s_scan[i - offset];
        barrier();
        s_scan[i] = sum;
        barrier();
    }
    return s_scan[i];
}
#endif

#ifdef PC_COMPACT_SCAN
// The survivors among the kCompactScanRun patches of the range from index run_first on: their
// bits (bit k: patch run_first + k) and their count.
uint run_survivors(uint run_first, out uint count) {
    uint bits = 0u;
    count = 0u;
    for (uint k = 0u; k < kCompactScanRun; ++k) {
        const uint index = run_first + k;
        if (index < compact.patch_count && (cull_flags[compact.first_patch + index] & compact.mask) == compact.value) {
            bits |= 1u << k;
            ++count;
        }
    }
    return bits;
}

// Writes the survivors of bits (a run from index run_first on) to the list from entry at on.
void write_run(uint bits, uint run_first, uint at) {
    for (uint k = 0u; k < kCompactScanRun; ++k)
        if ((bits & (1u << k)) != 0u) draw_list[at++] = compact.first_patch + run_first + k;
}
#endif

// The range's commands c = first, first + stride, ... and (by c == 0) its draw count, for n survivors.
void write_commands(uint first, uint stride, uint n) {
    // patch_count: the range's; K <= max(patch_count, 1), so no sum below overflows.
    const uint k = compact.patches_per_command;
    const uint commands = max(1u, (compact.patch_count + k - 1u) / k);
    for (uint c = first; c < commands; c += stride) {
        const uint start = c * k;
        write_command(c, n > start ? min(k, n - start) : 0u, compact.list_first + start);
    }
    if (first == 0u && compact.write_count != 0u) draw_count[compact.count_word] = (n + k - 1u) / k;
}

void main() {
    const uint mode = compact.mode;
    if (mode == kCompactInit) {
        if (gl_GlobalInvocationID.x == 0u) group_sums[0] = 0u;
        return;
    }
    if (mode == kCompactFinish) {
        // One command per invocation: a stride of max(patch_count, 1) >= the command count ends the
        // loop after it (no wrap: both are below 2^31).
        write_commands(compact.group_base + gl_GlobalInvocationID.x, max(compact.patch_count, 1u),
                       group_sums[compact.group_count]);
        return;
    }
    const uint lid = gl_LocalInvocationIndex;
#ifdef PC_COMPACT_SCAN
    if (mode == kCompactSingleGroup) {
        uint carry = 0u;  // survivors of the chunks before
        for (uint chunk = 0u; chunk < compact.patch_count; chunk += kCompactGroupSize * kCompactScanRun) {
            const uint run_first = chunk + lid * kCompactScanRun;
            uint count;
            const uint bits = run_survivors(run_first, count);
            write_run(bits, run_first, compact.list_first + carry + group_inclusive_scan(count) - count);
            carry += s_scan[kCompactGroupSize - 1u];
            barrier();  // every invocation has read s_scan before the next chunk writes it
        }
        write_commands(lid, kCompactGroupSize, carry);
        return;
    }
#endif
#ifdef PC_COMPACT_SCAN
    if (mode == kCompactScanSums) {
        uint carry = 0u;
        for (uint start = 0u; start < compact.group_count; start += kCompactGroupSize) {
            const uint g = start + lid;
            const uint v = g < compact.group_count ? group_sums[g] : 0u;
            const uint inclusive = group_inclusive_scan(v);
            if (g < compact.group_count) group_sums[g] = carry + inclusive - v;
            carry += s_scan[kCompactGroupSize - 1u];
            barrier();  // every invocation has read s_scan before the next chunk writes it
        }
        if (lid == 0u) group_sums[compact.group_count] = carry;
        return;
    }
#endif
#ifdef PC_COMPACT_SCAN
    // Invocation lid of group g holds kCompactScanRun consecutive patches of the range, from
    // index (g kCompactGroupSize + lid) kCompactScanRun on: its survivors' bits and their count.
    const uint run_first = (gl_WorkGroupID.x * kCompactGroupSize + lid) * kCompactScanRun;
    uint count;
    const uint bits = run_survivors(run_first, count);
    if (mode == kCompactGroupCounts) {
        if (lid == 0u) s_total = 0u;
        barrier();
        if (count != 0u) atomicAdd(s_total, count);
        barrier();
        if (lid == 0u) group_sums[compact.group_base + gl_WorkGroupID.x] = s_total;
        return;
    }
    // kCompactScatter: the runs' survivors in order, after those of the groups and runs before.
    write_run(bits, run_first,
              compact.list_first + group_sums[compact.group_base + gl_WorkGroupID.x] + group_inclusive_scan(count) -
                  count);
#else
    // kCompactAppend
    const uint index = gl_GlobalInvocationID.x;
    const uint p = compact.first_patch + index;
    const bool keep = index < compact.patch_count && (cull_flags[p] & compact.mask) == compact.value;
    const uint slot = group_count(keep);
    if (lid == 0u && s_total != 0u) s_total = atomicAdd(group_sums[0], s_total);
    barrier();
    if (keep) draw_list[compact.list_first + s_total + slot] = p;
#endif
}
