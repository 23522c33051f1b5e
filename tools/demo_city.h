// The main job's object-level part: the built-in city rendered for a few frames with
// each --objects method (none, frustum, bvh, bvh+backface) in front of the patch passes (cull
// mode all), every frame verified against the unculled render.
#pragma once

#include <cstddef>

#include "patchcull/gl/gl_renderer.h"

namespace patchcull::cli {

struct DemoCityOptions {
    int width = 640, height = 360;
    int frames = 3;
    int tess = 2;
};

/// Prints the rows; returns the false culls in total (patch and object level).
std::size_t run_demo_city(const gl::GlContext& context, const DemoCityOptions& options);

}  // namespace patchcull::cli
