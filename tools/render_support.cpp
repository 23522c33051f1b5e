// Helpers shared by the CLI's GPU commands (render_support.h).
#include "render_support.h"

#include "patchcull/import/scene_file.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>

#include "cli_options.h"
#include "commands.h"
#include "patchcull/core/error.h"
#include "patchcull/import/image.h"
#include "patchcull/gl/gl_verification.h"

namespace patchcull::cli {

gl::RenderParams render_params(const Camera& camera, int width, int height, int tess_level, bool one_sided) {
    gl::RenderParams params;
    params.discard_back_facing = one_sided;
    params.view = camera.view();
    params.projection = camera.projection();
    params.depth = camera.depth;
    params.width = width;
    params.height = height;
    params.tess_level = tess_level;
    return params;
}

ReferenceFrame render_reference(gl::PatchRenderer& renderer, const gl::RenderParams& params) {
    gl::RenderParams unculled = params;
    unculled.use_cull_flags = false;
    renderer.finish();
    const auto start = std::chrono::steady_clock::now();
    renderer.render(unculled);
    renderer.finish();
    ReferenceFrame reference;
    reference.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    reference.capture.ids = renderer.read_ids();
    reference.capture.depth = renderer.read_depth();
    reference.capture.patches = renderer.mark_front_patches(unculled);
    return reference;
}

gl::FrameCapture capture_culled_frame(const gl::PatchRenderer& renderer) {
    return {renderer.read_ids(), renderer.read_depth(), renderer.read_drawn_patches()};
}

gl::FrameComparison compare_with_reference(const gl::PatchRenderer& renderer, const ReferenceFrame& reference) {
    return gl::compare_frames(reference.capture, capture_culled_frame(renderer));
}

bool scene_is_one_sided(const Scene& scene) {
    return std::all_of(scene.models.begin(), scene.models.end(), [](const LoadedModel& m) { return m.closed; });
}

gl::PatchAttributes pose_attributes(const ScenePoser& poser) {
    gl::PatchAttributes attributes;
    attributes.tangent_index = poser.tangent_index();
    attributes.tangents = poser.tangents();
    attributes.depth = poser.depth();
    if (!poser.displacement_ranges().empty()) {
        attributes.texcoords = poser.texcoords();
        attributes.displacement_ranges = poser.displacement_ranges();
    }
    return attributes;
}

PoseWhere parse_pose_where(const std::string& flag, const std::string& text) {
    if (text == "cpu") return PoseWhere::cpu;
    if (text == "gpu") return PoseWhere::gpu;
    throw Error(flag + ": unknown value '" + text + "' (cpu or gpu)");
}

const char* pose_where_name(PoseWhere where) { return where == PoseWhere::gpu ? "gpu" : "cpu"; }

struct FramePoser::Gpu {
    explicit Gpu(const gl::GlContext& context) : poser(context) {}
    gl::StencilPoser poser;
};

namespace {

gl::StencilTableView table_view(const PointStencils& s) {
    return {s.offsets.data(), s.rows(), s.indices.data(), s.weights.data()};
}

}  // namespace

FramePoser::FramePoser(const gl::GlContext& context, ScenePoser& poser, gl::PatchRenderer& renderer, PoseWhere where,
                       bool cpu_patches)
    : poser_(&poser), renderer_(&renderer), where_(where), cpu_patches_(cpu_patches) {
    if (where != PoseWhere::gpu) return;
    const std::vector<PoseModelTables>* tables_or_null = nullptr;
    try {
        tables_or_null = &poser.gpu_tables();
    } catch (const Error& e) {
        throw Error(std::string("--pose gpu: ") + e.what());  // the flag that asked for it
    }
    const std::vector<PoseModelTables>& tables = *tables_or_null;
    std::vector<gl::PosingModel> models;
    for (const PoseModelTables& t : tables)
        models.push_back({table_view(*t.patch_points), table_view(*t.tangent_points), t.tangent_index, t.vertex_count});
    std::vector<std::uint32_t> instance_models;
    for (const SceneInstance& instance : poser.scene().instances)
        instance_models.push_back(static_cast<std::uint32_t>(instance.model));
    gpu_ = std::make_unique<Gpu>(context);
    gpu_->poser.set_tables(models, instance_models);
}

FramePoser::~FramePoser() = default;

const std::vector<BezierPatch>* FramePoser::pose(float time_seconds) {
    using clock = std::chrono::steady_clock;
    const auto start = clock::now();
    cost_ = {};
    cost_.where = where_;
    const std::vector<BezierPatch>* patches = nullptr;
    if (first_ || where_ == PoseWhere::cpu || cpu_patches_) {
        patches = &poser_->pose(time_seconds);
        cost_.cpu_patches = true;
    }
    if (first_) {
        renderer_->set_patches(*patches, pose_attributes(*poser_));
        cost_.bytes_uploaded += renderer_->last_upload_bytes();
    } else if (where_ == PoseWhere::cpu) {
        renderer_->update_patches(*patches, pose_attributes(*poser_));
        cost_.bytes_uploaded += renderer_->last_upload_bytes();
    }
    if (where_ == PoseWhere::gpu) {
        // Frame 0 too: its patches are then the GPU's (equal to the upload, which brought the
        // attributes).
        const auto meshes_start = clock::now();
        const PoseMeshes& meshes = poser_->gpu_meshes(time_seconds);
        cost_.meshes_ms = std::chrono::duration<double, std::milli>(clock::now() - meshes_start).count();
        instances_.resize(meshes.first_vertex.size());
        for (std::size_t i = 0; i < instances_.size(); ++i)
            instances_[i] = {meshes.first_vertex[i], meshes.to_world[i], meshes.mirrored[i] != 0};
        gpu_->poser.pose(meshes.vertices, instances_, renderer_->patch_buffer(), renderer_->tangent_buffer());
        cost_.bytes_uploaded += gpu_->poser.last_upload_bytes();
    }
    first_ = false;
    cost_.cpu_ms = std::chrono::duration<double, std::milli>(clock::now() - start).count();
    renderer_->finish();
    cost_.done_ms = std::chrono::duration<double, std::milli>(clock::now() - start).count();
    return patches;
}

Scene load_scene(const std::string& model, const std::string& scheme_text, int split) {
    Scheme scheme = Scheme::acc;
    if (!parse_scheme(scheme_text, scheme)) throw Error("--scheme: unknown scheme '" + scheme_text + "'");
    const bool builtin = model == "default" || model == "city" || model == "building";
    const bool file = model.size() > 5 && model.compare(model.size() - 5, 5, ".json") == 0;
    if ((builtin || file) && split != 0)
        throw Error("--split: not available for a scene (" + model + "); it splits a single model");
    const Scene scene = builtin ? make_builtin_scene(model, scheme)
                        : file  ? load_scene_file(model)
                                : make_model_scene(load_model(model, scheme, split));
    for (const LoadedModel& m : scene.models)
        print_warnings(m.warnings);
    return scene;
}

void upload_scene_occluders(gl::PatchRenderer& renderer, const Scene& scene) {
    std::vector<gl::TriangleSpan> one_sided;
    for (const EnvironmentObject& e : scene.environment)
        if (e.one_sided && e.triangle_count) one_sided.push_back({e.first_triangle, e.triangle_count});
    renderer.set_occluders(scene.occluder_vertices, scene.occluder_indices, one_sided);
}

std::vector<SceneObject> scene_objects(const Scene& scene) {
    std::vector<SceneObject> objects;
    std::vector<std::size_t> copies(scene.models.size(), 0);
    std::size_t first = 0;
    for (const SceneInstance& instance : scene.instances) {
        const LoadedModel& model = scene.models.at(instance.model);
        SceneObject o;
        // The instance's own name (unique: every scene builder and the scene file reader set
        // it); else LoadedModel::name (the OBJ path or "teapot") without the extension.
        const std::size_t copy = copies[instance.model]++;
        o.name = !instance.name.empty() ? instance.name
                                        : std::filesystem::path(model.name).stem().string() + "#" + std::to_string(copy);
        o.range.first = first;
        o.range.count = model.rest.patches.size();
        o.range.cull = true;
        first += o.range.count;
        objects.push_back(std::move(o));
    }
    return objects;
}

gl::CullMode applicable_cull_mode(const Scene& scene, gl::CullMode requested, const std::string& command) {
    const std::uint32_t bits = static_cast<std::uint32_t>(requested);
    if ((bits & gl::kFlagBackPatch) == 0) return requested;
    for (const LoadedModel& model : scene.models) {
        if (model.closed) continue;
        // Silently: `all` is the default, and the JSON says "backpatch": "off".
        if (requested == gl::CullMode::all) return static_cast<gl::CullMode>(bits & ~gl::kFlagBackPatch);
        print_warnings({command + ": " + model.name +
                        " is not a closed solid: back-patch culling may remove patches seen through its openings"});
        return requested;
    }
    return requested;
}

void add_tess_options(CLI::App& command, TessOptions& options) {
    add_choice_option(command, "--tess-mode", options.mode, {"uniform", "adaptive"},
                      "uniform: --tess everywhere; adaptive: by distance (Niessner & Loop §6.3), --tess the maximum");
    CLI::Option* distance = command.add_option_function<std::string>(
        "--tess-distance",
        [&options](const std::string& text) {
            const float d = static_cast<float>(parse_real("--tess-distance", text, 0, 1e9));
            // > 0 after rounding to float as well (1e-50 parses but is 0 as a float).
            if (!(d > 0)) throw Error("--tess-distance: expected a distance > 0, got " + quote_input(text));
            options.distance = d;
        },
        "adaptive: distance from the eye that gets the full --tess level (default: the camera path's eye-to-target "
        "distance)");
    distance->type_name("REAL >0");
}

void add_displace_options(CLI::App& command, DisplaceOptions& options) {
    CLI::Option* displace = add_text_option(
        command, "--displace", options.displace,
        "displacement map of every object: 'none', 'procedural' or a PNG height map (default: the scene's own; the "
        "default scene displaces its MonsterFrogs)");
    add_float_option(command, "--displace-scale", options.scale, 0, 1,
                     "displacement of a full height step, in character heights (default 0.02)")
        ->needs(displace);
    add_choice_option(command, "--bound", options.bound, {"caf", "oobb"},
                      "bound of displaced patches (Niessner & Loop §4.2: camera-aligned frustum, or "
                      "object-oriented box)");
    add_choice_option(command, "--cone", options.cone, {"full", "acon", "con"},
                      "normal cone of displaced patches' bounds (full, ACoN, CoN)");
}

void apply_displace_options(const DisplaceOptions& options, Scene& scene) {
    if (options.displace.empty()) return;
    if (options.displace == "none") {
        scene.displacement = {};
        scene.displacement_name = "none";
        for (SceneInstance& instance : scene.instances) instance.displaced = false;
        return;
    }
    const float scale = options.scale >= 0 ? options.scale : 0.02f;
    if (!(scale > 0)) throw Error("--displace-scale: must be > 0 with --displace " + quote_input(options.displace));
    scene.displacement = options.displace == "procedural" ? make_procedural_displacement(512, scale)
                                                         : load_displacement_png(options.displace, scale);
    scene.displacement_name = options.displace;
    for (SceneInstance& instance : scene.instances) instance.displaced = true;
}

std::size_t displaced_patch_count(const ScenePoser& poser) {
    const std::vector<DisplacementRange>& ranges = poser.displacement_ranges();
    return static_cast<std::size_t>(std::count_if(ranges.begin(), ranges.end(), [](const DisplacementRange& r) {
        return r.d_min != 0 || r.d_max != 0;
    }));
}

DisplacedBoundKind displace_bound(const DisplaceOptions& options) {
    return options.bound == "oobb" ? DisplacedBoundKind::oobb : DisplacedBoundKind::caf;
}

NormalConeKind displace_cone(const DisplaceOptions& options) {
    if (options.cone == "full") return NormalConeKind::full;
    return options.cone == "con" ? NormalConeKind::con : NormalConeKind::acon;
}

float camera_path_eye_distance(const CameraPath& path) { return std::hypot(path.distance, path.height); }

TessMode resolve_tess_mode(const TessOptions& options, const CameraPath& path) {
    TessMode mode;
    mode.adaptive = options.mode == "adaptive";
    if (options.distance > 0 && !mode.adaptive)
        throw Error("--tess-distance: needs --tess-mode adaptive (uniform tessellation has no reference distance)");
    mode.reference_distance = options.distance > 0 ? options.distance : camera_path_eye_distance(path);
    return mode;
}

void apply_tess_mode(const TessMode& mode, gl::RenderParams& params) {
    params.adaptive_tess = mode.adaptive;
    params.tess_reference_distance = mode.reference_distance;
}

std::vector<std::string> cull_mode_choices() {
    std::vector<std::string> names;
    for (gl::CullMode m : gl::kCullModes) names.emplace_back(gl::cull_mode_name(m));
    names.emplace_back("auto");
    return names;
}

std::vector<std::string> backpatch_method_choices() {
    std::vector<std::string> names;
    for (gl::BackpatchMethod m : gl::kBackpatchMethods) names.emplace_back(gl::backpatch_method_name(m));
    return names;
}

std::string names_text(const std::vector<std::string>& names) {
    std::string text;
    for (std::size_t i = 0; i < names.size(); ++i) {
        if (i > 0) text += i + 1 == names.size() ? " or " : ", ";
        text += names[i];
    }
    return text;
}

gl::BackpatchMethod parse_backpatch_method(const std::string& flag, const std::string& text) {
    gl::BackpatchMethod method = gl::BackpatchMethod::tcone;
    if (!gl::parse_backpatch_method(text.c_str(), method))
        throw Error(flag + ": unknown back-patch method '" + text + "' (" + names_text(backpatch_method_choices()) + ")");
    return method;
}

gl::CullMode parse_cull_mode_option(const std::string& flag, const std::string& text) {
    gl::CullMode mode = gl::CullMode::none;
    if (!gl::parse_cull_mode(text.c_str(), mode)) {
        std::vector<std::string> names = cull_mode_choices();
        names.pop_back();  // "auto" is the tools' own, decided before a mode is parsed
        throw Error(flag + ": unknown cull mode '" + text + "' (" + names_text(names) + ")");
    }
    return mode;
}

void parse_size(const std::string& flag, const std::string& text, int& width, int& height) {
    const std::size_t x = text.find('x');
    auto number = [&](const std::string& part, int& out) {
        if (part.empty() || part.size() > 5 || part.find_first_not_of("0123456789") != std::string::npos) return false;
        out = std::stoi(part);
        return out >= 1 && out <= 8192;
    };
    if (x == std::string::npos || !number(text.substr(0, x), width) || !number(text.substr(x + 1), height))
        throw Error(flag + ": expected WIDTHxHEIGHT with each in 1..8192, got '" + text + "'");
}

}  // namespace patchcull::cli
