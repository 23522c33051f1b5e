// examples/04_scene_object_level.cpp: a scene of many objects on the CPU. The object level
// (patchcull/import/scene_object_level.h) culls whole objects by their boxes through a BVH, and the
// back-facing clusters of rigid one-sided objects (Johannsen & Carter's clustered back-face
// culling); then the patch frustum kernel runs only on the patches it left
// (cull_frustum_after_objects, object_culling.h), so a culled object costs no patch test.
//
// Usage: 04_scene_object_level [SCENE.json] [--frames N] [--detail-cull PIXELS]
//   SCENE.json  a scene file (docs/SCENE_FORMAT.md); default: the built-in city at 3x3 blocks,
//               16 characters (ACC patches, animated, some rigid, the frogs displaced)
//   --frames N  frames along the scene's camera path, N in 1..100, default 3
//   --detail-cull PIXELS  also cull objects that cover fewer pixels (of a 640x360 view) than
//               PIXELS: NOT conservative (off by default); a large value shows the check failing
// Prints one line per frame. Checks every culled patch (by the object level or the kernel)
// against the ground truth (ground_truth.h, 17x17 samples in double): it is a false cull when a
// sample lies in the view volume and could be seen there: always for two-sided patches (open or
// displaced), and for one-sided ones when that sample's tangent plane faces the eye. Exit status:
// 0 no false cull; 1 a false cull, or nothing culled over the run (the check proved nothing); 2
// bad arguments or an unreadable scene (one line).
#include <algorithm>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "patchcull/core/error.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/ground_truth.h"
#include "patchcull/import/builtin_scenes.h"
#include "patchcull/import/scene_file.h"
#include "patchcull/import/scene_object_level.h"
#include "patchcull/import/scene_poser.h"
#include "patchcull/objects/object_culling.h"

namespace pc = patchcull;

namespace {

constexpr int kViewHeight = 360;  // pixels of a 640x360 view: the scale of detail culling's areas

struct Options {
    std::string scene_file;  // empty: the built-in city, small
    int frames = 3;
    int detail_pixels = 0;
};

Options parse_options(int argc, char** argv) {
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--frames" || arg == "--detail-cull") {
            const std::string v = i + 1 < argc ? argv[++i] : "";
            int& out = arg == "--frames" ? o.frames : o.detail_pixels;
            const int lo = arg == "--frames" ? 1 : 0, hi = arg == "--frames" ? 100 : 1000000;
            const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), out);
            if (v.empty() || v[0] == '-' || ec != std::errc() || end != v.data() + v.size() || out < lo || out > hi)
                throw pc::Error(arg + ": expected an integer in " + std::to_string(lo) + ".." + std::to_string(hi) +
                                ", got " + pc::quote_input(v));
        } else if (arg.rfind("-", 0) == 0 || !o.scene_file.empty()) {
            throw pc::Error("unknown argument " + pc::quote_input(arg) +
                            " (usage: [SCENE.json] [--frames N] [--detail-cull PIXELS])");
        } else {
            o.scene_file = arg;
        }
    }
    return o;
}

