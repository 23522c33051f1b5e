// `patchcull cull MODEL ... --json`: CPU cull kernels over random views, checked against the
// dense-sample ground truth. Output: {"model","patches","views","methods":{name:{cull_rate,
// false_culls, ns_per_patch}}}.
#include <iostream>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "patchcull/cull_eval.h"
#include "patchcull/error.h"
#include "patchcull/frustum.h"

namespace patchcull::cli {
namespace {

std::vector<std::string> split_list(const std::string& list) {
    std::vector<std::string> items;
    std::stringstream in(list);
    std::string item;
    while (std::getline(in, item, ','))
        if (!item.empty()) items.push_back(item);
    return items;
}

}  // namespace

Runner add_cull_command(CLI::App& app) {
    struct State {
        ModelOptions model;
        int views = 1000;
        std::uint64_t seed = 1;
        std::string view_mode = "contain";
        std::string methods = "frustum,frustum-disp";
        bool json = false;
    };
    auto state = std::make_shared<State>();
    CLI::App* command = app.add_subcommand("cull", "Run the CPU cull kernels over random views");
    add_model_options(*command, state->model, true);
    command->add_option("--views", state->views, "number of random views")->check(CLI::Range(0, 10000000));
    command->add_option("--seed", state->seed, "view generator seed");
    command->add_option("--view-mode", state->view_mode, "contain: whole object in view; free: anywhere")
        ->check(CLI::IsMember({"contain", "free"}));
    command->add_option("--methods", state->methods, "comma-separated cull methods");
    command->add_flag("--json", state->json, "print one JSON object");
    return [state]() {
        CullEvalOptions options;
        options.views = state->views;
        options.seed = state->seed;
        parse_view_mode(state->view_mode.c_str(), options.mode);
        options.methods = split_list(state->methods);
        if (options.methods.empty()) throw Error("--methods: empty list");
        for (const std::string& m : options.methods)
            if (!is_cull_method(m)) throw Error("--methods: unknown cull method '" + m + "'");
        const LoadedModel model = load_model_from_options(state->model);
        for (const std::string& w : model.warnings) std::cerr << "patchcull: warning: " << w << "\n";
        const DisplacementMap displacement = displacement_from_options(state->model, model);
        const CullEvalResult result = evaluate_cull(model.rest, displacement.empty() ? nullptr : &displacement, options);
        nlohmann::json out;
        out["model"] = model.name;
        out["patches"] = result.patches;
        out["views"] = result.views;
        out["view_mode"] = state->view_mode;
        out["seed"] = state->seed;
        out["simd"] = simd_target_name();
        out["methods"] = nlohmann::json::object();
        for (const CullMethodResult& r : result.methods)
            out["methods"][r.name] = {{"cull_rate", r.cull_rate}, {"false_culls", r.false_culls},
                                      {"ns_per_patch", r.ns_per_patch}};
        if (state->json) {
            std::cout << out.dump() << "\n";
        } else {
            std::cout << model.name << ": " << result.patches << " patches, " << result.views << " "
                      << state->view_mode << " views\n";
            for (const CullMethodResult& r : result.methods)
                std::cout << "  " << r.name << ": cull rate " << 100.0 * r.cull_rate << "%, false culls "
                          << r.false_culls << ", " << r.ns_per_patch << " ns/patch\n";
        }
        return 0;
    };
}

}  // namespace patchcull::cli
