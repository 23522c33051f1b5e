// Model loading by name for tools (patchcull/import/model_loader.h).
#include "patchcull/import/model_loader.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "patchcull/core/error.h"
#include "patchcull/core/teapot.h"
#include "patchcull/import/obj.h"

namespace patchcull {
namespace {

void split_in_place(PatchFrame& frame, int levels, const std::string& name) {
    if (levels < 0 || levels > 4) throw Error(name + ": --split must be between 0 and 4");
    if (levels == 0) return;
    // evaluate_patches() splits subdivision models; the teapot is split through a one-patch-per-
    // control-point stencil model so both share one split path.
    SubdivisionModel model;
    model.name = name;
    std::vector<Vec3> points;
    for (std::size_t p = 0; p < frame.patches.size(); ++p)
        for (int k = 0; k < kPatchPoints; ++k) {
            points.push_back(cartesian(frame.patches[p].cp[k]));
            model.patch_points.add_row({{static_cast<std::uint32_t>(points.size() - 1), 1.0f}});
        }
    model.patches = frame.info;
    evaluate_patches(model, points, levels, frame);
}

}  // namespace

LoadedModel load_model(const std::string& spec, Scheme scheme, int split_levels) {
    LoadedModel model;
    model.name = spec;
    model.split_levels = split_levels;
    if (split_levels < 0 || split_levels > 4)
        throw Error("--split: must be between 0 and 4, got " + std::to_string(split_levels));
    if (spec == "teapot") {
        model.rest.patches = teapot_patches();
        model.rest.info.assign(model.rest.patches.size(), PatchInfo{});
        for (std::size_t p = 0; p < model.rest.info.size(); ++p)
            model.rest.info[p].base_face = static_cast<std::uint32_t>(p);
        split_in_place(model.rest, split_levels, spec);
        return model;
    }
    ControlMesh mesh = load_obj(resolve_model_path(spec));
    // Orientation from geometry, shell by shell (mesh.h): inside-out shells are reversed, a flat or
    // undecided mesh is two-sided.
    const SurfaceOrientation orientation = orient_outward(mesh);
    const Bounds bounds = compute_bounds(mesh.positions);
    double diagonal_squared = 0;
    for (int axis = 0; axis < 3; ++axis) {
        const double side = double((&bounds.max.x)[axis]) - double((&bounds.min.x)[axis]);
        diagonal_squared += side * side;
    }
    if (!(diagonal_squared >= kMinMeshDiagonal * kMinMeshDiagonal)) {
        char text[32];
        std::snprintf(text, sizeof text, "%.3g", std::sqrt(diagonal_squared));
        throw Error(spec + ": the mesh is " + text + " units across; patchcull takes meshes of at least " +
                    "1e-06 units across (the kernels work in float)");
    }
    for (int axis = 0; axis < 3; ++axis) {
        const double extent = double((&bounds.max.x)[axis]) - double((&bounds.min.x)[axis]);
        if (!(extent <= kMaxMeshExtent)) {
            char text[32];
            std::snprintf(text, sizeof text, "%.3g", extent);
            throw Error(spec + ": the mesh is " + text + " units across; patchcull takes meshes up to " +
                        "2e+11 units across (the kernels work in float)");
        }
    }
    model.warnings = mesh.warnings;
    model.subdiv = build_model(mesh, scheme);
    model.origin = mesh.origin;
    for (const std::string& w : model.subdiv->mesh.warnings)
        if (std::find(model.warnings.begin(), model.warnings.end(), w) == model.warnings.end())
            model.warnings.push_back(w);
    evaluate_patches(*model.subdiv, model.subdiv->mesh.positions, split_levels, model.rest);
    // A hole (OBJ "t hole") opens the surface even where the control mesh is closed: through it the
    // inside shows, so the model is drawn two-sided and back-patch culling is off.
    model.closed = orientation == SurfaceOrientation::outward && mesh.holes.empty();
    return model;
}

void evaluate_frame(const LoadedModel& model, const std::vector<Vec3>& positions, PatchFrame& out) {
    if (!model.subdiv) {
        out = model.rest;
        return;
    }
    evaluate_patches(*model.subdiv, positions, model.split_levels, out);
}

std::vector<DisplacementRange> displacement_ranges(const PatchFrame& frame, const DisplacementMap* map) {
    std::vector<DisplacementRange> ranges(frame.patches.size());
    if (!map || map->empty()) return ranges;
    for (std::size_t p = 0; p < ranges.size(); ++p) ranges[p] = map->patch_range(frame.info[p].uv);
    return ranges;
}

Bounds patch_bounds(const PatchFrame& frame) {
    // compute_bounds over the control points in the same order, without copying them (a 1M-quad
    // mesh's 16M points were 0.19 GB of preprocessing's peak; docs/PERFORMANCE.md).
    if (frame.patches.empty()) return Bounds{};
    const Vec3 first = cartesian(frame.patches[0].cp[0]);
    Bounds b{first, first};
    for (const BezierPatch& patch : frame.patches)
        for (const Vec4& c : patch.cp) {
            const Vec3 p = cartesian(c);
            b.min = {std::min(b.min.x, p.x), std::min(b.min.y, p.y), std::min(b.min.z, p.z)};
            b.max = {std::max(b.max.x, p.x), std::max(b.max.y, p.y), std::max(b.max.z, p.z)};
        }
    return b;
}

namespace {
std::atomic<const char*> package_data_dir{nullptr};
}  // namespace

bool detail::register_package_data_dir(const char* dir) {
    if (dir && *dir) package_data_dir.store(dir, std::memory_order_relaxed);
    return true;
}

std::string shipped_model_path(const std::string& file_name) {
    const char* dir = std::getenv("PATCHCULL_DATA_DIR");
    if (dir && *dir) return std::string(dir) + "/models/" + file_name;  // empty: unset
    if (const char* package = package_data_dir.load(std::memory_order_relaxed))
        return std::string(package) + "/models/" + file_name;
    // The source tree's data/ while it exists (builds and tests); else the share/patchcull beside
    // the running program's prefix (an installed CLI, wherever the prefix was moved); else the
    // configured install prefix's, so an installed library finds its models after the source is gone.
    std::string source = std::string(PATCHCULL_DATA_DIR) + "/models/" + file_name;
    std::error_code error;
    if (std::filesystem::exists(source, error)) return source;
    const std::filesystem::path program = std::filesystem::read_symlink("/proc/self/exe", error);
    if (!error) {
        std::string beside = (program.parent_path().parent_path() / "share/patchcull/models" / file_name).string();
        if (std::filesystem::exists(beside, error)) return beside;
    }
    const std::string installed = std::string(PATCHCULL_INSTALLED_DATA_DIR) + "/models/" + file_name;
    return std::filesystem::exists(installed, error) ? installed : source;
}

std::string resolve_model_path(const std::string& spec) {
    std::error_code error;
    if (spec.empty() || std::filesystem::exists(spec, error)) return spec;
    for (const char* name : kShippedModels)
        if (spec == name) return shipped_model_path(spec + ".obj");
    return spec;
}

}  // namespace patchcull
