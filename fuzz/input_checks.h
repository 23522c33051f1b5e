// fuzz/input_checks.h: what every input to the OBJ reader and the PNG height-map loader must
// do, shared by the libFuzzer targets (fuzz/*_fuzz.cpp, clang) and the deterministic mutation
// test that ctest runs with any compiler (tests/import/input_mutation_test.cpp).
//
// An input either loads, into a mesh or map that is safe to use (finite values, indices in range,
// consistent sizes), or fails with a patchcull::Error whose message is one printable line of at
// most kMaxMessageBytes bytes. Anything else (another exception type, a long or unprintable
// message, a NaN in the mesh) is a violation: the check returns its description. Crashes, hangs
// and memory errors are the fuzzer's and the sanitizers' to find.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <sstream>
#include <string>

#include "patchcull/core/error.h"
#include "patchcull/core/mesh.h"
#include "patchcull/import/image.h"
#include "patchcull/import/obj.h"

namespace patchcull::fuzz {

// Loader messages here name a short fixed file name, so a message is the name, a line number, a
// fixed description and at most one quote_input (about 50 bytes): 256 leaves room and still
// catches a message that echoes a whole line.
inline constexpr std::size_t kMaxMessageBytes = 256;

inline std::string check_message(const char* what) {
    const std::string message = what;
    if (message.empty()) return "empty error message";
    if (message.size() > kMaxMessageBytes)
        return "error message of " + std::to_string(message.size()) + " bytes: " + printable_line(message, 120);
    if (!is_printable_line(message)) return "unprintable error message: " + printable_line(message, 120);
    return {};
}

inline bool finite(Vec3 p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

// A mesh parse_obj returned must be safe for the subdivision builders to index.
inline std::string check_mesh(const ControlMesh& mesh) {
    for (const Vec3& p : mesh.positions)
        if (!finite(p)) return "non-finite position";
    for (const Vec2& t : mesh.texcoords)
        if (!std::isfinite(t.x) || !std::isfinite(t.y)) return "non-finite texture coordinate";
    if (mesh.face_offsets.empty() || mesh.face_offsets.front() != 0 || mesh.face_count() == 0 ||
        mesh.face_offsets.back() != mesh.face_vertices.size())
        return "face offsets do not match the face vertices";
    for (std::size_t f = 0; f < mesh.face_count(); ++f)
        if (mesh.face_offsets[f + 1] < mesh.face_offsets[f] + 3) return "face with fewer than 3 corners";
    for (const std::uint32_t v : mesh.face_vertices)
        if (v >= mesh.positions.size()) return "face vertex out of range";
    if (mesh.has_texcoords() && mesh.face_texcoords.size() != mesh.face_vertices.size())
        return "face texcoords do not match the face vertices";
    for (const std::uint32_t t : mesh.face_texcoords)
        if (t >= mesh.texcoords.size()) return "face texcoord out of range";
    for (const Crease& c : mesh.creases)
        if (c.v0 >= mesh.positions.size() || c.v1 >= mesh.positions.size() || c.v0 == c.v1 ||
            !std::isfinite(c.sharpness) || c.sharpness < 0)
            return "invalid crease";
    for (const Crease& c : mesh.corners)
        if (c.v0 >= mesh.positions.size() || !std::isfinite(c.sharpness) || c.sharpness < 0) return "invalid corner";
    for (std::size_t k = 0; k < mesh.holes.size(); ++k)
        if (mesh.holes[k] >= mesh.face_count() || (k > 0 && mesh.holes[k] <= mesh.holes[k - 1]))
            return "hole out of range or not sorted";
    for (std::size_t f = 1; f < mesh.face_count(); ++f)
        if (mesh.face_line(f) <= mesh.face_line(f - 1)) return "face lines not increasing";
    for (const std::string& w : mesh.warnings)
        if (const std::string bad = check_message(w.c_str()); !bad.empty()) return "warning: " + bad;
    (void)classify_orientation(mesh);  // the orientation check every render runs: must not crash
    return {};
}

/// Runs the OBJ reader on size bytes; returns "" or the violation.
inline std::string check_obj_input(const std::uint8_t* data, std::size_t size) {
    std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
    try {
        return check_mesh(parse_obj(in, "fuzz.obj"));
    } catch (const Error& e) {
        return check_message(e.what());
    } catch (const std::exception& e) {
        return std::string("exception other than patchcull::Error: ") + printable_line(e.what(), 120);
    }
}

/// Runs the PNG height-map loader on size bytes; returns "" or the violation.
inline std::string check_png_input(const std::uint8_t* data, std::size_t size) {
    try {
        const DisplacementMap map = decode_displacement_png(data, size, "fuzz.png", 1.0f);
        if (map.width <= 0 || map.height <= 0) return "empty map loaded";
        if (map.texels.size() != static_cast<std::size_t>(map.width) * static_cast<std::size_t>(map.height))
            return "texel count does not match the size";
        for (const float h : map.texels)
            if (!(h >= 0.0f && h <= 1.0f)) return "height outside [0,1]";
        return {};
    } catch (const Error& e) {
        return check_message(e.what());
    } catch (const std::exception& e) {
        return std::string("exception other than patchcull::Error: ") + printable_line(e.what(), 120);
    }
}

}  // namespace patchcull::fuzz
