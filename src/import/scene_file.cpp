// Scene files (patchcull/import/scene_file.h; the format: docs/SCENE_FORMAT.md): the reader.
// What a scene reaches over a run (check_scene_motion, place_scene_at_first_camera):
// scene_placement.cpp.
//
// The reader walks the parsed JSON with the JSON path of every value at hand, so each check can
// name it. Objects are checked key by key against the keys their kind allows (unknown keys are
// errors: a misspelt "displaced" must not silently leave an object undisplaced); duplicate keys,
// which nlohmann-json would resolve silently (the last one wins), are caught while parsing by a
// parser callback that keeps the path of the container being parsed.
#include "patchcull/import/scene_file.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <map>
#include <set>
#include <utility>

#include <nlohmann/json.hpp>

#include "input_file.h"
#include "number_text.h"
#include "patchcull/core/error.h"
#include "patchcull/import/image.h"
#include "patchcull/import/obj.h"
#include "scene_builder.h"

namespace patchcull {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using namespace detail;

// A range bound: as number_text, the scene coordinate limit in full (536870912, not 5.36871e+08).
std::string bound_text(double v) {
    if (std::fabs(v) != kMaxSceneCoordinate) return number_text(v);
    char text[32];
    std::snprintf(text, sizeof text, "%.0f", v);
    return text;
}

std::string join(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }
std::string index(const std::string& path, std::size_t i) { return path + "[" + std::to_string(i) + "]"; }

// Throws "file: path: what" (or "file: what" at the root).
struct Reader {
    std::string file;
    fs::path dir;

    [[noreturn]] void fail(const std::string& path, const std::string& what) const {
        // Names from the file (model and map paths inside nested loaders' messages) are
        // untrusted: the whole line goes through printable_line.
        throw Error(printable_line(file + ": " + (path.empty() ? "" : path + ": ") + what));
    }

    std::string resolve(const std::string& p) const {
        const fs::path q(p);
        return q.is_absolute() || dir.empty() ? p : (dir / q).lexically_normal().string();
    }

    const json& object(const json& j, const std::string& path, std::initializer_list<const char*> allowed) const {
        if (!j.is_object()) fail(path, "expected an object");
        for (auto it = j.begin(); it != j.end(); ++it)
            if (std::none_of(allowed.begin(), allowed.end(), [&](const char* k) { return it.key() == k; })) {
                std::string keys;
                for (const char* k : allowed) keys += std::string(keys.empty() ? "" : ", ") + k;
                fail(path, "unknown key " + quote_input(it.key()) + " (expected " + keys + ")");
            }
        return j;
    }

    const json* find(const json& obj, const char* key) const {
        const auto it = obj.find(key);
        return it == obj.end() ? nullptr : &*it;
    }

    const json& require(const json& obj, const std::string& path, const char* key) const {
        const json* j = find(obj, key);
        if (!j) fail(path, std::string("missing required key '") + key + "'");
        return *j;
    }

    // A number in [lo, hi] that fits a float (lo_open: > lo).
    float number(const json& j, const std::string& path, double lo, double hi, bool lo_open = false) const {
        if (!j.is_number()) fail(path, "expected a number");
        const double v = j.get<double>();
        if (!std::isfinite(v)) fail(path, "expected a finite number");
        if (std::fabs(v) > double(FLT_MAX)) fail(path, "number " + number_text(v) + " does not fit a float");
        if (!(lo_open ? v > lo : v >= lo) || !(v <= hi))
            fail(path, "expected a number " + std::string(lo_open ? "> " : ">= ") + bound_text(lo) +
                           (hi < DBL_MAX ? " and <= " + bound_text(hi) : "") + ", got " + number_text(v));
        return static_cast<float>(v);
    }

    float number_or(const json& obj, const std::string& path, const char* key, float fallback, double lo, double hi,
                    bool lo_open = false) const {
        const json* j = find(obj, key);
        return j ? number(*j, join(path, key), lo, hi, lo_open) : fallback;
    }

    long long integer(const json& j, const std::string& path, long long lo, long long hi) const {
        if (!j.is_number_integer()) fail(path, "expected an integer");
        // Non-negative integers are stored unsigned (up to 2^64 - 1): compare before converting.
        const bool in_range = j.is_number_unsigned()
                                  ? j.get<unsigned long long>() <= static_cast<unsigned long long>(hi) &&
                                        static_cast<long long>(j.get<unsigned long long>()) >= lo
                                  : j.get<long long>() >= lo && j.get<long long>() <= hi;
        if (!in_range) fail(path, "expected an integer between " + std::to_string(lo) + " and " + std::to_string(hi));
        return j.get<long long>();
    }

    bool boolean(const json& j, const std::string& path) const {
        if (!j.is_boolean()) fail(path, "expected true or false");
        return j.get<bool>();
    }

    bool boolean_or(const json& obj, const std::string& path, const char* key, bool fallback) const {
        const json* j = find(obj, key);
        return j ? boolean(*j, join(path, key)) : fallback;
    }

    std::string string(const json& j, const std::string& path) const {
        if (!j.is_string()) fail(path, "expected a string");
        std::string s = j.get<std::string>();
        if (s.empty()) fail(path, "expected a non-empty string");
        return s;
    }

