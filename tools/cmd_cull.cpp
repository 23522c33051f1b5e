// `patchcull cull MODEL ... --json`: CPU cull kernels over random views, checked against the
// dense-sample ground truth. Output: {"model","patches","views","view_mode","view_distribution",
// "mean_eye_distance_radii","methods":{name:{cull_rate,
// false_culls, ns_per_patch}}}.
#include <algorithm>
#include <cstdint>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include <CLI/CLI.hpp>

#include "cli_options.h"
#include "commands.h"
#include "patchcull/core/error.h"
#include "patchcull/core/frustum.h"
#include "patchcull/eval/cull_eval.h"
#include "progress.h"

namespace patchcull::cli {
namespace {

// "a,b,c" -> {a, b, c}. An empty item ("a,,b", a trailing comma) or a repeated one is an error:
// either is a typo that would otherwise run a different list than the one meant.
std::vector<std::string> split_methods(const std::string& list) {
    std::vector<std::string> items;
    std::size_t begin = 0;
    while (true) {
        const std::size_t comma = list.find(',', begin);
        const std::string item = list.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin);
        if (item.empty()) throw Error("--methods: empty item in " + quote_input(list));
        if (!is_cull_method(item)) throw Error("--methods: unknown cull method " + quote_input(item));
        if (std::find(items.begin(), items.end(), item) != items.end())
            throw Error("--methods: " + quote_input(item) + " listed twice");
        items.push_back(item);
        if (comma == std::string::npos) return items;
        begin = comma + 1;
    }
}

// "A,B" -> DistanceViews{A, B}: two reals, 1 <= A <= B <= 1000 (cull_eval.h). One line naming the
// flag otherwise.
DistanceViews parse_distance_range(const std::string& text) {
    const std::size_t comma = text.find(',');
    if (comma == std::string::npos || text.find(',', comma + 1) != std::string::npos)
        throw Error("--distance-range: expected A,B (two multiples of the containing distance), got " +
                    quote_input(text));
    DistanceViews d;
    d.min = float(parse_real("--distance-range", text.substr(0, comma), 1.0, 1000.0));
    d.max = float(parse_real("--distance-range", text.substr(comma + 1), 1.0, 1000.0));
    if (d.max < d.min) throw Error("--distance-range: A must not exceed B, got " + quote_input(text));
    return d;
}

}  // namespace

Runner add_cull_command(CLI::App& app) {
    struct State {
        ModelOptions model;
        int views = 1000;
        std::uint64_t seed = 1;
        std::string view_mode = "contain";
        std::string methods = "frustum,frustum-disp";
        std::string distance_range;  // empty: not given
        bool json = false;
    };
    auto state = std::make_shared<State>();
    CLI::App* command = app.add_subcommand("cull", "Run the CPU cull kernels over random views");
    add_model_options(*command, state->model, true);
    add_int_option(*command, "--views", state->views, 1, 10000000, "number of random views");
    add_uint64_option(*command, "--seed", state->seed, UINT64_MAX, "view generator seed");
    add_choice_option(*command, "--view-mode", state->view_mode, {"contain", "free", "distance"},
                      "contain: whole object in view; free: anywhere; distance: whole object, centred, "
                      "45-degree view, eye at --distance-range times the containing distance");
    add_text_option(*command, "--distance-range", state->distance_range,
                    "A,B: with --view-mode distance, eye distance uniform in A..B times the distance at which "
                    "the object's bounding sphere just fits the view (1 <= A <= B <= 1000; default 1,3)");
    add_text_option(*command, "--methods", state->methods, "comma-separated cull methods");
    command->add_flag("--json", state->json, "print one JSON object");
    return [state]() {
        CullEvalOptions options;
        options.views = state->views;
        options.seed = state->seed;
        if (state->view_mode == "distance") {
            options.distance =
                state->distance_range.empty() ? DistanceViews{} : parse_distance_range(state->distance_range);
        } else {
            if (!state->distance_range.empty())
                throw Error("--distance-range: only with --view-mode distance (the view mode is " + state->view_mode +
                            ")");
            parse_view_mode(state->view_mode.c_str(), options.mode);
        }
        options.methods = split_methods(state->methods);
        const LoadedModel model = load_model_from_options(state->model);
        print_warnings(model.warnings);
        // The back-patch truth is one-sided (sampled tangent planes facing the eye): it is the
        // renderer's visibility only for closed solids (README, "What contributes a pixel").
        const bool backpatch_requested =
            std::any_of(options.methods.begin(), options.methods.end(),
                        [](const std::string& m) { return m != "frustum" && m != "frustum-disp"; });
        const DisplacementMap displacement = displacement_from_options(state->model, model);
        // Views done on stderr when it is a terminal (progress.h); nothing with --json or a pipe.
        Progress progress("cull", "views", std::uint64_t(options.views), progress_wanted(state->json));
        options.on_view_done = [&progress](int done) { progress.step(std::uint64_t(done)); };
        const CullEvalResult result =
            evaluate_cull(model.rest, displacement.empty() ? nullptr : &displacement, options);
        progress.finish();
        if (backpatch_requested && !model.closed)  // after the run: an error stays the only line
            print_warnings({"cull: " + model.name +
                            " is not a closed solid: it is drawn two-sided, and the back-patch "
                            "methods' false culls here count only front-facing samples"});
        nlohmann::json out;
        out["model"] = model.name;
        out["patches"] = result.patches;
        out["views"] = result.views;
        out["view_mode"] = state->view_mode;
        // The distribution the views came from (cull_eval.h, camera.cpp), and the mean eye
        // distance in bounding-sphere radii, the quantity that moves the back-patch rates.
        if (options.distance)
            out["view_distribution"] = {{"distance_range", {options.distance->min, options.distance->max}},
                                        {"fovy_degrees", DistanceViews::fovy_degrees},
                                        {"target", "centre"}};
        else if (options.mode == ViewMode::contain)
            out["view_distribution"] = {{"distance_range", {1.05, 2.55}},
                                        {"fovy_degrees", {30, 70}},
                                        {"target", "off centre, object kept in view"}};
        else
            out["view_distribution"] = {{"eye", "inside the object's box or the box enlarged 3x"},
                                        {"fovy_degrees", {20, 90}},
                                        {"target", "random direction"}};
        out["mean_eye_distance_radii"] = result.mean_eye_distance_radii;
        out["seed"] = state->seed;
        out["simd"] = simd_target_name();
        out["methods"] = nlohmann::json::object();
        for (const CullMethodResult& r : result.methods)
            out["methods"][r.name] = {
                {"cull_rate", r.cull_rate}, {"false_culls", r.false_culls}, {"ns_per_patch", r.ns_per_patch}};
        if (state->json) {
            std::cout << out.dump() << "\n";
        } else {
            std::cout << model.name << ": " << result.patches << " patches, " << result.views << " " << state->view_mode
                      << " views, eye " << result.mean_eye_distance_radii << " radii away on average\n";
            for (const CullMethodResult& r : result.methods)
                std::cout << "  " << r.name << ": cull rate " << 100.0 * r.cull_rate << "%, false culls "
                          << r.false_culls << ", " << r.ns_per_patch << " ns/patch\n";
        }
        return 0;
    };
}

}  // namespace patchcull::cli
