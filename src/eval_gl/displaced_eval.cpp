// Niessner & Loop's Table 1 (displaced_eval.h).
//
// The renderer's TES displaces along the unit normal of the patch's own derivatives, as the
// bounds assume; the depth of the unculled render is what Niessner & Loop §3's pipeline converges
// to on a static view (its visible set stable). The running pipeline tests the displaced patches
// with DisplacedPass against its own Hi-Z, built from the patches the previous frame found visible.
#include "patchcull/eval_gl/displaced_eval.h"

#include <algorithm>

#include "patchcull/core/hiz.h"
#include "patchcull/eval_gl/reference_frame.h"
#include "patchcull/gl/gl_cull_flags.h"

namespace patchcull::eval_gl {

std::size_t DisplacedEvalResult::false_culls() const {
    std::size_t total = 0;
    for (const DisplacedEvalRow& row : rows) total += row.false_culls + row.pipeline_false_culls;
    return total;
}

DisplacedEvalResult run_displaced_eval(const LoadedModel& model, const DisplacementMap& map,
                                       const DisplacedEvalOptions& o, const RunProgress& progress) {
    const int width = o.width, height = o.height;
    const std::vector<DisplacementRange> ranges = displacement_ranges(model.rest, &map);
    const std::size_t patches = model.rest.patches.size();
    const PatchBatch batch = make_batch(model.rest.patches);

    gl::GlContext context = gl::GlContext::create_headless();
    gl::PatchRenderer renderer(context);
    gl::PatchAttributes attributes;
    for (std::size_t p = 0; p < patches; ++p) {
        attributes.max_displacement.push_back(ranges[p].max_abs());
        const PatchInfo& info = model.rest.info[p];
        attributes.texcoords.push_back({info.uv[0], info.uv[1], info.uv[2], info.uv[3]});
        attributes.depth.push_back(info.depth);
    }
    renderer.set_patches(model.rest.patches, attributes);
    renderer.set_displacement_map(map);
    // The running pipeline on the same patches, with the ranges for its displaced pass.
    gl::CullPipeline pipeline(context);
    gl::PatchAttributes pipeline_attributes = attributes;
    pipeline_attributes.max_displacement.clear();  // from the ranges
    pipeline_attributes.displacement_ranges = ranges;
    pipeline.set_patches(model.rest.patches, pipeline_attributes);
    pipeline.renderer().set_displacement_map(map);
    ViewGenerator views(patch_bounds(model.rest), ViewMode::contain, o.seed, float(width) / float(height));

    DisplacedEvalResult result;
    result.patches = patches;
    std::vector<DisplacedEvalRow>& rows = result.rows;
    for (DisplacedBoundKind bound : {DisplacedBoundKind::oobb, DisplacedBoundKind::caf})
        for (NormalConeKind cone : {NormalConeKind::full, NormalConeKind::acon, NormalConeKind::con}) {
            DisplacedEvalRow row;
            row.bound = bound;
            row.cone = cone;
            rows.push_back(row);
        }
    std::vector<std::uint8_t> decision(patches);
    std::vector<bool> visible(patches);
    HiZPyramid hiz;
    // One unit per view and bound (the running pipeline per bound is most of a view's time).
    progress.begin(std::uint64_t(o.views) * rows.size());
    std::uint64_t done = 0;
    for (int v = 0; v < o.views; ++v) {
        Camera camera = views.next();
        camera.depth = o.clip_depth;                                                    // drawn and culled in it
        gl::RenderParams params = render_params(camera, width, height, o.tess, false);  // displaced: two-sided
        params.use_cull_flags = false;
        renderer.render(params);
        const std::vector<std::uint32_t> ids = renderer.read_ids();
        hiz.build(renderer.read_depth_bottom_up().data(), width, height, camera.depth);
        std::fill(visible.begin(), visible.end(), false);
        for (std::uint32_t id : ids)
            if (id != 0 && (id & gl::kIdOccluderBit) == 0 && id <= patches) visible[id - 1] = true;
        const DisplacedCullView cull_view = make_displaced_cull_view(camera.view(), camera.projection(), camera.depth);
        for (DisplacedEvalRow& row : rows) {
            cull_displaced_occlusion(batch.view(), ranges.data(), row.bound, row.cone, cull_view, hiz, decision.data());
            std::size_t culled = 0;
            for (std::size_t p = 0; p < patches; ++p) {
                if (decision[p] == kHiZVisible) continue;
                ++culled;
                row.false_culls += visible[p] ? 1 : 0;
            }
            row.rate_sum += double(culled) / double(std::max<std::size_t>(patches, 1));
            gl::PipelineParams pp;
            pp.frame.render = params;
            pp.frame.render.use_cull_flags = true;
            pp.frame.cull = static_cast<gl::CullMode>(gl::kCullFrustum | gl::kCullOcclusion);
            pp.frame.timing = gl::TimingMethod::off;
            pp.bound = row.bound;
            pp.cone = row.cone;
            const ConvergedFrame converged = converge_frame(pipeline, pp, 8);
            row.pipeline_rate_sum += double(converged.stats.frustum_culled + converged.stats.occlusion_culled) /
                                     double(std::max<std::size_t>(patches, 1));
            row.pipeline_frames_sum += converged.frames;
            const gl::FrameCapture culled_frame = capture_culled_frame(pipeline.renderer());
            const ReferenceFrame reference = render_reference(pipeline.renderer(), pp.frame.render);
            row.pipeline_false_culls += gl::compare_frames(reference.capture, culled_frame).false_culled.size();
            progress.done(++done);
        }
    }
    return result;
}

}  // namespace patchcull::eval_gl
