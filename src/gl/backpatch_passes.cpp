// The GPU back-patch pass registry (patchcull/gl/gl_backpatch_passes.h) and the built-in methods'
// passes: BackpatchConePass (tcone, ncone) and BackpatchPtpPass (ptp).
#include "patchcull/gl/gl_backpatch_passes.h"

#include <map>
#include <string>

#include "patchcull/core/error.h"

namespace patchcull::gl {
namespace {

class ConeMethodPass final : public BackpatchPass {
public:
    ConeMethodPass(PassContext& context, BackpatchMethod method) : pass_(context), method_(method) {}
    void run(const PatchBuffers& patches, const CullView& view, const BackpatchOptions&) override {
        if (view.has_eye) pass_.run(patches, method_, view.eye);
    }

private:
    BackpatchConePass pass_;
    BackpatchMethod method_;
};

class PtpMethodPass final : public BackpatchPass {
public:
    explicit PtpMethodPass(PassContext& context) : pass_(context) {}
    void run(const PatchBuffers& patches, const CullView& view, const BackpatchOptions& options) override {
        pass_.run(patches, view.object_to_clip, view.alpha, options.ptp_rule);
    }

private:
    BackpatchPtpPass pass_;
};

std::map<BackpatchMethod, BackpatchPassFactory>& factories() {
    static std::map<BackpatchMethod, BackpatchPassFactory> passes = {
        {BackpatchMethod::tcone,
         [](PassContext& c) -> std::unique_ptr<BackpatchPass> {
             return std::make_unique<ConeMethodPass>(c, BackpatchMethod::tcone);
         }},
        {BackpatchMethod::ncone,
         [](PassContext& c) -> std::unique_ptr<BackpatchPass> {
             return std::make_unique<ConeMethodPass>(c, BackpatchMethod::ncone);
         }},
        {BackpatchMethod::ptp,
         [](PassContext& c) -> std::unique_ptr<BackpatchPass> { return std::make_unique<PtpMethodPass>(c); }},
    };
    return passes;
}

}  // namespace

void register_backpatch_pass(BackpatchMethod id, BackpatchPassFactory factory) {
    backpatch_method_info(id);  // throws for an unregistered id
    if (!factory) throw Error(std::string("register_backpatch_pass: ") + backpatch_method_name(id) + ": no factory");
    factories()[id] = factory;
}

bool has_backpatch_pass(BackpatchMethod id) { return factories().count(id) != 0; }

std::unique_ptr<BackpatchPass> make_backpatch_pass(PassContext& context, BackpatchMethod id) {
    const auto it = factories().find(id);
    if (it == factories().end())
        throw Error(std::string("GL: back-patch method ") + backpatch_method_name(id) + " has no GPU pass");
    return it->second(context);
}

std::vector<BackpatchMethod> gpu_backpatch_methods() {
    std::vector<BackpatchMethod> ids;
    for (BackpatchMethod id : backpatch_method_ids())
        if (has_backpatch_pass(id)) ids.push_back(id);
    return ids;
}

}  // namespace patchcull::gl