int run(const Options& options) {
    pc::CityParams city;
    city.blocks_x = city.blocks_z = 3;
    city.characters = 16;
    pc::Scene scene = options.scene_file.empty() ? pc::make_city_scene(pc::Scheme::acc, city)
                                                 : pc::load_scene_file(options.scene_file);
    // Patch clusters may cull only when patches are drawn one-sided: every model a closed solid.
    pc::ObjectLevelSetup setup;
    setup.patches_one_sided =
        std::all_of(scene.models.begin(), scene.models.end(), [](const pc::LoadedModel& m) { return m.closed; });
    pc::SceneObjectLevel level(scene, setup);  // reorders occluder triangles: build before drawing them
    pc::ScenePoser poser(scene);
    pc::ObjectCullOptions object_options;
    object_options.method = pc::ObjectCullMethod::bvh_backface;
    object_options.detail_min_pixels = float(options.detail_pixels);
    std::printf("%s: %zu instances, %zu environment objects, %zu patches; patches %s\n", scene.name.c_str(),
                scene.instances.size(), scene.environment.size(), scene.patch_count(),
                setup.patches_one_sided ? "one-sided" : "two-sided");

    const std::size_t n = scene.patch_count();
    pc::PatchBatch batch(n);  // caller-owned, refilled every frame: no allocation after this
    std::vector<float> margins(n, 0.0f);
    std::vector<std::uint8_t> culled(n);
    std::vector<pc::Vec3> points(pc::kGroundTruthGrid * pc::kGroundTruthGrid);
    std::vector<pc::PlaneD> planes(points.size());
    const std::vector<pc::Camera> cameras = scene.camera_path(options.frames, 16.0f / 9.0f);
    std::size_t total_culled = 0, false_culls = 0;
    for (int f = 0; f < options.frames; ++f) {
        const float t = f / 30.0f;  // seconds
        const std::vector<pc::BezierPatch>& pose = poser.pose(t);
        const std::vector<pc::DisplacementRange>& ranges = poser.displacement_ranges();  // empty: none
        for (std::size_t i = 0; i < n; ++i) {
            batch.set(i, pose[i]);
            if (!ranges.empty()) margins[i] = ranges[i].max_abs();
        }
        const pc::Camera& camera = cameras[f];
        const pc::ObjectCullResult& objects = level.cull(pose, ranges, t, camera, kViewHeight, object_options);
        const pc::FrustumPlanes frustum = pc::make_frustum_planes(camera.view_projection(), pc::ClipDepth::zero_to_one);
        const std::size_t tested =
            pc::cull_frustum_after_objects(objects, batch.view(), margins.data(), frustum, culled.data());

        // Ground truth for every culled patch (object spans and kernel alike).
        std::size_t culled_now = 0, wrong = 0;
        for (std::size_t i = 0; i < n; ++i) {
            if (!culled[i]) continue;
            ++culled_now;
            const bool displaced = margins[i] > 0;
            const pc::Vec2* uv = poser.texcoords().empty() ? nullptr : poser.texcoords()[i].data();
            const pc::Vec2 unit[4] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
            pc::sample_displaced_patch(pose[i], nullptr, uv ? uv : unit, displaced ? &scene.displacement : nullptr,
                                       pc::kGroundTruthGrid, points.data());
            const pc::SampleSphere sphere = pc::bounding_sphere(points.data(), points.size());
            if (pc::sphere_outside_clip_volume(camera.view_projection(), sphere)) continue;  // fast, exact
            pc::sample_tangent_planes(pose[i], pc::kGroundTruthGrid, planes.data());
            for (std::size_t k = 0; k < points.size(); ++k)
                if (pc::any_point_in_clip_volume(camera.view_projection(), &points[k], 1) &&
                    (!setup.patches_one_sided || displaced || pc::any_plane_faces_eye(&planes[k], 1, camera.eye))) {
                    ++wrong;
                    break;
                }
        }
        const pc::ObjectCullStats& s = objects.stats;
        std::printf(
            "frame %d: objects culled %zu (frustum) + %zu (back-facing) + %zu (detail) of %zu; patches skipped %zu "
            "(%zu in back-facing clusters), tested %zu, culled in all %zu of %zu; %zu false culls\n",
            f, s.frustum_culled, s.backface_culled, s.detail_culled, s.total, s.patches_culled,
            s.backface_patches_culled, tested, culled_now, n, wrong);
        total_culled += s.patches_culled;
        false_culls += wrong;
    }
    if (total_culled == 0) {
        std::printf("FAILED: the object level culled nothing, so the check proved nothing\n");
        return 1;
    }
    std::printf(false_culls ? "FAILED: %zu false culls\n" : "ok: %zu false culls\n", false_culls);
    return false_culls ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return run(parse_options(argc, argv));
    } catch (const std::exception& e) {  // patchcull::Error: "file: objects[3].transform: ...", "--frames: ..."
        std::fprintf(stderr, "%s\n", pc::printable_line(e.what()).c_str());
        return 2;
    }
}
