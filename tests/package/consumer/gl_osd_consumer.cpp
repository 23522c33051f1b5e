// Uses patchcull::gl_osd from an installed package: a cube's feature-adaptive OpenSubdiv patch
// table (import's make_osd_adaptive_table) uploaded as Osd::GLPatchTable and OpenSubdiv's own GLSL
// patch programs compiled with patchcull's TCS include, on a headless GL 4.5 context (Mesa
// llvmpipe without a GPU). Exit status 1 on any failure.
#include <cstdint>
#include <exception>
#include <string>

#include "check.h"
#include "patchcull/gl/gl_context.h"
#include "patchcull/gl/gl_passes.h"
#include "patchcull/gl_osd/osd_gl_draw.h"
#include "patchcull/import/osd_patch_table.h"

namespace pc = patchcull;

int main() {
    // A unit cube: 8 points, 6 outward quads.
    pc::ControlMesh cube;
    cube.name = "cube";
    for (int i = 0; i < 8; ++i) cube.positions.push_back({float(i & 1), float((i >> 1) & 1), float((i >> 2) & 1)});
    const std::uint32_t faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                       {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& face : faces) {
        cube.face_vertices.insert(cube.face_vertices.end(), face, face + 4);
        cube.face_offsets.push_back(static_cast<std::uint32_t>(cube.face_vertices.size()));
    }
    try {
        const pc::OsdAdaptiveTable table = pc::make_osd_adaptive_table(cube, 2);
        pc::gl::GlContext context = pc::gl::GlContext::create_headless();
        pc::gl::PassContext passes;
        const pc::gl_osd::OsdPatchTableDraw draw(passes, *table.table);
        check(draw.patch_count() == static_cast<std::size_t>(table.table->GetNumPatchesTotal()),
              "OsdPatchTableDraw holds the table's " + std::to_string(draw.patch_count()) + " patches");
        check(draw.points_needed() <= table.points.size(), "the table reads " + std::to_string(draw.points_needed()) +
                                                               " of " + std::to_string(table.points.size()) +
                                                               " points");
    } catch (const std::exception& e) {
        check(false, std::string("gl_osd: ") + e.what());
    }
    return failures == 0 ? 0 : 1;
}
