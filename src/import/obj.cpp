// Strict Wavefront OBJ reader for subdivision control meshes (patchcull/obj.h).
//
// Why not tinyobjloader: it reads malformed numbers ("abc") and "nan" as 0 and only warns on
// out-of-range indices, i.e. it returns a silently wrong mesh. Control meshes need only v, vt, f
// (and OpenSubdiv's "t crease/corner" tags), so a strict line-numbered reader is small.
#include "patchcull/obj.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string_view>

#include "patchcull/error.h"

namespace patchcull {
namespace {

struct LineContext {
    const std::string& name;
    std::size_t line;
    [[noreturn]] void fail(const std::string& what) const {
        throw Error(name + ":" + std::to_string(line) + ": " + what);
    }
};

std::vector<std::string_view> split_tokens(std::string_view s) {
    std::vector<std::string_view> tokens;
    std::size_t i = 0;
    while (i < s.size()) {
        while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r')) ++i;
        std::size_t j = i;
        while (j < s.size() && s[j] != ' ' && s[j] != '\t' && s[j] != '\r') ++j;
        if (j > i) tokens.push_back(s.substr(i, j - i));
        i = j;
    }
    return tokens;
}

float parse_float(std::string_view token, const LineContext& ctx) {
    float value = 0;
    const char* first = token.data();
    const char* last = token.data() + token.size();
    if (first != last && *first == '+') ++first;  // from_chars rejects a leading '+'
    auto [ptr, ec] = std::from_chars(first, last, value);
    if (ec == std::errc::result_out_of_range) ctx.fail("number out of range '" + std::string(token) + "'");
    if (ec != std::errc() || ptr != last) ctx.fail("malformed number '" + std::string(token) + "'");
    if (!std::isfinite(value)) ctx.fail("non-finite coordinate '" + std::string(token) + "'");
    return value;
}

// A vertex coordinate, parsed in double so that a model far from the origin can be re-centred
// before the rounding to float (recentre below). parse_float checks it first: the same errors,
// and the value must fit a float.
double parse_coordinate(std::string_view token, const LineContext& ctx) {
    parse_float(token, ctx);
    double value = 0;
    const char* first = token.data();
    if (*first == '+') ++first;
    std::from_chars(first, token.data() + token.size(), value);
    return value;
}

// Moves the positions into a local frame (ControlMesh::origin, mesh.h) when the model lies far
// from 0. At a translation of 1e7 a float's spacing is 1 unit, so float positions would already
// be wrong by a good part of a model's size (BigGuy is about 20 units); and every later float
// computation (patches, clip transforms, ptp's rounding margin) loses precision in proportion
// to |position|, not to the model's size. A model whose bounding-box centre is within the box's
// diagonal of 0 keeps origin 0 and its positions exactly as before (they are as precise as
// centred ones, within a factor 3).
void recentre(const std::vector<DVec3>& world, ControlMesh& mesh) {
    if (world.empty()) return;
    DVec3 lo = world[0], hi = world[0];
    for (const DVec3& p : world) {
        lo = {std::fmin(lo.x, p.x), std::fmin(lo.y, p.y), std::fmin(lo.z, p.z)};
        hi = {std::fmax(hi.x, p.x), std::fmax(hi.y, p.y), std::fmax(hi.z, p.z)};
    }
    const DVec3 centre{0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y), 0.5 * (lo.z + hi.z)};
    const DVec3 d = hi - lo;
    const double diagonal = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    if (std::fmax(std::fabs(centre.x), std::fmax(std::fabs(centre.y), std::fabs(centre.z))) <= diagonal) return;
    mesh.origin = centre;
    for (std::size_t i = 0; i < world.size(); ++i) mesh.positions[i] = to_float(world[i] - centre);
}

long parse_int(std::string_view token, const LineContext& ctx, const char* what) {
    long value = 0;
    auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || ptr != token.data() + token.size() || token.empty())
        ctx.fail(std::string("malformed ") + what + " '" + std::string(token) + "'");
    return value;
}

// Resolves a 1-based (or negative, relative) OBJ index against count elements read so far.
std::uint32_t resolve_index(long index, std::size_t count, const LineContext& ctx, const char* what) {
    long resolved = index > 0 ? index - 1 : static_cast<long>(count) + index;
    if (index == 0 || resolved < 0 || resolved >= static_cast<long>(count))
        ctx.fail(std::string(what) + " index " + std::to_string(index) + " out of range (have " +
                 std::to_string(count) + ")");
    return static_cast<std::uint32_t>(resolved);
}

// "t crease 2/1/0 v0 v1 s" and "t corner 1/1/0 v s" (OpenSubdiv's shape format, 0-based vertices).
void parse_tag(const std::vector<std::string_view>& tokens, ControlMesh& mesh, const LineContext& ctx) {
    if (tokens.size() < 2) ctx.fail("malformed tag line");
    const std::string_view kind = tokens[1];
    if (kind != "crease" && kind != "corner") return;  // other OpenSubdiv tags are not used here
    const bool crease = kind == "crease";
    const std::size_t vertex_count = crease ? 2 : 1;
    if (tokens.size() != 3 + vertex_count + 1)
        ctx.fail(std::string("malformed '") + std::string(kind) + "' tag: expected " +
                 (crease ? "'t crease 2/1/0 v0 v1 sharpness'" : "'t corner 1/1/0 v sharpness'"));
    Crease c;
    long v[2] = {0, 0};
    for (std::size_t k = 0; k < vertex_count; ++k) {
        v[k] = parse_int(tokens[3 + k], ctx, "vertex index");
        if (v[k] < 0 || v[k] >= static_cast<long>(mesh.positions.size()))
            ctx.fail("tag vertex index " + std::to_string(v[k]) + " out of range (have " +
                     std::to_string(mesh.positions.size()) + ")");
    }
    c.v0 = static_cast<std::uint32_t>(v[0]);
    c.v1 = static_cast<std::uint32_t>(v[1]);
    c.sharpness = parse_float(tokens.back(), ctx);
    if (c.sharpness < 0) ctx.fail("negative sharpness");
    (crease ? mesh.creases : mesh.corners).push_back(c);
}

}  // namespace

