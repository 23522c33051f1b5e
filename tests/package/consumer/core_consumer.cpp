// Uses patchcull::core (the kernels alone) from an installed package: the built-in teapot culled
// by the frustum kernels (scalar and SIMD) for three cameras, each decision checked against
// sampled points of the patch. Prints one line per check; exit status 1 on any failure.
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "check.h"
#include "patchcull/core/camera.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/teapot.h"
#include "patchcull/version.h"

namespace pc = patchcull;

namespace {

// Whether some sampled point of the patch is inside the clip volume (0 <= z <= w): then the
// kernel must not have culled it.
bool sample_inside(const pc::BezierPatch& patch, const pc::Mat4& clip) {
    for (int j = 0; j <= 16; ++j)
        for (int i = 0; i <= 16; ++i) {
            const pc::Vec3 p = pc::evaluate_position(patch, i / 16.0f, j / 16.0f);
            float c[4];
            for (int r = 0; r < 4; ++r)
                c[r] = clip.at(r, 0) * p.x + clip.at(r, 1) * p.y + clip.at(r, 2) * p.z + clip.at(r, 3);
            if (c[3] > 0 && -c[3] <= c[0] && c[0] <= c[3] && -c[3] <= c[1] && c[1] <= c[3] && 0 <= c[2] && c[2] <= c[3])
                return true;
        }
    return false;
}

}  // namespace

int main() {
    const pc::Version v = pc::version();
    check(std::strcmp(pc::version_string(), PATCHCULL_VERSION_STRING) == 0 && v.major == PATCHCULL_VERSION_MAJOR &&
              v.minor == PATCHCULL_VERSION_MINOR && v.patch == PATCHCULL_VERSION_PATCH &&
              std::strcmp(PATCHCULL_VERSION_STRING, CONSUMER_PACKAGE_VERSION) == 0,
          std::string("library ") + pc::version_string() + ", headers " + PATCHCULL_VERSION_STRING + ", package " +
              CONSUMER_PACKAGE_VERSION);

    const std::vector<pc::BezierPatch> patches = pc::teapot_patches();
    const pc::PatchBatch batch = pc::make_batch(patches);
    struct View {
        const char* name;
        pc::Vec3 target;
        bool expect_none, expect_all;
    };
    // The teapot spans about x in [-3, 3.5], z in [0, 3.2]; the eye is at (0, -12, 1.5).
    const View views[] = {{"at the teapot", {0, 0, 1.5f}, true, false},
                          {"away from it", {0, -24, 1.5f}, false, true},
                          {"at its spout side", {6.5f, 0, 1.5f}, false, false}};
    for (const View& view : views) {
        pc::Camera camera;
        camera.eye = {0, -12, 1.5f};
        camera.target = view.target;
        camera.up = {0, 0, 1};
        const pc::Mat4 clip = camera.view_projection();
        const pc::FrustumPlanes planes = pc::make_frustum_planes(clip, pc::ClipDepth::zero_to_one);
        std::vector<std::uint8_t> scalar(patches.size()), simd(patches.size());
        pc::cull_frustum_scalar(batch.view(), nullptr, planes, scalar.data());
        pc::cull_frustum_simd(batch.view(), nullptr, planes, simd.data());
        std::size_t culled = 0, wrong = 0;
        for (std::size_t p = 0; p < patches.size(); ++p) {
            culled += scalar[p];
            if (scalar[p] && sample_inside(patches[p], clip)) ++wrong;
        }
        const bool count_ok = view.expect_none  ? culled == 0
                              : view.expect_all ? culled == patches.size()
                                                : culled > 0 && culled < patches.size();
        check(count_ok && wrong == 0 && scalar == simd,
              std::string(view.name) + ": " + std::to_string(culled) + " of " + std::to_string(patches.size()) +
                  " culled (" + pc::simd_target_name() + "), " + std::to_string(wrong) + " with a visible sample");
    }

    return failures == 0 ? 0 : 1;
}
