// Internal (src/import only): the wording of topology errors, shared by both schemes (acc:
// quad_topology.cpp, osd: osd_topology.cpp) so that one mesh gets one message whichever scheme
// reads it. Vertices are numbered from 1, as OBJ face records number them; a message about a
// face starts with "file:line" when the mesh came from a file (ControlMesh::face_line), else
// with "name: face F" (1-based).
#pragma once

#include <cstdint>
#include <string>

#include "patchcull/core/mesh.h"

namespace patchcull::detail {

/// "<name>:<line>: " for face f of a mesh read from a file, else "<name>: face <f+1>: ".
inline std::string at_face(const ControlMesh& mesh, std::size_t f) {
    const std::uint32_t line = mesh.face_line(f);
    std::string s = mesh.name;
    s += line != 0 ? ":" : ": face ";
    s += std::to_string(line != 0 ? line : f + 1);
    s += ": ";
    return s;
}

/// "the one at line <n>" or "face <f+1>": a second face named in a message.
inline std::string other_face(const ControlMesh& mesh, std::size_t f) {
    const std::uint32_t line = mesh.face_line(f);
    std::string s = line != 0 ? "the one at line " : "face ";  // += : GCC 12's false -Wrestrict on "x" + string
    s += std::to_string(line != 0 ? line : f + 1);
    return s;
}

inline std::string edge_vertices(std::uint32_t a, std::uint32_t b) {
    std::string s = "non-manifold edge between vertices ";  // += : GCC 12's false -Wrestrict on "x" + string
    s += std::to_string(a + 1);
    s += " and ";
    s += std::to_string(b + 1);
    return s;
}

/// Edge a-b used by `faces` faces (> 2); reported at the face that is its third use in file order.
inline std::string edge_shared_message(const ControlMesh& mesh, std::size_t third_face, std::uint32_t a,
                                       std::uint32_t b, std::size_t faces) {
    return at_face(mesh, third_face) + edge_vertices(a, b) + ": " + std::to_string(faces) + " faces share it";
}

/// Edge a -> b walked in the same direction by two faces (first_face before second_face).
inline std::string edge_orientation_message(const ControlMesh& mesh, std::size_t first_face, std::size_t second_face,
                                            std::uint32_t a, std::uint32_t b) {
    return at_face(mesh, second_face) + edge_vertices(a, b) + ": this face and " + other_face(mesh, first_face) +
           " run along it in the same direction (oriented inconsistently)";
}

/// Vertex v whose faces do not form one fan (a "bowtie"); reported at its first face.
inline std::string vertex_fan_message(const ControlMesh& mesh, std::size_t first_face, std::uint32_t v) {
    return at_face(mesh, first_face) + "non-manifold vertex " + std::to_string(v + 1) +
           ": its faces do not form a single fan";
}

}  // namespace patchcull::detail