ControlMesh parse_obj(std::istream& in, const std::string& name) {
    ControlMesh mesh;
    mesh.name = name;
    bool faces_with_uv = false, faces_without_uv = false;
    std::vector<std::uint32_t> face_uv_scratch;
    std::vector<DVec3> world_positions;  // as in the file, for recentre()
    std::string line;
    std::size_t line_number = 0;
    while (std::getline(in, line)) {
        ++line_number;
        const LineContext ctx{name, line_number};
        const auto hash = line.find('#');
        std::string_view content(line.data(), hash == std::string::npos ? line.size() : hash);
        const auto tokens = split_tokens(content);
        if (tokens.empty()) continue;
        const std::string_view key = tokens[0];
        if (key == "v") {
            // x y z, optionally followed by a weight w (x y z w) or a vertex colour (x y z r g b
            // [a]); both are checked and ignored (control meshes are polynomial, colour unused).
            const std::size_t values = tokens.size() - 1;
            if (values != 3 && values != 4 && values != 6 && values != 7) ctx.fail("vertex needs 3 coordinates");
            world_positions.push_back({parse_coordinate(tokens[1], ctx), parse_coordinate(tokens[2], ctx),
                                       parse_coordinate(tokens[3], ctx)});
            mesh.positions.push_back(to_float(world_positions.back()));  // origin 0 until recentre()
            for (std::size_t k = 4; k < tokens.size(); ++k) parse_float(tokens[k], ctx);
        } else if (key == "vt") {
            if (tokens.size() < 3 || tokens.size() > 4) ctx.fail("texture coordinate needs 2 values");
            mesh.texcoords.push_back({parse_float(tokens[1], ctx), parse_float(tokens[2], ctx)});
            if (tokens.size() == 4) parse_float(tokens[3], ctx);
        } else if (key == "vn") {
            if (tokens.size() != 4) ctx.fail("normal needs 3 values");
            for (int k = 1; k <= 3; ++k) parse_float(tokens[k], ctx);
        } else if (key == "f") {
            if (tokens.size() < 4) ctx.fail("face needs at least 3 vertices");
            bool has_uv = true;
            face_uv_scratch.clear();
            const std::size_t first_corner = mesh.face_vertices.size();
            for (std::size_t k = 1; k < tokens.size(); ++k) {
                const std::string_view corner = tokens[k];
                const auto slash1 = corner.find('/');
                const std::string_view vpart = corner.substr(0, slash1);
                mesh.face_vertices.push_back(
                    resolve_index(parse_int(vpart, ctx, "vertex index"), mesh.positions.size(), ctx, "vertex"));
                std::string_view tpart;
                if (slash1 != std::string_view::npos) {
                    const auto rest = corner.substr(slash1 + 1);
                    tpart = rest.substr(0, rest.find('/'));
                }
                if (tpart.empty()) {
                    has_uv = false;
                } else {
                    face_uv_scratch.push_back(resolve_index(parse_int(tpart, ctx, "texture index"),
                                                            mesh.texcoords.size(), ctx, "texture coordinate"));
                }
            }
            for (std::size_t a = first_corner; a < mesh.face_vertices.size(); ++a)
                for (std::size_t b = a + 1; b < mesh.face_vertices.size(); ++b)
                    if (mesh.face_vertices[a] == mesh.face_vertices[b])
                        ctx.fail("face uses vertex " + std::to_string(mesh.face_vertices[a] + 1) + " twice");
            if (has_uv && face_uv_scratch.size() == tokens.size() - 1) {
                faces_with_uv = true;
                mesh.face_texcoords.insert(mesh.face_texcoords.end(), face_uv_scratch.begin(), face_uv_scratch.end());
            } else {
                faces_without_uv = true;
            }
            mesh.face_offsets.push_back(static_cast<std::uint32_t>(mesh.face_vertices.size()));
        } else if (key == "t") {
            parse_tag(tokens, mesh, ctx);
        } else if (key == "o" || key == "g" || key == "s" || key == "usemtl" || key == "mtllib" || key == "l" ||
                   key == "p" || key == "vp" || key == "cstype" || key == "deg") {
            // Grouping, materials, points and lines: no effect on a control mesh.
        } else {
            ctx.fail("unknown record '" + std::string(key) + "'");
        }
    }
    if (in.bad()) throw Error(name + ": read error");
    if (mesh.face_count() == 0) throw Error(name + ": no faces");
    recentre(world_positions, mesh);
    if (faces_with_uv && faces_without_uv) {
        mesh.face_texcoords.clear();
        mesh.warnings.push_back(name + ": some faces lack texture coordinates; texture coordinates ignored");
    }
    return mesh;
}

ControlMesh load_obj(const std::string& path) {
    std::ifstream file(path, std::ios::binary);
    if (!file) throw Error(path + ": cannot open file");
    return parse_obj(file, path);
}

}  // namespace patchcull
