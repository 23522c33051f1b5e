// Uses patchcull::import from an installed package: with PATCHCULL_DATA_DIR set, a shipped model
// loaded from the installed data (ACC patches, one per quad). Prints one line per check; exit
// status 1 on any failure.
#include <cstdlib>
#include <fstream>
#include <string>

#include "check.h"
#include "patchcull/import/model_loader.h"

namespace pc = patchcull;

int main() {
    // The installed data: the test sets PATCHCULL_DATA_DIR to the package's share/patchcull.
    // ACC makes one patch per quad of an all-quad mesh: count the OBJ's faces independently.
    if (const char* dir = std::getenv("PATCHCULL_DATA_DIR")) {
        const std::string path = pc::shipped_model_path("bigguy.obj");
        std::ifstream obj(path);
        std::size_t faces = 0;
        for (std::string line; std::getline(obj, line);)
            if (line.rfind("f ", 0) == 0) ++faces;
        const pc::LoadedModel model = pc::load_model(path, pc::Scheme::acc, 0);
        check(path.rfind(dir, 0) == 0 && faces > 0 && model.rest.patches.size() == faces,
              path + ": " + std::to_string(model.rest.patches.size()) + " ACC patches, " + std::to_string(faces) +
                  " faces");
    } else {
        check(false, "PATCHCULL_DATA_DIR is not set");
    }
    return failures == 0 ? 0 : 1;
}
