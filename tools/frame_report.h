// What `render` reports of one frame, the same for both APIs: the counts, times and submitted
// patches of gl_pipeline.h's FrameStats or vk_renderer.h's CullFrameStats (the same member
// names), as the JSON keys and the text line of cmd_render.cpp's header. Each caller adds its own
// keys (verification, posing, object level, validation).
#pragma once

#include <cstdio>

#include <nlohmann/json.hpp>

namespace patchcull::cli {

/// {"frame","pass1_drawn","pass2_drawn","frustum_culled","backpatch_culled","occlusion_culled",
///  "displaced_occlusion_culled","visible","newly_visible","fused_pass","submitted":{"pass1","pass2"}},
/// without "ms" (frame_ms_json: the GL run adds its own parts to it).
template <class Stats>
nlohmann::json frame_counts_json(int frame, const Stats& s) {
    return {{"frame", frame},
            {"pass1_drawn", s.pass1_drawn},
            {"pass2_drawn", s.pass2_drawn},
            {"frustum_culled", s.frustum_culled},
            {"backpatch_culled", s.backpatch_culled},
            {"occlusion_culled", s.occlusion_culled},
            {"displaced_occlusion_culled", s.displaced_occlusion_culled},
            {"visible", s.visible},
            {"newly_visible", s.newly_visible},
            {"fused_pass", s.fused_pass},
            {"submitted", {{"pass1", s.pass1_submitted}, {"pass2", s.pass2_submitted}}}};
}

/// "ms": {"pass1","hiz","cull","pass2","total"}.
template <class Stats>
nlohmann::json frame_ms_json(const Stats& s) {
    return {
        {"pass1", s.pass1_ms}, {"hiz", s.hiz_ms}, {"cull", s.cull_ms}, {"pass2", s.pass2_ms}, {"total", s.total_ms}};
}

/// The text line of a frame without its end ("; false culls N" and the newline are the caller's).
template <class Stats>
void print_frame_line(int frame, const Stats& s) {
    std::printf(
        "frame %d: drawn %zu + %zu of %zu; culled frustum %zu, back-patch %zu, occlusion %zu (displaced %zu); "
        "ms pass1 %.1f hiz %.1f cull %.1f pass2 %.1f",
        frame, s.pass1_drawn, s.pass2_drawn, s.patches, s.frustum_culled, s.backpatch_culled, s.occlusion_culled,
        s.displaced_occlusion_culled, s.pass1_ms, s.hiz_ms, s.cull_ms, s.pass2_ms);
}

}  // namespace patchcull::cli
