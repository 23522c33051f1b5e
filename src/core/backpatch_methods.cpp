// The back-patch method registry (patchcull/core/backpatch_methods.h): the built-in entries
// (Loop, Niessner & Eisenacher, "Effective Back-Patch Culling for Hardware Tessellation") and
// registration.
#include "patchcull/core/backpatch_methods.h"

#include <algorithm>

#include "patchcull/core/error.h"

namespace patchcull {
namespace {

void no_cull(const PatchBatchView& patches, std::uint8_t* culled) {
    std::fill_n(culled, patches.count, std::uint8_t{0});
}

void tcone_scalar(const PatchBatchView& p, const CullView& v, const BackpatchOptions&, std::uint8_t* culled) {
    if (v.has_eye)
        cull_tcone_scalar(p, v.eye, culled);
    else
        no_cull(p, culled);
}
void tcone_simd(const PatchBatchView& p, const CullView& v, const BackpatchOptions&, std::uint8_t* culled) {
    if (v.has_eye)
        cull_tcone_simd(p, v.eye, culled);
    else
        no_cull(p, culled);
}
void ncone_scalar(const PatchBatchView& p, const CullView& v, const BackpatchOptions&, std::uint8_t* culled) {
    if (v.has_eye)
        cull_ncone_scalar(p, v.eye, culled);
    else
        no_cull(p, culled);
}
void ncone_simd(const PatchBatchView& p, const CullView& v, const BackpatchOptions&, std::uint8_t* culled) {
    if (v.has_eye)
        cull_ncone_simd(p, v.eye, culled);
    else
        no_cull(p, culled);
}
void ptp_scalar(const PatchBatchView& p, const CullView& v, const BackpatchOptions& o, std::uint8_t* culled) {
    cull_ptp_scalar(p, v.object_to_clip, v.alpha, o.ptp_rule, culled);
}
void ptp_simd(const PatchBatchView& p, const CullView& v, const BackpatchOptions& o, std::uint8_t* culled) {
    cull_ptp_simd(p, v.object_to_clip, v.alpha, o.ptp_rule, culled);
}

std::vector<BackpatchMethodInfo>& registry() {
    static std::vector<BackpatchMethodInfo> methods = {
        {"tcone", "cone of normals from the tangent and bitangent cones", tcone_scalar, tcone_simd, true},
        {"ncone", "cone bounding the normal patch", ncone_scalar, ncone_simd, true},
        {"ptp", "parametric tangent plane: 8x8 control planes in clip space", ptp_scalar, ptp_simd, false},
    };
    return methods;
}

}  // namespace

const std::vector<BackpatchMethodInfo>& backpatch_methods() { return registry(); }

const BackpatchMethodInfo& backpatch_method_info(BackpatchMethod id) {
    const auto k = static_cast<std::size_t>(id);
    if (k >= registry().size()) throw Error("back-patch method " + std::to_string(k) + " is not registered");
    return registry()[k];
}

const char* backpatch_method_name(BackpatchMethod id) {
    const auto k = static_cast<std::size_t>(id);
    return k < registry().size() ? registry()[k].name.c_str() : "?";
}

bool parse_backpatch_method(const char* name, BackpatchMethod& id) {
    if (!name) return false;
    for (std::size_t k = 0; k < registry().size(); ++k)
        if (registry()[k].name == name) {
            id = static_cast<BackpatchMethod>(k);
            return true;
        }
    return false;
}

std::vector<BackpatchMethod> backpatch_method_ids() {
    std::vector<BackpatchMethod> ids;
    for (std::size_t k = 0; k < registry().size(); ++k) ids.push_back(static_cast<BackpatchMethod>(k));
    return ids;
}

BackpatchMethod register_backpatch_method(BackpatchMethodInfo info) {
    if (info.name.empty()) throw Error("register_backpatch_method: the name is empty");
    if (!info.scalar) throw Error("register_backpatch_method: " + info.name + " has no scalar kernel");
    BackpatchMethod existing;
    if (parse_backpatch_method(info.name.c_str(), existing))
        throw Error("register_backpatch_method: " + info.name + " is already registered");
    registry().push_back(std::move(info));
    return static_cast<BackpatchMethod>(registry().size() - 1);
}

void cull_backpatch(BackpatchMethod id, const PatchBatchView& patches, const CullView& view,
                    const BackpatchOptions& options, std::uint8_t* culled) {
    const BackpatchMethodInfo& m = backpatch_method_info(id);
    (m.simd ? m.simd : m.scalar)(patches, view, options, culled);
}

}  // namespace patchcull
