// patchcull/core/backpatch_methods.h: the registry of back-patch methods: one entry per method
// with its name, its flag bit and its CPU kernels. The CLI (`cull --methods`, `render
// --backpatch`), the viewer, the evaluation and the GPU pipeline iterate it; the GPU pass of a
// method is registered under the same id in gl/gl_backpatch_passes.h. docs/CONTRIBUTING.md lists
// the files a new method touches.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "patchcull/core/backpatch.h"
#include "patchcull/core/cull_flags.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/core/patch.h"

namespace patchcull {

/// A back-patch method's id: its position in the registry. The built-in methods come first, in
/// this order; register_backpatch_method appends.
enum class BackpatchMethod : std::uint32_t { tcone = 0, ncone = 1, ptp = 2 };

/// Per-call choices of a method (ignored by the methods they do not concern).
struct BackpatchOptions {
    PtpRule ptp_rule = PtpRule::ncnt;  ///< ptp: DVis on Ncnt (default) or Pcnt
};

/// A CPU kernel: culled[i] = 1 when patch i faces away from view.eye everywhere, else 0; culled
/// holds patches.count bytes. Conservative (never culls a patch that faces the eye anywhere);
/// must not cull when !view.has_eye (or the method's own inputs are degenerate); never allocates
/// or throws.
using BackpatchKernel = void (*)(const PatchBatchView& patches, const CullView& view, const BackpatchOptions& options,
                                 std::uint8_t* culled);

struct BackpatchMethodInfo {
    std::string name;                  ///< the CLI's name, e.g. "tcone": lower case, unique
    std::string summary;               ///< one line for help text and docs
    BackpatchKernel scalar = nullptr;  ///< the reference kernel (required)
    BackpatchKernel simd = nullptr;    ///< the same decisions, faster (nullptr: scalar is used)
    /// True when the fused kernel and the fused GPU pass can run it as their back-patch stage
    /// (the cone tests); false: the pipeline runs it as its own pass.
    bool fusable = false;
    std::uint32_t flag = kCullBackPatch;  ///< the reason bit a culled patch gets
};

/// Every registered method, built-in ones first; entry k has id BackpatchMethod(k).
const std::vector<BackpatchMethodInfo>& backpatch_methods();
/// The entry of id (Error when there is none).
const BackpatchMethodInfo& backpatch_method_info(BackpatchMethod id);
/// "tcone", "ncone", "ptp", or a registered method's name ("?" for an unknown id).
const char* backpatch_method_name(BackpatchMethod id);
/// Finds a method by name; returns false (id unchanged) when none has it.
bool parse_backpatch_method(const char* name, BackpatchMethod& id);
/// The ids of every method, in registry order (the tools' lists).
std::vector<BackpatchMethod> backpatch_method_ids();
/// Adds a method and returns its id. Throws Error when the name is empty or taken, or scalar is
/// null. Call before any thread uses the registry (at start-up): it is not synchronised.
BackpatchMethod register_backpatch_method(BackpatchMethodInfo info);

/// Runs method id's SIMD kernel (its scalar one when it has none).
void cull_backpatch(BackpatchMethod id, const PatchBatchView& patches, const CullView& view,
                    const BackpatchOptions& options, std::uint8_t* culled);

}  // namespace patchcull
