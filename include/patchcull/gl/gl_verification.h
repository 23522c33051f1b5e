// patchcull/gl/gl_verification.h: judging a culled frame against the unculled render of the same
// camera, resolution and tessellation (the GPU ground truth, e.g. a --verify option), per patch:
// a false cull is a patch that contributes a pixel to the reference and was not drawn. The
// captures come from PatchRenderer's read-backs (gl_renderer.h); nothing here needs a context.
// Errors: patchcull::Error with a one-line message.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace patchcull::gl {

/// One frame as --verify compares it: id and depth buffers (read_ids, read_depth) and one byte
/// per patch: for the unculled reference its front set (mark_front_patches), for a culled frame
/// its drawn set (read_drawn_patches).
struct FrameCapture {
    std::vector<std::uint32_t> ids;
    std::vector<float> depth;
    std::vector<std::uint8_t> patches;
};

/// A culled frame against the unculled render of the same camera, resolution and tessellation
/// (the GPU ground truth), e.g. for a --verify option.
struct FrameComparison {
    std::size_t differing_pixels = 0;  ///< pixels whose id differs
    /// Of those, pixels where both ids are patches and the depths are equal: two patches with
    /// fragments at exactly the same depth, drawn in another order (GL_LESS keeps the first).
    /// Reported apart from false culls; they never count as one and never hide one.
    std::size_t depth_ties = 0;
    /// False culls (ascending patch indices): patches in the reference's front set that the
    /// culled frame did not draw. Judged per patch, not per pixel, so a patch that was drawn but
    /// lost a depth tie is not one, and a culled patch that only ties at the front still is.
    std::vector<std::uint32_t> false_culled;
    bool identical() const { return differing_pixels == 0; }
    /// No false cull and nothing but depth ties differs.
    bool conservative() const { return false_culled.empty() && differing_pixels == depth_ties; }
};
/// Compares a culled frame with its reference. Throws patchcull::Error when the buffer sizes or
/// patch counts differ.
FrameComparison compare_frames(const FrameCapture& reference, const FrameCapture& culled);

/// Writes an id buffer (as read_ids returns it) as a PNG with one distinct colour per id, black
/// for the background: for looking at false culls. Throws patchcull::Error on failure.
void write_ids_png(const std::string& path, const std::vector<std::uint32_t>& ids, int width, int height);

}  // namespace patchcull::gl