    // A finite number in [lo, hi] kept in double (a world position).
    double real(const json& j, const std::string& path, double lo, double hi) const {
        number(j, path, lo, hi);  // the same checks and messages
        return j.get<double>();
    }

    // 3 finite floats within `limit` of 0 (offsets, directions, and what is kept in float world
    // coordinates: cells and portals).
    Vec3 vec3(const json& j, const std::string& path, double limit = kMaxSceneCoordinate) const {
        if (!j.is_array() || j.size() != 3) fail(path, "expected 3 numbers");
        Vec3 v;
        float* out = &v.x;
        for (std::size_t k = 0; k < 3; ++k) out[k] = number(j[k], index(path, k), -limit, limit);
        return v;
    }

    // A world position: 3 finite numbers within kMaxSceneCoordinate of 0, in double.
    DVec3 position(const json& j, const std::string& path) const {
        if (!j.is_array() || j.size() != 3) fail(path, "expected 3 numbers");
        double v[3];
        for (std::size_t k = 0; k < 3; ++k)
            v[k] = real(j[k], index(path, k), -kMaxSceneCoordinate, kMaxSceneCoordinate);
        return {v[0], v[1], v[2]};
    }

    const json& array(const json& j, const std::string& path, bool non_empty) const {
        if (!j.is_array()) fail(path, "expected an array");
        if (non_empty && j.empty()) fail(path, "expected a non-empty array");
        return j;
    }
};

// A double as a float; beyond the float range: infinity (which check_placed reports), never the
// undefined conversion.
float to_float(double v) {
    if (!(std::fabs(v) <= double(FLT_MAX))) return v < 0 ? -INFINITY : INFINITY;
    return static_cast<float>(v);
}

// Determinant of the linear (upper-left 3x3) part, in double.
double linear_determinant(const Mat4& m) {
    auto a = [&](int r, int c) { return double(m.at(r, c)); };
    return a(0, 0) * (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1)) - a(0, 1) * (a(1, 0) * a(2, 2) - a(1, 2) * a(2, 0)) +
           a(0, 2) * (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0));
}

// A transform split into a world origin (double, scene_frame_near: SceneInstance::origin) and a
// float matrix whose translation is within half a kSceneFrameGrid of 0.
struct Placement {
    Mat4 m;
    DVec3 origin;
};

// The placement of a world translation t (double) and a float linear part: t's nearest grid
// point becomes the origin, the rest (|x| <= 8) the float translation, rounded once. Near the
// world's origin (within 1024) the origin is 0 and the translation float(t), as in float world
// coordinates (default.json reproduces the built-in scene bit for bit).
Placement split_translation(Mat4 m, DVec3 t) {
    Placement out;
    out.origin = scene_frame_near(t);
    const DVec3 rest = t - out.origin;
    m.at(0, 3) = to_float(rest.x);
    m.at(1, 3) = to_float(rest.y);
    m.at(2, 3) = to_float(rest.z);
    out.m = m;
    return out;
}

// A transform: an object {position, yaw_degrees, scale | height} or 16 numbers row-major.
// `standing` (objects only) gives the height form's standing transform. The result maps the
// object's own coordinates (relative to `origin`, the loader's local frame) to world space:
// translation(result.origin) * result.m, composed in double.
Placement read_transform(const Reader& r, const json& j, const std::string& path, const LoadedModel* model,
                         DVec3 origin) {
    if (j.is_array()) {
        if (j.size() != 16) r.fail(path, "expected 16 numbers (a row-major 4x4 matrix) or an object");
        Mat4 m;
        double t[3];
        for (int row = 0; row < 4; ++row)
            for (int col = 0; col < 4; ++col) {
                const std::size_t k = 4 * static_cast<std::size_t>(row) + static_cast<std::size_t>(col);
                m.at(row, col) = r.number(j[k], index(path, k), -FLT_MAX, FLT_MAX);
                if (col == 3 && row < 3) t[row] = j[k].get<double>();
            }
        if (m.at(3, 0) != 0 || m.at(3, 1) != 0 || m.at(3, 2) != 0 || m.at(3, 3) != 1)
            r.fail(path, "the last row must be 0 0 0 1 (an affine matrix)");
        const double det = linear_determinant(m);
        if (!(std::fabs(det) > 0) || !std::isfinite(det)) r.fail(path, "the matrix is singular (a zero scale)");
        // M * translation(origin): the translation summed in double.
        for (int row = 0; row < 3; ++row)
            t[row] +=
                double(m.at(row, 0)) * origin.x + double(m.at(row, 1)) * origin.y + double(m.at(row, 2)) * origin.z;
        return split_translation(m, {t[0], t[1], t[2]});
    }
    if (model)
        r.object(j, path, {"position", "yaw_degrees", "scale", "height"});
    else
        r.object(j, path, {"position", "yaw_degrees", "scale"});
    const json* p = r.find(j, "position");
    const DVec3 position = p ? r.position(*p, join(path, "position")) : DVec3{};
    const float yaw = r.number_or(j, path, "yaw_degrees", 0, -1e6, 1e6);
    const json* height = model ? r.find(j, "height") : nullptr;
    if (height && r.find(j, "scale")) r.fail(path, "give 'height' or 'scale', not both");
    Mat4 local;
    DVec3 shift{};  // R * s * origin (the model's local frame, scale form), in double
    if (height) {
        const float h = r.number(*height, join(path, "height"), 0, 1e9, true);
        try {
            local = standing_transform(*model, h);
        } catch (const Error& e) {
            r.fail(join(path, "height"), e.what());
        }
    } else {
        const float s = r.number_or(j, path, "scale", 1, 0, 1e9, true);
        local = scaling(s);
        const Mat4 turn = rotation_y(yaw);
        const double so[3] = {double(s) * origin.x, double(s) * origin.y, double(s) * origin.z};
        double* out = &shift.x;
        for (int row = 0; row < 3; ++row)
            out[row] =
                double(turn.at(row, 0)) * so[0] + double(turn.at(row, 1)) * so[1] + double(turn.at(row, 2)) * so[2];
    }
    // translation(rest) * rotation_y(yaw) * local in float, the rest of the position after its
    // grid origin (all of it near the world's origin) added in float as the built-in scenes do.
    Placement out;
    out.origin = scene_frame_near(position + shift);
    const DVec3 rest = position + shift - out.origin;
    out.m = translation(patchcull::to_float(rest)) * rotation_y(yaw) * local;
    return out;
}

