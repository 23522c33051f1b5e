// Internal: ControlMesh -> Far::TopologyRefiner with validation (see osd_topology.h).
//
// Source: OpenSubdiv 3.5 Far, TopologyDescriptor/TopologyRefinerFactory, with the subdivision
// options of Niessner & Loop and Loop, Niessner & Eisenacher (Catmull-Clark, EDGE_AND_CORNER
// vertex boundaries) unless the mesh carries others (ControlMesh::options and holes, from OpenSubdiv's OBJ tags).
#include "import/osd_topology.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <sstream>

#include <opensubdiv/far/error.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include "import/mesh_messages.h"
#include "patchcull/core/error.h"

namespace patchcull::osd_detail {

namespace OSD = OpenSubdiv::Far;

void RefinerDeleter::operator()(OSD::TopologyRefiner* r) const { delete r; }

namespace {

// Far reports errors and warnings through process-wide C callbacks (default: printf). We install
// ours once and collect the messages per thread, so concurrent builds keep their own messages.
thread_local std::vector<std::string>* t_errors = nullptr;
thread_local std::vector<std::string>* t_warnings = nullptr;

void on_far_error(OSD::ErrorType, const char* message) {
    if (t_errors) t_errors->emplace_back(message ? message : "unknown OpenSubdiv error");
}
void on_far_warning(const char* message) {
    if (t_warnings) t_warnings->emplace_back(message ? message : "unknown OpenSubdiv warning");
}

void install_callbacks() {
    static std::once_flag once;
    std::call_once(once, [] {
        OSD::SetErrorCallback(on_far_error);
        OSD::SetWarningCallback(on_far_warning);
    });
}

// Collapses a Far message (which may span lines) into one line.
std::string one_line(std::string s) {
    std::replace(s.begin(), s.end(), '\n', ' ');
    while (!s.empty() && s.back() == ' ') s.pop_back();
    return s;
}

[[noreturn]] void fail(const ControlMesh& mesh, const std::string& what) { throw Error(mesh.name + ": " + what); }

void validate(const ControlMesh& mesh) {
    const std::size_t nv = mesh.positions.size();
    if (mesh.face_count() == 0) fail(mesh, "mesh has no faces");
    if (mesh.face_offsets.empty() || mesh.face_offsets.front() != 0 ||
        mesh.face_offsets.back() != mesh.face_vertices.size())
        fail(mesh, "face offsets do not match the face vertex list");
    if (mesh.has_texcoords() && mesh.face_texcoords.size() != mesh.face_vertices.size())
        fail(mesh, "face texcoord list does not match the face vertex list");
    for (std::size_t f = 0; f < mesh.face_count(); ++f) {
        const std::uint32_t b = mesh.face_offsets[f], e = mesh.face_offsets[f + 1];
        if (e < b + 3) fail(mesh, "face " + std::to_string(f) + " has fewer than 3 corners");
        for (std::uint32_t c = b; c < e; ++c) {
            if (mesh.face_vertices[c] >= nv)
                fail(mesh, "face " + std::to_string(f) + " uses vertex " + std::to_string(mesh.face_vertices[c]) +
                               " out of range (" + std::to_string(nv) + " vertices)");
            for (std::uint32_t d = b; d < c; ++d)
                if (mesh.face_vertices[d] == mesh.face_vertices[c])
                    fail(mesh,
                         "face " + std::to_string(f) + " repeats vertex " + std::to_string(mesh.face_vertices[c]));
            if (mesh.has_texcoords() && mesh.face_texcoords[c] >= mesh.texcoords.size())
                fail(mesh, "face " + std::to_string(f) + " uses texcoord " + std::to_string(mesh.face_texcoords[c]) +
                               " out of range");
        }
    }
    for (const Crease& c : mesh.creases)
        if (c.v0 >= nv || c.v1 >= nv || c.v0 == c.v1 || !std::isfinite(c.sharpness) || c.sharpness < 0)
            fail(mesh, "invalid crease (" + std::to_string(c.v0) + ", " + std::to_string(c.v1) + ")");
    for (const Crease& c : mesh.corners)
        if (c.v0 >= nv || !std::isfinite(c.sharpness) || c.sharpness < 0)
            fail(mesh, "invalid corner on vertex " + std::to_string(c.v0));
    for (const std::uint32_t f : mesh.holes)
        if (f >= mesh.face_count()) fail(mesh, "hole face " + std::to_string(f) + " out of range (0-based)");
}

// Position k of the edge {a, b} in face f (corner k to k+1, either direction).
int edge_corner(const ControlMesh& mesh, std::size_t f, std::uint32_t a, std::uint32_t b) {
    const std::uint32_t first = mesh.face_offsets[f], n = mesh.face_size(f);
    for (std::uint32_t k = 0; k < n; ++k) {
        const std::uint32_t u = mesh.face_vertices[first + k], w = mesh.face_vertices[first + (k + 1) % n];
        if ((u == a && w == b) || (u == b && w == a)) return static_cast<int>(k);
    }
    return 0;
}

// Far accepts non-manifold topology (it sharpens it); patchcull does not (see header). Reported
// as the acc scheme reports them (quad_topology.cpp, same words through mesh_messages.h, same
// offender): first an edge of more than two faces, the one whose third face comes first in the
// file (then by corner); then an edge two faces walk the same way, the one whose second face
// comes first; then the first vertex whose faces do not form one fan.
void check_manifold(const ControlMesh& mesh, const OSD::TopologyLevel& base) {
    struct Offender {
        std::size_t face = SIZE_MAX;
        int corner = 0;
        int edge = -1;
        bool before(std::size_t f, int k) const { return f < face || (f == face && k < corner); }
    };
    Offender shared, flipped;
    for (int e = 0; e < base.GetNumEdges(); ++e) {
        if (!base.IsEdgeNonManifold(e)) continue;
        const auto ev = base.GetEdgeVertices(e);
        std::vector<int> faces(base.GetEdgeFaces(e).begin(), base.GetEdgeFaces(e).end());
        std::sort(faces.begin(), faces.end());
        if (faces.size() < 2) continue;
        Offender& o = faces.size() > 2 ? shared : flipped;
        const auto f = static_cast<std::size_t>(faces[faces.size() > 2 ? 2 : 1]);
        const int k = edge_corner(mesh, f, static_cast<std::uint32_t>(ev[0]), static_cast<std::uint32_t>(ev[1]));
        if (o.before(f, k)) o = {f, k, e};
    }
    if (shared.edge >= 0) {
        const std::uint32_t first = mesh.face_offsets[shared.face], n = mesh.face_size(shared.face);
        const auto k = static_cast<std::uint32_t>(shared.corner);
        throw Error(detail::edge_shared_message(mesh, shared.face, mesh.face_vertices[first + k],
                                                mesh.face_vertices[first + (k + 1) % n],
                                                static_cast<std::size_t>(base.GetEdgeFaces(shared.edge).size())));
    }
    if (flipped.edge >= 0) {
        std::vector<int> faces(base.GetEdgeFaces(flipped.edge).begin(), base.GetEdgeFaces(flipped.edge).end());
        std::sort(faces.begin(), faces.end());
        const std::uint32_t first = mesh.face_offsets[flipped.face], n = mesh.face_size(flipped.face);
        const auto k = static_cast<std::uint32_t>(flipped.corner);
        throw Error(detail::edge_orientation_message(mesh, static_cast<std::size_t>(faces[0]), flipped.face,
                                                     mesh.face_vertices[first + k],
                                                     mesh.face_vertices[first + (k + 1) % n]));
    }
    for (int v = 0; v < base.GetNumVertices(); ++v) {
        // An unused vertex (no faces) is harmless: no stencil refers to it.
        const auto vf = base.GetVertexFaces(v);
        if (vf.empty() || !base.IsVertexNonManifold(v)) continue;
        throw Error(detail::vertex_fan_message(mesh, static_cast<std::size_t>(*std::min_element(vf.begin(), vf.end())),
                                               static_cast<std::uint32_t>(v)));
    }
}

}  // namespace

RefinerPtr create_refiner(const ControlMesh& mesh, std::vector<std::string>* warnings) {
    validate(mesh);
    install_callbacks();

    std::vector<int> verts_per_face(mesh.face_count());
    for (std::size_t f = 0; f < mesh.face_count(); ++f) verts_per_face[f] = static_cast<int>(mesh.face_size(f));
    std::vector<int> face_verts(mesh.face_vertices.begin(), mesh.face_vertices.end());
    std::vector<int> crease_pairs;
    std::vector<float> crease_weights;
    for (const Crease& c : mesh.creases) {
        crease_pairs.push_back(static_cast<int>(c.v0));
        crease_pairs.push_back(static_cast<int>(c.v1));
        crease_weights.push_back(c.sharpness);
    }
    std::vector<int> corner_verts;
    std::vector<float> corner_weights;
    for (const Crease& c : mesh.corners) {
        corner_verts.push_back(static_cast<int>(c.v0));
        corner_weights.push_back(c.sharpness);
    }
    std::vector<int> fvar_indices(mesh.face_texcoords.begin(), mesh.face_texcoords.end());

    OSD::TopologyDescriptor desc;
    desc.numVertices = static_cast<int>(mesh.positions.size());
    desc.numFaces = static_cast<int>(mesh.face_count());
    desc.numVertsPerFace = verts_per_face.data();
    desc.vertIndicesPerFace = face_verts.data();
    desc.numCreases = static_cast<int>(crease_weights.size());
    desc.creaseVertexIndexPairs = crease_pairs.data();
    desc.creaseWeights = crease_weights.data();
    desc.numCorners = static_cast<int>(corner_weights.size());
    desc.cornerVertexIndices = corner_verts.data();
    desc.cornerWeights = corner_weights.data();
    const std::vector<int> holes(mesh.holes.begin(), mesh.holes.end());
    desc.numHoles = static_cast<int>(holes.size());
    desc.holeIndices = holes.data();
    desc.isLeftHanded = false;  // OBJ faces are counter-clockwise
    OSD::TopologyDescriptor::FVarChannel channel;
    if (mesh.has_texcoords()) {
        channel.numValues = static_cast<int>(mesh.texcoords.size());
        channel.valueIndices = fvar_indices.data();
        desc.numFVarChannels = 1;
        desc.fvarChannels = &channel;
    }

    // The mesh's options (mesh.h: patchcull's defaults, or the OBJ's OpenSubdiv tags).
    using Sdc = OpenSubdiv::Sdc::Options;
    Sdc sdc;
    sdc.SetVtxBoundaryInterpolation(mesh.options.boundary == BoundaryInterpolation::none ? Sdc::VTX_BOUNDARY_NONE
                                    : mesh.options.boundary == BoundaryInterpolation::edge_only
                                        ? Sdc::VTX_BOUNDARY_EDGE_ONLY
                                        : Sdc::VTX_BOUNDARY_EDGE_AND_CORNER);
    sdc.SetCreasingMethod(mesh.options.chaikin_creases ? Sdc::CREASE_CHAIKIN : Sdc::CREASE_UNIFORM);
    sdc.SetTriangleSubdivision(mesh.options.smooth_triangles ? Sdc::TRI_SUB_SMOOTH : Sdc::TRI_SUB_CATMARK);
    // Texture coordinates are interpolated bilinearly (patchcull's PatchInfo::uv is bilinear).
    sdc.SetFVarLinearInterpolation(OpenSubdiv::Sdc::Options::FVAR_LINEAR_ALL);
    OSD::TopologyRefinerFactory<OSD::TopologyDescriptor>::Options options(OpenSubdiv::Sdc::SCHEME_CATMARK, sdc);
    options.validateFullTopology = true;

    std::vector<std::string> errors, warns;
    t_errors = &errors;
    t_warnings = &warns;
    RefinerPtr refiner(OSD::TopologyRefinerFactory<OSD::TopologyDescriptor>::Create(desc, options));
    t_errors = nullptr;
    t_warnings = nullptr;
    if (!refiner)
        fail(mesh, "OpenSubdiv rejected the topology: " +
                       (errors.empty() ? std::string("unknown error") : one_line(errors.front())));
    if (!errors.empty()) fail(mesh, "OpenSubdiv: " + one_line(errors.front()));
    if (warnings)
        for (const std::string& w : warns) warnings->push_back(mesh.name + ": OpenSubdiv: " + one_line(w));

    check_manifold(mesh, refiner->GetLevel(0));
    return refiner;
}

}  // namespace patchcull::osd_detail
