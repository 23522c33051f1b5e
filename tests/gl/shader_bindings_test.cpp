// Every shader storage binding point of patchcull is declared once, in shaders/shared.h, and each
// number is used by one buffer only: passes leave their buffers bound, so two buffers sharing a
// number would let one pass read another's. The shaders and the GL sources name bindings by
// those constants, never by a literal number, and the other constant headers declare none.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "shared.h"

namespace fs = std::filesystem;

namespace {

std::string read_text(const fs::path& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

const fs::path kRoot = fs::path(PATCHCULL_SOURCE_DIR);

}  // namespace

TEST(ShaderBindings, EveryStorageBindingIsDeclaredOnceWithItsOwnNumber) {
    const std::string shared = read_text(kRoot / "shaders/shared.h");
    const std::regex binding_re(R"(PATCHCULL_CONST uint (kBinding\w+) = (\d+)u;)");
    std::map<unsigned, std::string> by_number;
    std::set<std::string> names;
    for (std::sregex_iterator it(shared.begin(), shared.end(), binding_re), end; it != end; ++it) {
        const std::string name = (*it)[1];
        const unsigned number = static_cast<unsigned>(std::stoul((*it)[2]));
        EXPECT_TRUE(names.insert(name).second) << name << " declared twice";
        const auto [at, fresh] = by_number.emplace(number, name);
        EXPECT_TRUE(fresh) << name << " and " << at->second << " share binding " << number;
    }
    EXPECT_GE(by_number.size(), 20u);
    EXPECT_EQ(by_number.begin()->first, 0u);
    // The numbers the C++ side compiles agree with the text (the regex read the right lines).
    EXPECT_EQ(by_number.at(patchcull::gl::shared::kBindingPtpPlanes), "kBindingPtpPlanes");
    EXPECT_EQ(by_number.at(patchcull::gl::shared::kBindingPatchTessScale), "kBindingPatchTessScale");

    // No other header declares a binding, and no shader or GL source writes one as a number.
    const std::regex declared_re(R"(CONST uint kBinding\w+)");
    const std::regex literal_re(R"(binding\s*=\s*\d)");
    const std::regex used_re(R"(\bkBinding\w+)");
    std::size_t shaders = 0;
    for (const char* dir : {"shaders", "src/gl", "src/gl_osd"})
        for (const auto& entry : fs::directory_iterator(kRoot / dir)) {
            if (!entry.is_regular_file() || entry.path().extension() == ".txt") continue;
            const std::string text = read_text(entry.path());
            if (entry.path().filename() != "shared.h") {
                EXPECT_FALSE(std::regex_search(text, declared_re)) << entry.path() << " declares a binding point";
            }
            if (entry.path().extension() == ".glsl") {
                ++shaders;
                EXPECT_FALSE(std::regex_search(text, literal_re)) << entry.path() << " writes a binding as a number";
            }
            for (std::sregex_iterator it(text.begin(), text.end(), used_re), end; it != end; ++it) {
                EXPECT_TRUE(names.count((*it)[0])) << entry.path() << " uses " << (*it)[0] << ", not in shared.h";
            }
        }
    EXPECT_GE(shaders, 10u);
}

TEST(ShaderBindings, SharedPatchBlocksAreDeclaredOnlyInPatchBuffers) {
    // shaders/patch_buffers.h declares the storage blocks of the per-patch buffers that several
    // shaders share; no other shader or header of shaders/ declares a block at one of its bindings
    // (patchcull_tcs.h excepted: shipped to engines on its own, it names its flag block itself).
    const std::string blocks = read_text(kRoot / "shaders/patch_buffers.h");
    const std::regex block_re(R"(binding\s*=\s*(kBinding\w+)\))");
    std::set<std::string> declared;
    for (std::sregex_iterator it(blocks.begin(), blocks.end(), block_re), end; it != end; ++it)
        declared.insert((*it)[1]);
    EXPECT_GE(declared.size(), 8u);
    EXPECT_TRUE(declared.count("kBindingControlPoints"));
    for (const auto& entry : fs::directory_iterator(kRoot / "shaders")) {
        const std::string name = entry.path().filename().string();
        if (!entry.is_regular_file() || name == "patch_buffers.h" || name == "patchcull_tcs.h") continue;
        const std::string text = read_text(entry.path());
        for (std::sregex_iterator it(text.begin(), text.end(), block_re), end; it != end; ++it)
            EXPECT_FALSE(declared.count((*it)[1]))
                << name << " declares the block at " << (*it)[1] << " (patch_buffers.h declares it)";
    }
}