// World-space points must be finite, within kMaxSceneCoordinate of 0 and (together) at least
// kMinMeshDiagonal across.
void check_placed(const Reader& r, const std::string& path, const std::vector<DVec3>& points, const char* what) {
    double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
    for (const DVec3& p : points) {
        const double* c = &p.x;
        for (int a = 0; a < 3; ++a) {
            if (!std::isfinite(c[a]) || std::fabs(c[a]) > kMaxSceneCoordinate)
                r.fail(path, std::string("the placed ") + what + " reaches " + number_text(c[a]) +
                                 "; scene files take world coordinates up to 536870912 (2^29: beyond it a double world "
                                 "position is coarser than the float data it places)");
            lo[a] = std::min(lo[a], c[a]);
            hi[a] = std::max(hi[a], c[a]);
        }
    }
    double diagonal = 0;
    for (int a = 0; a < 3; ++a) diagonal += (hi[a] - lo[a]) * (hi[a] - lo[a]);
    diagonal = std::sqrt(diagonal);
    if (!(diagonal >= kMinMeshDiagonal))
        r.fail(path,
               std::string("the placed ") + what + " is " + number_text(diagonal) +
                   " units across; patchcull takes meshes of at least 1e-06 units across (the kernels work in float)");
}

Scheme read_scheme(const Reader& r, const json& obj, const std::string& path) {
    const json* j = r.find(obj, "scheme");
    if (!j) return Scheme::acc;
    const std::string text = r.string(*j, join(path, "scheme"));
    Scheme scheme = Scheme::acc;
    if (!parse_scheme(text, scheme))
        r.fail(join(path, "scheme"), "unknown scheme " + quote_input(text) + " (acc or osd)");
    return scheme;
}

