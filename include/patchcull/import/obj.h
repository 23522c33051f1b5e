// patchcull/import/obj.h: a strict Wavefront OBJ reader for subdivision control meshes.
//
// Reads v, vt and f records (f with v, v/vt, v//vn or v/vt/vn corners, negative indices allowed)
// and the "t" tags of OpenSubdiv's shape files, with the meaning OpenSubdiv's own shape reader
// gives them (0-based vertex and face indices; ControlMesh, mesh.h, holds the result):
//   t crease n/1/0 v0 v1 [v2 v3 ..] s   creases on the edges (v0,v1), (v2,v3), .. (vertex pairs)
//   t corner n/1/0 v.. s, n/n/0 v.. s..  vertex sharpness
//   t hole n/0/0 f..                     faces without surface (ControlMesh::holes)
//   t interpolateboundary 1/0/0 m        0 none, 1 edges and corners, 2 edges only (a file
//                                        without the tag gets edges and corners, patchcull's
//                                        default; OpenSubdiv's regression harness uses edges only)
//   t creasemethod 0/0/1 normal|chaikin  t smoothtriangles 0/0/1 catmark|smooth
//   t facevaryinginterpolateboundary 1/0/0 m, t facevaryingpropagatecorners 1/0/0 b: checked
//                                        and ignored (patchcull has no face-varying data)
// accepts vertex weights and colours (x y z [w] or x y z r g b [a], ignored); checks vn records
// and the normal indices that name them, then drops them; ignores o, g, s, usemtl, mtllib, l, p,
// comments, blank lines and a UTF-8 byte-order mark. Strict by design: every malformed number,
// non-finite coordinate or sharpness, out-of-range index (vertex, texture coordinate, normal,
// tag vertex or hole face), malformed corner, face with fewer than 3 corners or a repeated
// vertex, unknown or unsupported tag (a misspelt "crease" must not drop a crease), crease that
// is no edge of a face, crease from a vertex to itself or negative sharpness is a
// patchcull::Error naming "file:line", one short printable line (offending text is quoted
// through quote_input, patchcull/core/error.h). Work is O(n log n) in the file size for any face size.
// Each face's line is kept (ControlMesh::face_line) for later messages about the mesh.
// (tinyobjloader, tried first, reads "abc" and "nan" as 0 and only warns on out-of-range indices:
// a silently wrong mesh, so it is not used.)
#pragma once

#include <cstdint>

#include <istream>
#include <string>

#include "patchcull/core/mesh.h"

namespace patchcull {

/// Largest OBJ file load_obj reads (it reads the whole file): 2 GiB.
inline constexpr std::uintmax_t kMaxObjFileBytes = std::uintmax_t{2} << 30;

/// Loads an OBJ file: a regular file of at most kMaxObjFileBytes (a device, FIFO or directory is
/// refused before any read). Throws patchcull::Error ("path: cannot open ...", "path:line: ...").
/// A mesh where some faces have texture coordinates and others not drops them all and says so in
/// ControlMesh::warnings: displacement then falls back to each patch's own (u,v) domain.
ControlMesh load_obj(const std::string& path);

/// Parses OBJ text from a stream; name is used in error messages. Vertex coordinates are parsed
/// in double (each must fit a float) and, when the bounding-box centre is farther from 0 than
/// the box's diagonal, stored relative to that centre (ControlMesh::origin): a model at 1e7
/// keeps its shape to float precision of its own size.
ControlMesh parse_obj(std::istream& in, const std::string& name);

}  // namespace patchcull
