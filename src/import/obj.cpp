// Strict Wavefront OBJ reader for subdivision control meshes (patchcull/import/obj.h).
//
// Why not tinyobjloader: it reads malformed numbers ("abc") and "nan" as 0 and only warns on
// out-of-range indices, i.e. it returns a silently wrong mesh. Control meshes need only v, vt, f
// (and the "t" tags of OpenSubdiv's shape files), so a strict line-numbered reader is small.
#include "patchcull/import/obj.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string_view>

#include "input_file.h"
#include "patchcull/core/error.h"

namespace patchcull {
namespace {

struct LineContext {
    const std::string& name;
    std::size_t line;
    [[noreturn]] void fail(const std::string& what) const {
        throw Error(name + ":" + std::to_string(line) + ": " + what);
    }
};

// Fills tokens (reused across lines: one allocation per file, not per line).
void split_tokens(std::string_view s, std::vector<std::string_view>& tokens) {
    tokens.clear();
    std::size_t i = 0;
    while (i < s.size()) {
        while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r')) ++i;
        std::size_t j = i;
        while (j < s.size() && s[j] != ' ' && s[j] != '\t' && s[j] != '\r') ++j;
        if (j > i) tokens.push_back(s.substr(i, j - i));
        i = j;
    }
}

float parse_float(std::string_view token, const LineContext& ctx, const char* what = "coordinate") {
    float value = 0;
    const char* first = token.data();
    const char* last = token.data() + token.size();
    if (first != last && *first == '+') ++first;  // from_chars rejects a leading '+'
    auto [ptr, ec] = std::from_chars(first, last, value);
    if (ec == std::errc::result_out_of_range) ctx.fail("number out of range " + quote_input(token));
    if (ec != std::errc() || ptr != last) ctx.fail("malformed number " + quote_input(token));
    if (!std::isfinite(value)) ctx.fail(std::string("non-finite ") + what + " " + quote_input(token));
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
        ctx.fail(std::string("malformed ") + what + " " + quote_input(token));
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

// Parses a tag's "ints/floats/strings" argument counts (OpenSubdiv's shape format).
void parse_tag_counts(std::string_view token, long counts[3], const LineContext& ctx) {
    const char* p = token.data();
    const char* const end = p + token.size();
    for (int k = 0; k < 3; ++k) {
        const auto [next, ec] = std::from_chars(p, end, counts[k]);
        const bool separated = k < 2 ? next != end && *next == '/' : next == end;
        if (ec != std::errc() || counts[k] < 0 || !separated)
            ctx.fail("malformed tag argument counts " + quote_input(token));
        p = k < 2 ? next + 1 : next;
    }
}

// OpenSubdiv's shape-format tags: "t NAME ints/floats/strings" and then that many integers,
// floats and strings, read with the meaning OpenSubdiv's own shape reader gives them
// (regression/common/far_utils.h in OpenSubdiv):
//   crease n/1/0 v0 v1 [v2 v3 ...] s   edges (v0,v1), (v2,v3), ... (pairs, not RenderMan's chain
//                                      of edges: OpenSubdiv reads pairs), 0-based, sharpness s
//   corner n/1/0 v.. s | n/n/0 v.. s..  vertex sharpness, one for all or one per vertex
//   hole n/0/0 f..                     faces (0-based) with no surface of their own
//   interpolateboundary 1/0/0 m        0 none, 1 edges and corners, 2 edges only
//   creasemethod 0/0/1 normal|chaikin, smoothtriangles 0/0/1 catmark|smooth
//   facevaryinginterpolateboundary 1/0/0 m (0-5), facevaryingpropagatecorners 1/0/0 0|1:
//                                      face-varying options; patchcull has no face-varying data
//                                      (its texture coordinates are bilinear per patch), so they
//                                      are checked and have no effect.
// Every other tag is an error, not ignored: a misspelt "crease" would silently drop a crease,
// and the hierarchical edits (vertexedit, edgeedit, faceedit) are not in OpenSubdiv 3 at all.
// A crease with several sharpness values over several edges is refused: OpenSubdiv's reader
// indexes them inconsistently (by vertex, not by edge), so no reading is OpenSubdiv's.
struct TagState {
    std::uint32_t boundary_line = 0, crease_method_line = 0, triangles_line = 0;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> holes;  // (face, line), checked at the end
};

void parse_tag(const std::vector<std::string_view>& tokens, ControlMesh& mesh, TagState& state,
               const LineContext& ctx) {
    if (tokens.size() < 3)
        ctx.fail(
            "malformed tag line (expected 't NAME ints/floats/strings arguments...', e.g. 't crease 2/1/0 v0 v1 "
            "sharpness')");
    const std::string_view kind = tokens[1];
    std::string tag = "'";  // built with += : GCC 12 warns falsely (-Wrestrict) on "'" + std::string
    tag += kind;
    tag += "' tag";
    static constexpr std::string_view kKnown[] = {"crease",
                                                  "corner",
                                                  "hole",
                                                  "interpolateboundary",
                                                  "facevaryinginterpolateboundary",
                                                  "facevaryingpropagatecorners",
                                                  "creasemethod",
                                                  "smoothtriangles"};
    if (std::find(std::begin(kKnown), std::end(kKnown), kind) == std::end(kKnown)) {
        if (kind == "vertexedit" || kind == "edgeedit" || kind == "faceedit")
            ctx.fail("unsupported tag " + quote_input(kind) + " (hierarchical edits are not part of OpenSubdiv 3)");
        ctx.fail("unknown tag " + quote_input(kind) +
                 " (expected crease, corner, hole, interpolateboundary, creasemethod, smoothtriangles, "
                 "facevaryinginterpolateboundary or facevaryingpropagatecorners)");
    }
    long counts[3];
    parse_tag_counts(tokens[2], counts, ctx);
    const long ints = counts[0], floats = counts[1], strings = counts[2];
    const auto arguments = static_cast<long>(tokens.size() - 3);
    if (ints > arguments || floats > arguments - ints ||
        strings != arguments - ints - floats)  // (no sum: it can overflow)
        ctx.fail("malformed " + tag + ": " + std::to_string(arguments) + " arguments for counts " +
                 quote_input(tokens[2]));
    const auto expect = [&](bool ok, const char* form) {
        if (!ok) ctx.fail("malformed " + tag + ": expected " + form);
    };
    const auto integer = [&](long k) { return parse_int(tokens[static_cast<std::size_t>(3 + k)], ctx, "tag integer"); };
    const auto word = [&](long k) { return tokens[static_cast<std::size_t>(3 + ints + floats + k)]; };

    if (kind == "crease" || kind == "corner") {
        const bool crease = kind == "crease";
        if (crease) {
            expect(ints >= 2 && strings == 0,
                   "'t crease 2/1/0 v0 v1 sharpness' (or n/1/0 with n vertices, read as n/2 edges)");
            if (ints % 2 != 0)
                ctx.fail("'crease' tag over an odd number of vertices (" + std::to_string(ints) +
                         "): OpenSubdiv's shape format lists a crease's edges as vertex pairs");
            if (floats != 1)
                ctx.fail(floats == 0 ? std::string("'crease' tag without a sharpness")
                                     : "'crease' tag with " + std::to_string(floats) +
                                           " sharpness values: give one for all its edges, or one tag per edge");
        } else {
            expect(ints >= 1 && strings == 0 && (floats == 1 || floats == ints),
                   "'t corner 1/1/0 v sharpness' (or n/1/0 or n/n/0 for n vertices)");
        }
        std::vector<std::uint32_t> vertices;
        for (long k = 0; k < ints; ++k) {
            const long v = integer(k);
            if (v < 0 || v >= static_cast<long>(mesh.positions.size()))
                ctx.fail("tag vertex index " + std::to_string(v) + " out of range (0-based; have " +
                         std::to_string(mesh.positions.size()) + " vertices so far)");
            vertices.push_back(static_cast<std::uint32_t>(v));
        }
        std::vector<float> sharpness;
        for (long k = 0; k < floats; ++k) {
            sharpness.push_back(parse_float(tokens[static_cast<std::size_t>(3 + ints + k)], ctx, "sharpness"));
            if (sharpness.back() < 0)
                ctx.fail("negative sharpness " + quote_input(tokens[static_cast<std::size_t>(3 + ints + k)]));
        }
        const auto line = static_cast<std::uint32_t>(ctx.line);
        if (crease) {
            for (std::size_t k = 0; k < vertices.size(); k += 2) {
                if (vertices[k] == vertices[k + 1])
                    ctx.fail("crease from vertex " + std::to_string(vertices[k]) + " to itself (0-based)");
                mesh.creases.push_back({vertices[k], vertices[k + 1], sharpness[0], line});
            }
            return;
        }
        for (std::size_t k = 0; k < vertices.size(); ++k)
            mesh.corners.push_back({vertices[k], 0, sharpness[floats == 1 ? 0 : k], line});
        return;
    }
    if (kind == "hole") {
        expect(ints >= 1 && floats == 0 && strings == 0, "'t hole n/0/0 f1 .. fn' (0-based faces)");
        for (long k = 0; k < ints; ++k) {
            const long f = integer(k);
            if (f < 0 || f > 0xfffffffel) ctx.fail("hole face index " + std::to_string(f) + " out of range (0-based)");
            state.holes.emplace_back(static_cast<std::uint32_t>(f), static_cast<std::uint32_t>(ctx.line));
        }
        return;
    }
    const auto once = [&](std::uint32_t& seen) {
        if (seen != 0) ctx.fail(tag + " given twice (first at line " + std::to_string(seen) + ")");
        seen = static_cast<std::uint32_t>(ctx.line);
    };
    if (kind == "interpolateboundary") {
        expect(ints == 1 && floats == 0 && strings == 0, "'t interpolateboundary 1/0/0 m' with m 0, 1 or 2");
        const long m = integer(0);
        if (m < 0 || m > 2)
            ctx.fail("'interpolateboundary' " + std::to_string(m) +
                     ": expected 0 (none), 1 (edges and corners) or 2 (edges only)");
        once(state.boundary_line);
        mesh.options.boundary = m == 0   ? BoundaryInterpolation::none
                                : m == 1 ? BoundaryInterpolation::edge_and_corner
                                         : BoundaryInterpolation::edge_only;
        mesh.options.boundary_line = state.boundary_line;
    } else if (kind == "creasemethod" || kind == "smoothtriangles") {
        const bool method = kind == "creasemethod";
        expect(ints == 0 && floats == 0 && strings == 1,
               method ? "'t creasemethod 0/0/1 normal' or 'chaikin'" : "'t smoothtriangles 0/0/1 catmark' or 'smooth'");
        const std::string_view value = word(0);
        const std::string_view plain = method ? "normal" : "catmark", special = method ? "chaikin" : "smooth";
        if (value != plain && value != special)
            ctx.fail(tag + " " + quote_input(value) + ": expected " + std::string(plain) + " or " +
                     std::string(special));
        once(method ? state.crease_method_line : state.triangles_line);
        (method ? mesh.options.chaikin_creases : mesh.options.smooth_triangles) = value == special;
    } else {  // face-varying options: checked, no effect (see above)
        const bool boundary = kind == "facevaryinginterpolateboundary";
        expect(ints == 1 && floats == 0 && strings == 0, boundary
                                                             ? "'t facevaryinginterpolateboundary 1/0/0 m' with m 0..5"
                                                             : "'t facevaryingpropagatecorners 1/0/0 0' or '1'");
        const long m = integer(0);
        if (m < 0 || m > (boundary ? 5 : 1))
            ctx.fail(tag + " value " + std::to_string(m) + ": expected " + (boundary ? "0 to 5" : "0 or 1"));
    }
}

// After the last line: hole faces exist, and every crease joins two vertices of one face edge
// (Far would drop or refuse any other, with 0-based indices and no line).
void check_tags(ControlMesh& mesh, TagState& state, const std::string& name) {
    for (const auto& [face, line] : state.holes) {
        if (face >= mesh.face_count())
            throw Error(name + ":" + std::to_string(line) + ": hole tag names face " + std::to_string(face) +
                        " (0-based); the file has " + std::to_string(mesh.face_count()) + " faces");
        mesh.holes.push_back(face);
    }
    std::sort(mesh.holes.begin(), mesh.holes.end());
    mesh.holes.erase(std::unique(mesh.holes.begin(), mesh.holes.end()), mesh.holes.end());
    if (mesh.creases.empty()) return;
    const auto key = [](std::uint32_t a, std::uint32_t b) {
        return std::uint64_t{std::min(a, b)} << 32 | std::max(a, b);
    };
    std::vector<std::uint64_t> wanted;
    for (const Crease& c : mesh.creases) wanted.push_back(key(c.v0, c.v1));
    std::sort(wanted.begin(), wanted.end());
    std::vector<std::uint8_t> found(wanted.size(), 0);
    for (std::size_t f = 0; f < mesh.face_count(); ++f) {
        const std::uint32_t b = mesh.face_offsets[f], n = mesh.face_size(f);
        for (std::uint32_t k = 0; k < n; ++k) {
            const std::uint64_t e = key(mesh.face_vertices[b + k], mesh.face_vertices[b + (k + 1) % n]);
            const auto at = std::lower_bound(wanted.begin(), wanted.end(), e);
            if (at != wanted.end() && *at == e) found[static_cast<std::size_t>(at - wanted.begin())] = 1;
        }
    }
    for (const Crease& c : mesh.creases) {
        const auto at = std::lower_bound(wanted.begin(), wanted.end(), key(c.v0, c.v1));
        if (!found[static_cast<std::size_t>(at - wanted.begin())])
            throw Error(name + ":" + std::to_string(c.line) + ": crease between vertices " + std::to_string(c.v0) +
                        " and " + std::to_string(c.v1) + " (0-based, as tags count; OBJ vertices " +
                        std::to_string(c.v0 + 1) + " and " + std::to_string(c.v1 + 1) + "): no face has that edge");
    }
}

// Scratch buffers reused across faces (one allocation per mesh, not per face).
struct FaceScratch {
    std::vector<std::uint32_t> uvs, sorted;
};

// Parses "f c1 c2 c3 ...", each corner v, v/vt, v//vn or v/vt/vn, every index checked against
// the elements read so far (normals too: they are not kept, but a corner naming a missing one is
// a broken file). Appends the face to mesh; returns whether every corner has a texture coordinate
// (they are then appended to mesh.face_texcoords).
bool parse_face(const std::vector<std::string_view>& tokens, ControlMesh& mesh, std::size_t normal_count,
                FaceScratch& scratch, const LineContext& ctx) {
    if (tokens.size() < 4) ctx.fail("face needs at least 3 vertices");
    scratch.uvs.clear();
    const std::size_t first_corner = mesh.face_vertices.size();
    for (std::size_t k = 1; k < tokens.size(); ++k) {
        const std::string_view corner = tokens[k];
        std::string_view parts[3];
        std::size_t count = 0, begin = 0;
        for (;;) {
            const std::size_t slash = corner.find('/', begin);
            if (count == 3)
                ctx.fail("malformed face corner " + quote_input(corner) + " (expected v, v/vt, v//vn or v/vt/vn)");
            parts[count++] =
                corner.substr(begin, slash == std::string_view::npos ? std::string_view::npos : slash - begin);
            if (slash == std::string_view::npos) break;
            begin = slash + 1;
        }
        // Empty parts are allowed only as the texture coordinate of v//vn.
        if (parts[0].empty() || (count >= 2 && parts[count - 1].empty()))
            ctx.fail("malformed face corner " + quote_input(corner) + " (expected v, v/vt, v//vn or v/vt/vn)");
        mesh.face_vertices.push_back(
            resolve_index(parse_int(parts[0], ctx, "vertex index"), mesh.positions.size(), ctx, "vertex"));
        if (count >= 2 && !parts[1].empty())
            scratch.uvs.push_back(resolve_index(parse_int(parts[1], ctx, "texture index"), mesh.texcoords.size(), ctx,
                                                "texture coordinate"));
        if (count == 3) resolve_index(parse_int(parts[2], ctx, "normal index"), normal_count, ctx, "normal");
    }
    // Repeated vertices: sorted, so that a face of a million corners costs n log n, not n^2.
    scratch.sorted.assign(mesh.face_vertices.begin() + first_corner, mesh.face_vertices.end());
    std::sort(scratch.sorted.begin(), scratch.sorted.end());
    const auto repeated = std::adjacent_find(scratch.sorted.begin(), scratch.sorted.end());
    if (repeated != scratch.sorted.end()) ctx.fail("face uses vertex " + std::to_string(*repeated + 1) + " twice");
    mesh.face_offsets.push_back(static_cast<std::uint32_t>(mesh.face_vertices.size()));
    if (scratch.uvs.size() != tokens.size() - 1) return false;
    mesh.face_texcoords.insert(mesh.face_texcoords.end(), scratch.uvs.begin(), scratch.uvs.end());
    return true;
}

// The rest of the stream in one string: sized once when the stream can tell its length (a file),
// else copied through its buffer.
std::string read_all(std::istream& in, const std::string& name) {
    std::string text;
    if (!in) {  // as std::getline on a failed stream: no lines
        if (in.bad()) throw Error(name + ": read error");
        return text;
    }
    const std::istream::pos_type start = in.tellg();
    if (start != std::istream::pos_type(-1) && in.seekg(0, std::ios::end)) {
        const std::istream::pos_type end = in.tellg();
        in.seekg(start);
        if (end != std::istream::pos_type(-1) && end >= start && in) {
            text.resize(static_cast<std::size_t>(end - start));
            in.read(text.data(), static_cast<std::streamsize>(text.size()));
            text.resize(static_cast<std::size_t>(in.gcount()));
            if (in.bad()) throw Error(name + ": read error");
            return text;
        }
    }
    in.clear(in.rdstate() & std::ios::badbit);
    std::ostringstream buffer;
    if (in.rdbuf() && in.peek() != std::istream::traits_type::eof()) buffer << in.rdbuf();
    if (in.bad()) throw Error(name + ": read error");
    return std::move(buffer).str();
}

}  // namespace

ControlMesh parse_obj(std::istream& in, const std::string& name) {
    ControlMesh mesh;
    mesh.name = name;
    bool faces_with_uv = false, faces_without_uv = false;
    std::size_t normal_count = 0;
    FaceScratch scratch;
    TagState tags;
    std::vector<DVec3> world_positions;  // as in the file, for recentre()
    // The whole stream at once (one copy of the file in memory while it is parsed), split at '\n'
    // as std::getline splits it: a 1M-face file has 2M lines, and a getline and a token vector
    // per line were a third of the reader's instructions (callgrind).
    const std::string text = read_all(in, name);
    // Reserved from a count of the lines that start with "v " and "f " (four corners a face): the
    // arrays then grow without copies, and a copy's fresh pages cost more than the parsing.
    std::size_t vertex_lines = 0, face_lines = 0;
    for (std::size_t at = 0; at + 1 < text.size();) {
        vertex_lines += text[at] == 'v' && text[at + 1] == ' ';
        face_lines += text[at] == 'f' && text[at + 1] == ' ';
        const std::size_t newline = text.find('\n', at);
        if (newline == std::string::npos) break;
        at = newline + 1;
    }
    world_positions.reserve(vertex_lines);
    mesh.positions.reserve(vertex_lines);
    mesh.face_offsets.reserve(face_lines + 1);
    mesh.face_vertices.reserve(4 * face_lines);
    std::vector<std::string_view> tokens;
    std::size_t line_number = 0;
    for (std::size_t begin = 0; begin < text.size();) {
        const std::size_t newline = text.find('\n', begin);
        const std::size_t end = newline == std::string::npos ? text.size() : newline;
        std::string_view line(text.data() + begin, end - begin);
        begin = end + 1;
        ++line_number;
        const LineContext ctx{name, line_number};
        // A UTF-8 byte-order mark (written by some Windows editors) is not part of the first record.
        if (line_number == 1 && line.starts_with("\xEF\xBB\xBF")) line.remove_prefix(3);
        const auto hash = line.find('#');
        const std::string_view content = hash == std::string_view::npos ? line : line.substr(0, hash);
        split_tokens(content, tokens);
        if (tokens.empty()) continue;
        const std::string_view key = tokens[0];
        if (key == "v") {
            // x y z, optionally followed by a weight w (x y z w) or a vertex colour (x y z r g b
            // [a]); both are checked and ignored (control meshes are polynomial, colour unused).
            const std::size_t values = tokens.size() - 1;
            if (values != 3 && values != 4 && values != 6 && values != 7)
                ctx.fail("vertex has " + std::to_string(values) + (values == 1 ? " value" : " values") +
                         "; expected 3 (x y z), 4 (x y z w), 6 (x y z r g b) or 7 (x y z r g b a)");
            world_positions.push_back(
                {parse_coordinate(tokens[1], ctx), parse_coordinate(tokens[2], ctx), parse_coordinate(tokens[3], ctx)});
            mesh.positions.push_back(to_float(world_positions.back()));  // origin 0 until recentre()
            for (std::size_t k = 4; k < tokens.size(); ++k) parse_float(tokens[k], ctx);
        } else if (key == "vt") {
            if (tokens.size() < 3 || tokens.size() > 4) ctx.fail("texture coordinate needs 2 values");
            mesh.texcoords.push_back({parse_float(tokens[1], ctx), parse_float(tokens[2], ctx)});
            if (tokens.size() == 4) parse_float(tokens[3], ctx);
        } else if (key == "vn") {
            if (tokens.size() != 4) ctx.fail("normal needs 3 values");
            for (int k = 1; k <= 3; ++k) parse_float(tokens[k], ctx);
            ++normal_count;  // normals are not kept, but face corners that name one are checked
        } else if (key == "f") {
            if (parse_face(tokens, mesh, normal_count, scratch, ctx))
                faces_with_uv = true;
            else
                faces_without_uv = true;
            const auto face = static_cast<std::uint32_t>(mesh.face_count() - 1),
                       line = static_cast<std::uint32_t>(line_number);
            if (mesh.face_line_runs.empty() || mesh.face_line(face - 1) + 1 != line)
                mesh.face_line_runs.emplace_back(face, line);
        } else if (key == "t") {
            parse_tag(tokens, mesh, tags, ctx);
        } else if (key == "o" || key == "g" || key == "s" || key == "usemtl" || key == "mtllib" || key == "l" ||
                   key == "p" || key == "vp" || key == "cstype" || key == "deg") {
            // Grouping, materials, points and lines: no effect on a control mesh.
        } else {
            ctx.fail("unknown record " + quote_input(key));
        }
    }
    if (in.bad()) throw Error(name + ": read error");
    if (mesh.face_count() == 0) throw Error(name + ": no faces");
    check_tags(mesh, tags, name);
    recentre(world_positions, mesh);
    if (faces_with_uv && faces_without_uv) {
        mesh.face_texcoords.clear();
        mesh.warnings.push_back(name + ": some faces lack texture coordinates; texture coordinates ignored");
    }
    return mesh;
}

ControlMesh load_obj(const std::string& path) {
    if (const std::string problem = detail::input_file_problem(path, kMaxObjFileBytes, "OBJ"); !problem.empty())
        throw Error(path + ": " + problem);
    std::ifstream file(path, std::ios::binary);
    if (!file) throw Error(path + ": cannot open file");
    return parse_obj(file, path);
}

}  // namespace patchcull
