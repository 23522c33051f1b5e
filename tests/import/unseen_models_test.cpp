// Models we did not write: every OBJ file of Debian's assimp-testmodels package (installed by
// scripts/install-deps.sh) goes through both schemes. Each must either give finite patches that
// the frustum kernels cull with zero false culls, or fail with one clean patchcull::Error line
// that names the file. Nothing may crash or hang.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "patchcull/core/error.h"
#include "patchcull/eval/cull_eval.h"
#include "patchcull/import/model_loader.h"

using namespace patchcull;
namespace fs = std::filesystem;

namespace {

const char* kAssimpModels = "/usr/share/assimp/models";

std::vector<std::string> obj_files() {
    std::vector<std::string> files;
    if (!fs::exists(kAssimpModels)) return files;
    for (const auto& e : fs::recursive_directory_iterator(kAssimpModels))
        if (e.is_regular_file() && e.path().extension() == ".obj") files.push_back(e.path().string());
    std::sort(files.begin(), files.end());
    return files;
}

}  // namespace

TEST(UnseenModels, AssimpTestModelsLoadCleanlyOrFailWithOneLine) {
    const auto files = obj_files();
    if (files.empty()) GTEST_SKIP() << kAssimpModels << " missing: run scripts/install-deps.sh";
    int built = 0, refused = 0;
    for (const std::string& file : files)
        for (Scheme scheme : {Scheme::acc, Scheme::osd}) {
            SCOPED_TRACE(file + " " + scheme_name(scheme));
            try {
                const LoadedModel m = load_model(file, scheme, 0);
                ASSERT_GT(m.rest.patches.size(), 0u);
                for (const BezierPatch& p : m.rest.patches)
                    for (const Vec4& c : p.cp) ASSERT_TRUE(std::isfinite(c.x + c.y + c.z + c.w));
                const Bounds b = patch_bounds(m.rest);
                const DisplacementMap d = make_procedural_displacement(128, 0.05f * length(b.max - b.min));
                CullEvalOptions options;
                options.views = 200;
                options.mode = ViewMode::free;
                for (const CullMethodResult& r : evaluate_cull(m.rest, &d, options).methods)
                    EXPECT_EQ(r.false_culls, 0u) << r.name;
                ++built;
            } catch (const Error& e) {
                const std::string message = e.what();
                EXPECT_EQ(message.rfind(file, 0), 0u) << message;
                EXPECT_EQ(message.find('\n'), std::string::npos) << message;
                ++refused;
            }
        }
    // The package holds both usable meshes and deliberately broken files.
    EXPECT_GT(built, 10);
    EXPECT_GT(refused, 10);
}
