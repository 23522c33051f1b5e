// shaders/flag_chain.h (GLSL only; include after shared.h and patch_buffers.h, with its blocks
// CullFlags read-write and MaxDisplacement: define PC_CULL_FLAGS and PC_MAX_DISPLACEMENT): the
// flag chain of the cull passes (include/patchcull/gl/gl_passes.h, "The flag chain"). Every test
// pass reads and writes the caller's flag buffer (kBindingCullFlags, one uint per patch); a patch
// whose reason bits (kCullReasonMask) are set was culled by an earlier pass of the frame and is
// skipped, so each patch ends with the reason of the first test that culled it, and the later,
// costlier tests only see the survivors. Status bits (kStatusVisible, kStatusNewlyVisible) are
// left alone; only the status pass (cull_status.comp.glsl) writes them.
// The optional margin buffer (kBindingMaxDisplacement, float per patch, >= 0) marks displaced
// patches: margin > 0. Each invocation reads and writes its own patch's flag word only.

#if !defined(PC_CULL_FLAGS) || !defined(PC_MAX_DISPLACEMENT)
#error flag_chain.h needs patch_buffers.h's CullFlags and MaxDisplacement (PC_CULL_FLAGS, PC_MAX_DISPLACEMENT)
#endif

// True when an earlier pass of the chain culled patch p.
bool pc_chain_culled(uint p) { return (cull_flags[p] & kCullReasonMask) != 0u; }

// Culls patch p with `reason` (its status bits kept).
void pc_chain_cull(uint p, uint reason) { cull_flags[p] = (cull_flags[p] & ~kCullReasonMask) | reason; }

// Runs `call`, a pass's work on patch p (its flag word and its own outputs written), exactly. With
// PATCHCULL_FMA_VIA_DOUBLE (exact_fma.h) it runs first with the fast pc_fma, and returns from
// main when no call was suspect; otherwise it restores the flag word and runs again exactly.
// Use it at the top level of main. llvmpipe (Mesa 22.3) branches neither on `if` nor on `return`
// (it runs the code with the invocations masked off); it only leaves a loop early once no
// invocation is left in it. So the rerun pays where a pass's work is mostly loops: measured
// cheaper for the frustum and occlusion passes, dearer for the cones and the displaced bounds,
// which run once, exactly (docs/PERFORMANCE.md).
#ifdef PATCHCULL_FMA_VIA_DOUBLE
#define PC_RUN_EXACT(p, call)              \
    {                                      \
        const uint pc_word = cull_flags[p]; \
        pc_fma_exact = false;              \
        pc_fma_suspect = false;            \
        call;                              \
        if (!pc_fma_suspect) return;       \
        cull_flags[p] = pc_word;           \
        pc_fma_exact = true;               \
        call;                              \
    }
#else
#define PC_RUN_EXACT(p, call) call
#endif

// Whether the pass has a margin buffer: its has_margins flag, or the constant PC_MARGINS (0 or 1)
// where the pass compiles one program for each (llvmpipe runs both sides of a branch even on a
// uniform, so a constant drops the unused side's cost).
#ifdef PC_MARGINS
#define PC_HAS_MARGINS(has_margins) (PC_MARGINS != 0)
#else
#define PC_HAS_MARGINS(has_margins) ((has_margins) != 0u)
#endif

// Patch p's displacement margin, 0 without a margin buffer.
float pc_margin(uint p, uint has_margins) { return PC_HAS_MARGINS(has_margins) ? max_displacement[p] : 0.0; }
