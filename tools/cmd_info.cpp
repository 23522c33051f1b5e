// `patchcull info MODEL [--scheme acc|osd] [--split N] --json`: patch counts of a model.
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include <CLI/CLI.hpp>

#include "commands.h"

namespace patchcull::cli {

Runner add_info_command(CLI::App& app) {
    struct State {
        ModelOptions model;
        bool json = false;
    };
    auto state = std::make_shared<State>();
    CLI::App* command = app.add_subcommand("info", "Print a model's patch counts");
    add_model_options(*command, state->model, false);
    command->add_flag("--json", state->json, "print one JSON object");
    return [state]() {
        const LoadedModel model = load_model_from_options(state->model);
        print_warnings(model.warnings);
        std::size_t extraordinary = 0;
        for (const PatchInfo& p : model.rest.info) extraordinary += p.extraordinary ? 1 : 0;
        const Bounds b = patch_bounds(model.rest);
        nlohmann::json out;
        out["model"] = model.name;
        out["scheme"] = model.subdiv ? scheme_name(model.subdiv->scheme) : "bezier";
        out["split"] = model.split_levels;
        out["patches"] = model.rest.patches.size();
        out["extraordinary_patches"] = extraordinary;
        out["tangent_patches"] = model.rest.tangents.size();
        if (model.subdiv) {
            out["control_vertices"] = model.subdiv->mesh.positions.size();
            out["faces"] = model.subdiv->mesh.face_count();
        }
        // World (file) coordinates: the patches are relative to model.origin (mesh.h), added in double.
        const DVec3 o = model.origin, lo = o + to_double(b.min), hi = o + to_double(b.max);
        out["origin"] = {o.x, o.y, o.z};
        out["bounds"] = {{"min", {lo.x, lo.y, lo.z}}, {"max", {hi.x, hi.y, hi.z}}};
        out["warnings"] = model.warnings;
        if (state->json) {
            std::cout << out.dump() << "\n";
        } else {
            std::cout << "model                 " << model.name << "\n"
                      << "scheme                " << out["scheme"].get<std::string>() << "\n"
                      << "patches               " << model.rest.patches.size() << "\n"
                      << "extraordinary patches " << extraordinary << "\n";
        }
        return 0;
    };
}

}  // namespace patchcull::cli