// Parses text, catching duplicate keys (with their JSON path) and reporting syntax errors with
// line and column.
json parse_strict(const Reader& r, const std::string& text) {
    constexpr std::size_t kMaxDepth = 32;
    struct Frame {
        bool array;
        std::size_t next = 0;
        std::string path, key;
        std::set<std::string> keys;
    };
    std::vector<Frame> frames;
    auto child_path = [&]() -> std::string {
        if (frames.empty()) return "";
        Frame& parent = frames.back();
        return parent.array ? index(parent.path, parent.next++) : join(parent.path, parent.key);
    };
    const json::parser_callback_t callback = [&](int, json::parse_event_t event, json& parsed) {
        switch (event) {
            case json::parse_event_t::object_start:
            case json::parse_event_t::array_start: {
                // The format nests 6 deep; a deeper file is refused before its paths grow (each
                // frame keeps its path: quadratic in the depth).
                if (frames.size() >= kMaxDepth)
                    r.fail("", "JSON nested deeper than " + std::to_string(kMaxDepth) + " levels");
                std::string path = child_path();
                frames.push_back({event == json::parse_event_t::array_start, 0, std::move(path), {}, {}});
                break;
            }
            case json::parse_event_t::object_end:
            case json::parse_event_t::array_end:
                if (!frames.empty()) frames.pop_back();
                break;
            case json::parse_event_t::key:
                if (!frames.empty()) {
                    Frame& f = frames.back();
                    f.key = parsed.is_string() ? parsed.get<std::string>() : std::string();
                    if (!f.keys.insert(f.key).second) r.fail(f.path, "duplicate key " + quote_input(f.key));
                }
                break;
            case json::parse_event_t::value:
                if (!frames.empty() && frames.back().array) ++frames.back().next;
                break;
        }
        return true;
    };
    try {
        return json::parse(text, callback);
    } catch (const json::parse_error& e) {
        // Line and column of the byte nlohmann stopped at (e.byte counts from 1).
        const std::size_t end = std::min<std::size_t>(e.byte == 0 ? 0 : e.byte - 1, text.size());
        std::size_t line = 1, column = 1;
        for (std::size_t i = 0; i < end; ++i) {
            if (text[i] == '\n')
                ++line, column = 1;
            else
                ++column;
        }
        std::string what = e.what();
        const std::size_t colon = what.find(": ", what.find("column"));
        what = colon != std::string::npos ? what.substr(colon + 2)
                                          : what.substr(std::min(what.size(), what.find(']') + 1));
        throw Error(
            printable_line(r.file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " + what, 300));
    } catch (const json::exception& e) {
        // E.g. out_of_range.406, a number beyond a double (nlohmann-json gives no position).
        std::string what = e.what();
        what = what.substr(std::min(what.size(), what.find("] ") == std::string::npos ? 0 : what.find("] ") + 2));
        throw Error(printable_line(r.file + ": invalid JSON: " + what, 300));
    }
}

struct ModelKey {
    std::string file;  // canonical path, or the built-in name
    Scheme scheme;
    bool operator<(const ModelKey& o) const { return file != o.file ? file < o.file : scheme < o.scheme; }
};

// Names of objects, environment objects or cells -> their indices (for the lists that name them).
using NameIndex = std::map<std::string, std::size_t>;

// The whole file, size-checked, parsed (parse_strict), its root object's keys checked.
json read_root(const Reader& r, const std::string& path) {
    const std::string problem = detail::input_file_problem(path, kMaxSceneFileBytes, "scene");
    if (!problem.empty()) r.fail("", problem);
    std::ifstream in(path, std::ios::binary);
    if (!in) r.fail("", "cannot open file");
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) r.fail("", "cannot read the file");
    json root = parse_strict(r, text);
    r.object(root, "", {"name", "objects", "environment", "displacement", "animation", "camera", "cells", "portals"});
    return root;
}

// "animation": the scene's AnimationParams, each key defaulting to the struct's value.
void read_animation(const Reader& r, const json& a, AnimationParams& animation) {
    r.object(a, "animation", {"bend_radians", "twist_radians", "breathe_amplitude", "period_seconds"});
    animation.bend_radians = r.number_or(a, "animation", "bend_radians", animation.bend_radians, -10, 10);
    animation.twist_radians = r.number_or(a, "animation", "twist_radians", animation.twist_radians, -10, 10);
    animation.breathe_amplitude = r.number_or(a, "animation", "breathe_amplitude", animation.breathe_amplitude, 0, 0.5);
    animation.period_seconds = r.number_or(a, "animation", "period_seconds", animation.period_seconds, 0, 1e6, true);
}

// "displacement": map "none", "procedural" (scale, size, seed) or a PNG path (scale).
void read_displacement(const Reader& r, const json& d, Scene& scene) {
    r.object(d, "displacement", {"map", "scale", "size", "seed"});
    const std::string map = r.string(r.require(d, "displacement", "map"), "displacement.map");
    if (map == "none") {
        for (const char* key : {"scale", "size", "seed"})
            if (r.find(d, key)) r.fail(join("displacement", key), "not used with map 'none'");
        return;
    }
    const float scale = r.number(r.require(d, "displacement", "scale"), "displacement.scale", 0, 1e6, true);
    if (map == "procedural") {
        const json* size = r.find(d, "size");
        const json* seed = r.find(d, "seed");
        const int n = size ? static_cast<int>(r.integer(*size, "displacement.size", 1, 4096)) : 512;
        const auto s = seed ? static_cast<std::uint32_t>(r.integer(*seed, "displacement.seed", 0, 4294967295LL)) : 7u;
        scene.displacement = make_procedural_displacement(n, scale, s);
    } else {
        for (const char* key : {"size", "seed"})
            if (r.find(d, key)) r.fail(join("displacement", key), "only for map 'procedural'");
        try {
            scene.displacement = load_displacement_png(r.resolve(map), scale);
        } catch (const Error& e) {
            r.fail("displacement.map", e.what());
        }
    }
    scene.displacement_name = map == "procedural" ? map : r.resolve(map);
}

// The file a model name stands for.
std::string model_file(const Reader& r, const std::string& spec) {
    if (spec == "bigguy" || spec == "monsterfrog") return shipped_model_path(spec + ".obj");
    return spec == "teapot" ? std::string("teapot") : r.resolve(spec);
}

// The model's key (file and scheme).
ModelKey model_key(const Reader& r, const std::string& spec, Scheme scheme) {
    ModelKey key{model_file(r, spec), spec == "teapot" ? Scheme::acc : scheme};
    if (spec != "teapot") {
        std::error_code ec;
        const fs::path canonical = fs::weakly_canonical(key.file, ec);
        if (!ec) key.file = canonical.string();
    }
    return key;
}

// Default names are "STEM#k", k counting the objects of one model (file and scheme). Where
// models of one stem differ (one model in both schemes, or two files of one name), the stem
// alone would name two objects alike: their default names then say the model as the file
// writes it (when the files differ) and the scheme (when the schemes differ), e.g.
// "bigguy:osd#0", "a/bigguy.obj#0". This first pass finds them (without loading, and without
// failing: read_objects reports malformed objects in file order).
std::map<ModelKey, std::string> default_name_stems(const Reader& r, const json& objects) {
    std::map<ModelKey, std::string> default_keys;
    std::map<std::string, std::vector<std::pair<ModelKey, std::string>>> by_stem;  // stem -> (key, spec)
    for (const json& o : objects) {
        const auto m = o.is_object() ? o.find("model") : o.end();
        if (m == o.end() || !m->is_string() || m->get<std::string>().empty()) continue;
        const auto sc = o.find("scheme");
        Scheme scheme = Scheme::acc;
        if (sc != o.end() && !(sc->is_string() && parse_scheme(sc->get<std::string>(), scheme))) continue;
        const std::string spec = m->get<std::string>();
        const ModelKey key = model_key(r, spec, scheme);
        auto& group = by_stem[fs::path(model_file(r, spec)).stem().string()];
        if (std::none_of(group.begin(), group.end(),
                         [&](const auto& g) { return !(g.first < key) && !(key < g.first); }))
            group.emplace_back(key, spec);
    }
    for (const auto& [stem, group] : by_stem) {
        bool files_differ = false, schemes_differ = false;
        for (const auto& g : group) {
            files_differ = files_differ || g.first.file != group.front().first.file;
            schemes_differ = schemes_differ || g.first.scheme != group.front().first.scheme;
        }
        for (const auto& [key, spec] : group)
            default_keys[key] =
                (files_differ ? spec : stem) + (schemes_differ ? std::string(":") + scheme_name(key.scheme) : "");
    }
    return default_keys;
}

// An object's "animation": deform, time_offset, velocity.
void read_object_animation(const Reader& r, const json& a, const std::string& ap, SceneInstance& instance) {
    r.object(a, ap, {"deform", "time_offset", "velocity"});
    instance.deforms = r.boolean_or(a, ap, "deform", true);
    instance.time_offset = r.number_or(a, ap, "time_offset", 0, -1e6, 1e6);
    if (const json* v = r.find(a, "velocity")) {
        instance.velocity = r.vec3(*v, join(ap, "velocity"));
        if (length(instance.velocity) > 1e6f)
            r.fail(join(ap, "velocity"), "expected a speed of at most 1e6 units per second");
    }
}

// "objects": the models (each file and scheme loaded once) and their instances. Returns the
// instances' names.
NameIndex read_objects(const Reader& r, const json& root, Scene& scene) {
    std::map<ModelKey, std::size_t> loaded;
    NameIndex instance_names;
    std::vector<std::size_t> copies;
    const json& objects = r.array(r.require(root, "", "objects"), "objects", true);
    const std::map<ModelKey, std::string> default_keys = default_name_stems(r, objects);
    for (std::size_t i = 0; i < objects.size(); ++i) {
        const std::string p = index("objects", i);
        const json& o = r.object(objects[i], p, {"name", "model", "scheme", "transform", "animation", "displaced"});
        const std::string spec = r.string(r.require(o, p, "model"), join(p, "model"));
        const Scheme scheme = read_scheme(r, o, p);
        const std::string file = model_file(r, spec);
        const ModelKey key = model_key(r, spec, scheme);
        auto found = loaded.find(key);
        if (found == loaded.end()) {
            try {
                scene.models.push_back(load_model(file, key.scheme, 0));
            } catch (const Error& e) {
                r.fail(join(p, "model"), e.what());
            }
            found = loaded.emplace(key, scene.models.size() - 1).first;
            copies.push_back(0);
        }
        const LoadedModel& model = scene.models[found->second];
        SceneInstance instance;
        instance.model = found->second;
        const json* t = r.find(o, "transform");
        const Placement placed = t ? read_transform(r, *t, join(p, "transform"), &model, model.origin)
                                   : read_transform(r, json::object(), join(p, "transform"), &model, model.origin);
        instance.object_to_world = placed.m;
        instance.origin = placed.origin;
        if (const json* a = r.find(o, "animation")) read_object_animation(r, *a, join(p, "animation"), instance);
        instance.displaced = r.boolean_or(o, p, "displaced", false);
        if (instance.displaced && scene.displacement.empty())
            r.fail(join(p, "displaced"), "true, but the scene has no displacement map (\"displacement\")");
        // The placed model's control points at rest (which bound the surface) must fit the limits.
        std::vector<DVec3> points;
        points.reserve(model.rest.patches.size() * kPatchPoints);
        for (const BezierPatch& patch : model.rest.patches)
            for (const Vec4& c : patch.cp)
                points.push_back(to_double(cartesian(instance.object_to_world * c)) + instance.origin);
        check_placed(r, join(p, "transform"), points, "model");
        const json* n = r.find(o, "name");
        instance.name =
            n ? r.string(*n, join(p, "name")) : default_keys.at(key) + "#" + std::to_string(copies[instance.model]);
        ++copies[instance.model];
        if (!instance_names.emplace(instance.name, i).second)
            r.fail(join(p, "name"), "duplicate object name " + quote_input(instance.name) + " (also objects[" +
                                        std::to_string(instance_names[instance.name]) + "])");
        scene.instances.push_back(std::move(instance));
    }
    return instance_names;
}

// An environment object's triangles before its transform: vertices (plus `origin`, an OBJ's
// local frame), 3 indices per triangle, and whether its kind is one-sided by default.
struct EnvironmentShape {
    std::vector<DVec3> local;
    std::vector<std::uint32_t> indices;
    DVec3 origin{};
    bool one_sided = false;
};

// "box": {min, max}, add_box's triangles over its corners, one-sided.
EnvironmentShape read_box(const Reader& r, const json& box, const std::string& bp) {
    EnvironmentShape shape;
    r.object(box, bp, {"min", "max"});
    const DVec3 lo = r.position(r.require(box, bp, "min"), join(bp, "min"));
    const DVec3 hi = r.position(r.require(box, bp, "max"), join(bp, "max"));
    if (!(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z))
        r.fail(bp, "max must be greater than min on every axis (a flat or empty box)");
    // add_box's triangles over its corners (bit 0 = x, bit 1 = y, bit 2 = z), in double.
    Scene tmp;
    add_box(tmp, "", {0, 0, 0}, {1, 1, 1});
    for (const Vec3& v : tmp.occluder_vertices)
        shape.local.push_back({v.x > 0 ? hi.x : lo.x, v.y > 0 ? hi.y : lo.y, v.z > 0 ? hi.z : lo.z});
    shape.indices = tmp.occluder_indices;
    shape.one_sided = true;
    return shape;
}

// "quad": 4 corners spanning an area, two triangles.
EnvironmentShape read_quad(const Reader& r, const json& quad, const std::string& qp) {
    EnvironmentShape shape;
    if (!quad.is_array() || quad.size() != 4) r.fail(qp, "expected 4 corners");
    DVec3 c[4];
    for (std::size_t k = 0; k < 4; ++k) c[k] = r.position(quad[k], index(qp, k));
    // The area from offsets to the first corner (small numbers, whatever the position).
    const Vec3 e1 = to_float(c[1] - c[0]), e2 = to_float(c[2] - c[0]), e3 = to_float(c[3] - c[0]);
    const float area = length(cross(e1, e2)) + length(cross(e2, e3));
    if (!(area > 0)) r.fail(qp, "the corners span no area");
    for (const DVec3& v : c) shape.local.push_back(v);
    shape.indices = {0, 1, 2, 0, 2, 3};
    return shape;
}

// "obj": an OBJ file's faces as fans of triangles, in its local frame.
EnvironmentShape read_obj_shape(const Reader& r, const json& obj, const std::string& op) {
    EnvironmentShape shape;
    const std::string file = r.resolve(r.string(obj, op));
    ControlMesh mesh;
    try {
        mesh = load_obj(file);
    } catch (const Error& err) {
        r.fail(op, err.what());
    }
    if (mesh.face_count() == 0) r.fail(op, file + ": the mesh has no faces");
    for (const Vec3& v : mesh.positions) shape.local.push_back({v.x, v.y, v.z});
    shape.origin = mesh.origin;
    for (std::size_t f = 0; f < mesh.face_count(); ++f) {
        const std::uint32_t first = mesh.face_offsets[f];
        for (std::uint32_t k = 1; k + 1 < mesh.face_size(f); ++k)
            for (std::uint32_t c : {first, first + k, first + k + 1}) shape.indices.push_back(mesh.face_vertices[c]);
    }
    return shape;
}

// One entry of "environment": its shape placed in world space and added to the scene.
void read_environment_object(const Reader& r, const json& e, std::size_t i, Scene& scene,
                             NameIndex& environment_names) {
    const std::string p = index("environment", i);
    r.object(e, p, {"name", "box", "quad", "obj", "transform", "one_sided"});
    const int kinds = (r.find(e, "box") ? 1 : 0) + (r.find(e, "quad") ? 1 : 0) + (r.find(e, "obj") ? 1 : 0);
    if (kinds != 1) r.fail(p, "expected exactly one of 'box', 'quad' or 'obj'");
    EnvironmentShape shape = r.find(e, "box")    ? read_box(r, *r.find(e, "box"), join(p, "box"))
                             : r.find(e, "quad") ? read_quad(r, *r.find(e, "quad"), join(p, "quad"))
                                                 : read_obj_shape(r, *r.find(e, "obj"), join(p, "obj"));
    const bool one_sided = r.boolean_or(e, p, "one_sided", shape.one_sided);
    // The transform maps the object's coordinates (an OBJ's own, with its local frame's
    // origin added back) to world space, in double.
    const json* t = r.find(e, "transform");
    const Placement placed = t ? read_transform(r, *t, join(p, "transform"), nullptr, {}) : Placement{};
    const Mat4& m = placed.m;
    const double det = linear_determinant(m);
    if (!(std::fabs(det) > 0)) r.fail(join(p, "transform"), "the transform is singular (a zero scale)");
    std::vector<DVec3> world;
    world.reserve(shape.local.size());
    for (const DVec3& v : shape.local) {
        const double x = v.x + shape.origin.x, y = v.y + shape.origin.y, z = v.z + shape.origin.z;
        double w[3];
        for (int row = 0; row < 3; ++row)
            w[row] =
                double(m.at(row, 0)) * x + double(m.at(row, 1)) * y + double(m.at(row, 2)) * z + double(m.at(row, 3));
        world.push_back(DVec3{w[0], w[1], w[2]} + placed.origin);
    }
    check_placed(r, t ? join(p, "transform") : p, world, "environment object");
    // The scene's frame is the world's (origin 0): float world vertices, and the exact
    // ones in double for rebase_scene.
    std::vector<Vec3> world_float;
    world_float.reserve(world.size());
    for (const DVec3& v : world) world_float.push_back({to_float(v.x), to_float(v.y), to_float(v.z)});
    scene.occluder_world.insert(scene.occluder_world.end(), world.begin(), world.end());
    // A mirroring transform turns counter-clockwise into clockwise: flip the triangles back.
    std::vector<std::uint32_t>& indices = shape.indices;
    if (det < 0)
        for (std::size_t k = 0; k + 2 < indices.size(); k += 3) std::swap(indices[k + 1], indices[k + 2]);
    const json* n = r.find(e, "name");
    const std::string object_name = n ? r.string(*n, join(p, "name")) : "environment#" + std::to_string(i);
    if (!environment_names.emplace(object_name, i).second)
        r.fail(join(p, "name"), "duplicate environment name " + quote_input(object_name) + " (also environment[" +
                                    std::to_string(environment_names[object_name]) + "])");
    add_triangles(scene, object_name, world_float, indices, one_sided);
}

// "environment" (optional). Returns the environment objects' names.
NameIndex read_environment(const Reader& r, const json& root, Scene& scene) {
    NameIndex environment_names;
    if (const json* env = r.find(root, "environment")) {
        r.array(*env, "environment", false);
        for (std::size_t i = 0; i < env->size(); ++i)
            read_environment_object(r, (*env)[i], i, scene, environment_names);
    }
    return environment_names;
}

// "camera.orbit": target (a world position), distance, height, start and step in degrees.
void read_orbit(const Reader& r, const json& orbit, CameraPath& cam) {
    r.object(orbit, "camera.orbit", {"target", "distance", "height", "start_degrees", "degrees_per_frame"});
    const json* target = r.find(orbit, "target");
    const DVec3 t = target ? r.position(*target, "camera.orbit.target") : DVec3{};
    cam.origin = scene_frame_near(t);
    cam.target = to_float(t - cam.origin);
    cam.distance =
        r.number(r.require(orbit, "camera.orbit", "distance"), "camera.orbit.distance", 0, kMaxMeshExtent, true);
    cam.height = r.number_or(orbit, "camera.orbit", "height", 0, -kMaxMeshExtent, kMaxMeshExtent);
    cam.start_degrees = r.number_or(orbit, "camera.orbit", "start_degrees", 0, -1e6, 1e6);
    cam.degrees_per_frame = r.number_or(orbit, "camera.orbit", "degrees_per_frame", 5, -360, 360);
}

// "camera.walk": start (a world position), step, direction (not zero or vertical), view_distance.
void read_walk(const Reader& r, const json& walk, CameraPath& cam) {
    r.object(walk, "camera.walk", {"start", "step", "direction", "view_distance"});
    cam.walk = true;
    const DVec3 start = r.position(r.require(walk, "camera.walk", "start"), "camera.walk.start");
    cam.origin = scene_frame_near(start);
    cam.walk_start = to_float(start - cam.origin);
    cam.walk_step = r.vec3(r.require(walk, "camera.walk", "step"), "camera.walk.step");
    cam.walk_direction = r.vec3(r.require(walk, "camera.walk", "direction"), "camera.walk.direction");
    const Vec3 d = cam.walk_direction;
    if (!(std::hypot(d.x, d.z) > 1e-6f * std::fabs(d.y)) || !(length(d) > 0))
        r.fail("camera.walk.direction", "expected a direction that is not zero or vertical");
    cam.distance = r.number_or(walk, "camera.walk", "view_distance", 5, 0, kMaxMeshExtent, true);
    cam.height = 0;
    cam.target = cam.walk_start + cam.walk_direction;
}

// "camera": exactly one of orbit or walk, and the projection.
void read_camera(const Reader& r, const json& root, CameraPath& cam) {
    const json& c =
        r.object(r.require(root, "", "camera"), "camera", {"orbit", "walk", "fovy_degrees", "z_near", "z_far"});
    const json* orbit = r.find(c, "orbit");
    const json* walk = r.find(c, "walk");
    if ((orbit ? 1 : 0) + (walk ? 1 : 0) != 1) r.fail("camera", "expected exactly one of 'orbit' or 'walk'");
    if (orbit)
        read_orbit(r, *orbit, cam);
    else
        read_walk(r, *walk, cam);
    const float fovy = r.number_or(c, "camera", "fovy_degrees", 60, 0, 179, true);
    cam.fovy_radians = fovy * kPi / 180.0f;
    cam.z_near = r.number_or(c, "camera", "z_near", 0.05f, 0, kMaxMeshExtent, true);
    cam.z_far = r.number_or(c, "camera", "z_far", 50, 0, 1e30, true);
    if (!(cam.z_far > cam.z_near)) r.fail("camera.z_far", "must be greater than z_near");
}

// A cell's list `key` of names from `known` (what: the kind, for the messages) as indices.
void read_cell_names(const Reader& r, const json& c, const std::string& p, const char* key, const NameIndex& known,
                     const char* what, std::vector<std::size_t>& out) {
    const json* list = r.find(c, key);
    if (!list) return;
    const std::string lp = join(p, key);
    r.array(*list, lp, false);
    for (std::size_t k = 0; k < list->size(); ++k) {
        const std::string n = r.string((*list)[k], index(lp, k));
        const auto it = known.find(n);
        if (it == known.end()) r.fail(index(lp, k), std::string("no ") + what + " named " + quote_input(n));
        if (std::find(out.begin(), out.end(), it->second) != out.end())
            r.fail(index(lp, k), quote_input(n) + " is listed twice");
        out.push_back(it->second);
    }
}

// "cells" (optional): named boxes listing their objects and environment objects. Returns the
// cells' names.
NameIndex read_cells(const Reader& r, const json& root, const NameIndex& instance_names,
                     const NameIndex& environment_names, Scene& scene) {
    NameIndex cell_names;
    const json* cells = r.find(root, "cells");
    if (!cells) return cell_names;
    r.array(*cells, "cells", false);
    for (std::size_t i = 0; i < cells->size(); ++i) {
        const std::string p = index("cells", i);
        const json& c = r.object((*cells)[i], p, {"name", "min", "max", "objects", "environment"});
        SceneCell cell;
        cell.name = r.string(r.require(c, p, "name"), join(p, "name"));
        if (!cell_names.emplace(cell.name, i).second)
            r.fail(join(p, "name"), "duplicate cell name " + quote_input(cell.name));
        // World positions in double (rebase_scene rounds them into each frame); the scene's
        // frame is the world's, so the floats are the world coordinates rounded.
        const DVec3 lo = r.position(r.require(c, p, "min"), join(p, "min"));
        const DVec3 hi = r.position(r.require(c, p, "max"), join(p, "max"));
        if (!(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z)) r.fail(p, "max must be greater than min on every axis");
        cell.box = {patchcull::to_float(lo), patchcull::to_float(hi)};
        scene.cell_world.push_back({lo, hi});
        read_cell_names(r, c, p, "objects", instance_names, "object", cell.instances);
        read_cell_names(r, c, p, "environment", environment_names, "environment object", cell.environment);
        scene.cells.push_back(std::move(cell));
    }
    return cell_names;
}

// One entry of "portals": the two cells it joins and its 4 corners (spanning an area).
void read_portal(const Reader& r, const json& entry, const std::string& p, const NameIndex& cell_names, Scene& scene) {
    const json& o = r.object(entry, p, {"cells", "corners"});
    const json& pair = r.require(o, p, "cells");
    if (!pair.is_array() || pair.size() != 2) r.fail(join(p, "cells"), "expected 2 cell names");
    ScenePortal portal;
    std::size_t* ends[2] = {&portal.cell_a, &portal.cell_b};
    for (std::size_t k = 0; k < 2; ++k) {
        const std::string n = r.string(pair[k], index(join(p, "cells"), k));
        const auto it = cell_names.find(n);
        if (it == cell_names.end()) r.fail(index(join(p, "cells"), k), "no cell named " + quote_input(n));
        *ends[k] = it->second;
    }
    if (portal.cell_a == portal.cell_b) r.fail(join(p, "cells"), "a portal joins two different cells");
    const json& corners = r.require(o, p, "corners");
    if (!corners.is_array() || corners.size() != 4) r.fail(join(p, "corners"), "expected 4 corners");
    std::array<DVec3, 4> world;
    for (std::size_t k = 0; k < 4; ++k) {
        world[k] = r.position(corners[k], index(join(p, "corners"), k));
        portal.corners[k] = patchcull::to_float(world[k]);
    }
    // The area in double, relative to the first corner (floats far out would round it).
    const Vec3 e1 = patchcull::to_float(world[1] - world[0]), e2 = patchcull::to_float(world[2] - world[0]),
               e3 = patchcull::to_float(world[3] - world[0]);
    if (!(length(cross(e1, e2)) + length(cross(e2, e3)) > 0)) r.fail(join(p, "corners"), "the corners span no area");
    scene.portals.push_back(portal);
    scene.portal_world.push_back(world);
}

// "portals" (optional; they need cells).
void read_portals(const Reader& r, const json& root, const NameIndex& cell_names, Scene& scene) {
    const json* portals = r.find(root, "portals");
    if (!portals) return;
    r.array(*portals, "portals", false);
    if (!portals->empty() && scene.cells.empty()) r.fail("portals", "portals need cells (\"cells\")");
    for (std::size_t i = 0; i < portals->size(); ++i)
        read_portal(r, (*portals)[i], index("portals", i), cell_names, scene);
}

}  // namespace

Scene load_scene_file(const std::string& path) {
    const Reader r{path, fs::path(path).parent_path()};
    const json root = read_root(r, path);
    Scene scene;
    const json* name = r.find(root, "name");
    scene.name = name ? r.string(*name, "name") : fs::path(path).stem().string();
    // Animation and displacement first: objects refer to them.
    if (const json* a = r.find(root, "animation")) read_animation(r, *a, scene.animation);
    if (const json* d = r.find(root, "displacement")) read_displacement(r, *d, scene);
    const NameIndex instance_names = read_objects(r, root, scene);
    const NameIndex environment_names = read_environment(r, root, scene);
    read_camera(r, root, scene.camera);
    const NameIndex cell_names = read_cells(r, root, instance_names, environment_names, scene);
    read_portals(r, root, cell_names, scene);
    return scene;
}

}  // namespace patchcull
