// The scene of a MODEL argument and the cull tests conservative on it (render_support.h).
#include "render_support.h"

#include <cstdint>
#include <string>

#include "commands.h"
#include "patchcull/core/error.h"
#include "patchcull/import/builtin_scenes.h"
#include "patchcull/import/model_loader.h"
#include "patchcull/import/scene_file.h"
#include "patchcull/import/subdivision.h"

namespace patchcull::cli {

Scene load_scene(const std::string& model, const std::string& scheme_text, int split) {
    Scheme scheme = Scheme::acc;
    if (!parse_scheme(scheme_text, scheme)) throw Error("--scheme: unknown scheme '" + scheme_text + "'");
    const bool builtin = model == "default" || model == "city" || model == "building";
    const bool file = model.size() > 5 && model.compare(model.size() - 5, 5, ".json") == 0;
    if ((builtin || file) && split != 0)
        throw Error("--split: not available for a scene (" + model + "); it splits a single model");
    Scene scene = builtin ? make_builtin_scene(model, scheme)
                  : file  ? load_scene_file(model)
                          : make_model_scene(load_model(model, scheme, split));
    for (const LoadedModel& m : scene.models) print_warnings(m.warnings);
    return scene;
}

gl::CullMode applicable_cull_mode(const Scene& scene, gl::CullMode requested, const std::string& command) {
    const std::uint32_t bits = static_cast<std::uint32_t>(requested);
    if ((bits & gl::kCullBackPatch) == 0) return requested;
    for (const LoadedModel& model : scene.models) {
        if (model.closed) continue;
        // Silently: `all` is the default, and the JSON says "backpatch": "off".
        if (requested == gl::CullMode::all) return static_cast<gl::CullMode>(bits & ~gl::kCullBackPatch);
        print_warnings({command + ": " + model.name +
                        " is not a closed solid: back-patch culling may remove patches seen through its openings"});
        return requested;
    }
    return requested;
}

}  // namespace patchcull::cli
