// Uses patchcull::import from an installed package: a shipped model loaded by name (ACC patches,
// one per quad) from the data of the package the program was built against, or from
// $PATCHCULL_DATA_DIR when the environment sets it. Prints one line per check; exit status 1 on
// any failure.
#include <cstdlib>
#include <fstream>
#include <string>

#include "check.h"
#include "patchcull/import/model_loader.h"

namespace pc = patchcull;

int main() {
    // Where the model must come from: the environment's folder, else the package's share/patchcull
    // (the consumer's CMakeLists passes find_package's patchcull_DATA_DIR), never a source tree.
    const char* env = std::getenv("PATCHCULL_DATA_DIR");
    const std::string expected_dir = env && *env ? env : CONSUMER_PACKAGE_DATA_DIR;
    const std::string path = pc::resolve_model_path("bigguy");
    // ACC makes one patch per quad of an all-quad mesh: count the OBJ's faces independently.
    std::ifstream obj(path);
    std::size_t faces = 0;
    for (std::string line; std::getline(obj, line);)
        if (line.rfind("f ", 0) == 0) ++faces;
    check(path == expected_dir + "/models/bigguy.obj",
          "bigguy resolves to " + path + " (expected under " + expected_dir + ")");
    if (faces > 0) {
        const pc::LoadedModel model = pc::load_model(path, pc::Scheme::acc, 0);
        check(model.rest.patches.size() == faces, path + ": " + std::to_string(model.rest.patches.size()) +
                                                      " ACC patches, " + std::to_string(faces) + " faces");
    } else {
        check(false, path + ": no faces read");
    }
    return failures == 0 ? 0 : 1;
}
