// patchcull/gl/gl_backpatch_passes.h: the GPU side of the back-patch method registry
// (core/backpatch_methods.h): each method's pass, made by a factory registered under the method's
// id. CullPipeline, BackpatchCuller and the tools' lists of GPU methods iterate it.
#pragma once

#include <memory>
#include <vector>

#include "patchcull/core/backpatch_methods.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/gl/gl_passes.h"

namespace patchcull::gl {

/// One back-patch method on the GPU, in the flag chain (gl_passes.h): for each patch of the range
/// whose reason bits are 0 and whose margin is 0 (or no margins), the method's CPU kernel's
/// decision on the same view; a culled patch gets the method's flag (kCullBackPatch) in its reason
/// bits, others are left as they are. The state contract of gl_passes.h's run() holds.
class BackpatchPass {
public:
    virtual ~BackpatchPass() = default;
    virtual void run(const PatchBuffers& patches, const CullView& view, const BackpatchOptions& options) = 0;
};

/// Makes a method's pass on a context's PassContext (its programs are compiled on first use).
using BackpatchPassFactory = std::unique_ptr<BackpatchPass> (*)(PassContext& context);

/// Registers the pass of method id (registered in core/backpatch_methods.h), replacing any
/// earlier one. Throws Error for an unregistered id or a null factory. Call at start-up, before
/// any thread uses the registry.
void register_backpatch_pass(BackpatchMethod id, BackpatchPassFactory factory);
/// True when method id has a GPU pass.
bool has_backpatch_pass(BackpatchMethod id);
/// The pass of method id on context (Error when the method has none).
std::unique_ptr<BackpatchPass> make_backpatch_pass(PassContext& context, BackpatchMethod id);
/// The methods that have a GPU pass, in registry order: `render --backpatch`'s choices.
std::vector<BackpatchMethod> gpu_backpatch_methods();

}  // namespace patchcull::gl
