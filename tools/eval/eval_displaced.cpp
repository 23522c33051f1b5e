// `patchcull eval displaced MODEL [--split N] [--views N] [--displace FILE.png|procedural]
// [--displace-scale X] --json`: Niessner & Loop's Table 1 (§4.2, §6.2): cull rates of the six bounds of a
// displaced patch, {oobb, caf} x {full, acon, con} (patchcull/core/displaced_bounds.h), by the frustum
// and by occlusion inside the object, over views that contain the whole object.
//
// Per view (camera.h, contain mode): the displaced model is rendered unculled (GPU, the renderer's
// TES displaces along the unit normal of the patch's own derivatives, as the bounds assume); its
// depth buffer gives the CPU Hi-Z pyramid (hiz.h), which is what Niessner & Loop §3's pipeline converges
// to on a static view (its visible set stable); each bound is then tested against the frustum and
// that pyramid (cull_displaced_occlusion). A patch culled although its id is in the unculled id
// buffer is a false cull.
// Next to these converged-depth rates, the running pipeline's (temporal coherence, Niessner & Loop §3):
// per view and combination, CullPipeline::render_frame (frustum + occlusion; the displaced patches
// tested by DisplacedPass against the pipeline's own Hi-Z, built from the patches the previous
// frame found visible) from a first frame until its visible set is stable (at most 8 frames), its
// last frame compared with the unculled render (render_reference: a false cull is judged per
// patch). Output (--json):
//   {"model","clip_depth","patches","views","displace","displace_scale","size","tess","seed",
//    "rows":[{"bound":"oobb"|"caf","cone":"full"|"acon"|"con","cull_rate":0..1,"false_culls":n,
//             "pipeline_cull_rate":0..1,"pipeline_frames":mean,"pipeline_false_culls":n}, ...]}
// with one row per combination (cull_rate, pipeline_cull_rate: the mean over views of the culled
// fraction).
#include "eval_displaced.h"

#include <algorithm>
#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "cli_options.h"
#include "commands.h"
#include "patchcull/core/displaced_bounds.h"
#include "patchcull/core/error.h"
#include "patchcull/gl/gl_verification.h"
#include "eval_temporal.h"
#include "progress.h"
#include "render_support.h"

namespace patchcull::cli {

int run_displaced_eval(const DisplacedEvalOptions& o) {
    int width = 0, height = 0;
    parse_size("--size", o.size, width, height);
    ModelOptions model_options;
    model_options.model = o.model;
    model_options.scheme = o.scheme;
    model_options.split = o.split;
    model_options.displace = o.displace;
    model_options.displace_scale = o.displace_scale;
    const LoadedModel model = load_model_from_options(model_options);
    print_warnings(model.warnings);
    const DisplacementMap map = displacement_from_options(model_options, model);
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
    const ClipDepth clip_depth = parse_clip_depth_option(o.clip_depth);

    struct Row {
        DisplacedBoundKind bound;
        NormalConeKind cone;
        double rate_sum = 0;
        std::size_t false_culls = 0;
        double pipeline_rate_sum = 0, pipeline_frames_sum = 0;
        std::size_t pipeline_false_culls = 0;
    };
    std::vector<Row> rows;
    for (DisplacedBoundKind bound : {DisplacedBoundKind::oobb, DisplacedBoundKind::caf})
        for (NormalConeKind cone : {NormalConeKind::full, NormalConeKind::acon, NormalConeKind::con})
            rows.push_back({bound, cone});
    std::vector<std::uint8_t> decision(patches);
    std::vector<bool> visible(patches);
    HiZPyramid hiz;
    // One unit per view and bound (the running pipeline per bound is most of a view's time).
    Progress progress("eval displaced", "view-bounds", std::uint64_t(o.views) * rows.size(), progress_wanted(o.json));
    std::uint64_t done = 0;
    for (int v = 0; v < o.views; ++v) {
        Camera camera = views.next();
        camera.depth = clip_depth;  // drawn and culled in it
        gl::RenderParams params = render_params(camera, width, height, o.tess, false);  // displaced: two-sided
        params.use_cull_flags = false;
        renderer.render(params);
        const std::vector<std::uint32_t> ids = renderer.read_ids();
        hiz.build(renderer.read_depth_bottom_up().data(), width, height, camera.depth);
        std::fill(visible.begin(), visible.end(), false);
        for (std::uint32_t id : ids)
            if (id != 0 && (id & gl::kIdOccluderBit) == 0 && id <= patches) visible[id - 1] = true;
        const DisplacedCullView cull_view = make_displaced_cull_view(camera.view(), camera.projection(), camera.depth);
        for (Row& row : rows) {
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
            pp.frame.cull = static_cast<gl::CullMode>(gl::kFlagFrustum | gl::kFlagOcclusion);
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
            progress.step(++done);
        }
    }
    nlohmann::json out;
    out["model"] = model.name;
    out["clip_depth"] = clip_depth_name(clip_depth);
    out["patches"] = patches;
    out["views"] = o.views;
    out["displace"] = o.displace;
    out["displace_scale"] = map.scale;
    out["size"] = {width, height};
    out["tess"] = o.tess;
    out["seed"] = o.seed;
    out["rows"] = nlohmann::json::array();
    for (const Row& row : rows)
        out["rows"].push_back({{"bound", displaced_bound_name(row.bound)},
                               {"cone", normal_cone_name(row.cone)},
                               {"cull_rate", row.rate_sum / o.views},
                               {"false_culls", row.false_culls},
                               {"pipeline_cull_rate", row.pipeline_rate_sum / o.views},
                               {"pipeline_frames", row.pipeline_frames_sum / o.views},
                               {"pipeline_false_culls", row.pipeline_false_culls}});
    if (o.json) {
        std::cout << out.dump() << "\n";
    } else {
        std::printf("%s: %zu patches, %d whole-object views at %dx%d, level %d, displacement %s (scale %g)\n",
                    model.name.c_str(), patches, o.views, width, height, o.tess, o.displace.c_str(), map.scale);
        for (const Row& row : rows)
            std::printf("  %-4s %-4s  cull rate %6.2f%%  false culls %zu   running pipeline %6.2f%% (%.1f frames), "
                        "false culls %zu\n",
                        displaced_bound_name(row.bound), normal_cone_name(row.cone), 100 * row.rate_sum / o.views,
                        row.false_culls, 100 * row.pipeline_rate_sum / o.views, row.pipeline_frames_sum / o.views,
                        row.pipeline_false_culls);
    }
    std::size_t false_total = 0;
    for (const Row& row : rows) false_total += row.false_culls + row.pipeline_false_culls;
    return false_total > 0 ? 1 : 0;  // a false cull breaks the conservative promise, as in `render --verify`
}

}  // namespace patchcull::cli
