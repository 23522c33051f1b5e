// Deterministic mutation test of the input loaders: the checked-in fuzz corpus (fuzz/corpus) and
// a few thousand mutants of it (byte flips, truncations, inserted control bytes and invalid
// UTF-8, huge numbers and indices, long lines, big faces) go through the same checks as the
// libFuzzer targets (fuzz/input_checks.h). It runs with any compiler, so the malformed cases are
// exercised even where clang's libFuzzer is not there.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "../../fuzz/input_checks.h"

namespace fs = std::filesystem;
using Bytes = std::string;

namespace {

std::vector<std::pair<std::string, Bytes>> corpus(const char* kind) {
    std::vector<std::pair<std::string, Bytes>> files;
    for (const auto& entry : fs::directory_iterator(fs::path(PATCHCULL_SOURCE_DIR) / "fuzz" / "corpus" / kind)) {
        std::ifstream in(entry.path(), std::ios::binary);
        files.emplace_back(entry.path().filename().string(),
                           Bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()));
    }
    std::sort(files.begin(), files.end());  // directory order is not deterministic
    return files;
}

// std::mt19937's output is fixed by the standard (its distributions are not): mutants are the
// same on every platform.
struct Rng {
    std::mt19937 engine;
    explicit Rng(std::uint32_t seed) : engine(seed) {}
    std::size_t below(std::size_t n) { return n == 0 ? 0 : engine() % n; }
};

const char* const kHugeNumbers[] = {"1e39",        "-1e39",      "1e-50",      "99999999999999999999",
                                    "-2147483649", "4294967296", "4294967297", "nan",
                                    "inf",         "-0",         "0x7fffffff", "1e308"};
const char* const kHugeIndices[] = {"0",
                                    "-1",
                                    "999999999",
                                    "-999999999",
                                    "2147483648",
                                    "4294967295",
                                    "18446744073709551617",
                                    "1//4294967296",
                                    "1/999999999/1",
                                    "-9223372036854775808"};
const char kControlBytes[] = {'\0',   '\x01', '\x07', '\x08', '\x0b', '\x0c',
                              '\x1b', '\x7f', '\xff', '\xc3', '\xe2', '\r'};

// One mutation of data; OBJ-aware ones replace whole tokens so that the parser gets past them.
void mutate(Bytes& data, Rng& rng, bool text) {
    switch (rng.below(text ? 9 : 6)) {
        case 0:  // flip one bit
            if (!data.empty()) data[rng.below(data.size())] ^= static_cast<char>(1u << rng.below(8));
            break;
        case 1:  // truncate
            data.resize(rng.below(data.size() + 1));
            break;
        case 2:  // insert a control byte or a piece of an invalid UTF-8 sequence
            data.insert(rng.below(data.size() + 1), 1, kControlBytes[rng.below(sizeof kControlBytes)]);
            break;
        case 3:  // overwrite a byte with any value
            if (!data.empty()) data[rng.below(data.size())] = static_cast<char>(rng.below(256));
            break;
        case 4: {  // duplicate a slice (repeated records, chunks)
            const std::size_t at = rng.below(data.size() + 1),
                              length = rng.below(std::min<std::size_t>(64, data.size() - at) + 1);
            data.insert(at, data.substr(at, length));
            break;
        }
        case 5: {  // overwrite 4 bytes with a big-endian huge value (PNG widths, heights, lengths)
            if (data.size() < 4) break;
            const std::size_t at = rng.below(data.size() - 3);
            const std::uint32_t values[] = {0xFFFFFFFFu, 0x7FFFFFFFu, 0x01000000u, 0x00FFFFFFu, 0x80000000u, 0};
            const std::uint32_t v = values[rng.below(std::size(values))];
            for (int k = 0; k < 4; ++k) data[at + k] = static_cast<char>(v >> (24 - 8 * k));
            break;
        }
        case 6: {  // replace a token with a huge or non-finite number, or a huge index
            std::vector<std::size_t> starts;
            for (std::size_t i = 0; i < data.size(); ++i)
                if (data[i] != ' ' && data[i] != '\n' && (i == 0 || data[i - 1] == ' ')) starts.push_back(i);
            if (starts.empty()) break;
            const std::size_t at = starts[rng.below(starts.size())];
            std::size_t end = at;
            while (end < data.size() && data[end] != ' ' && data[end] != '\n') ++end;
            const bool index = rng.below(2) == 0;
            data.replace(at, end - at,
                         index ? kHugeIndices[rng.below(std::size(kHugeIndices))]
                               : kHugeNumbers[rng.below(std::size(kHugeNumbers))]);
            break;
        }
        case 7: {  // a long line without a newline, of garbage or of one token repeated
            const std::size_t at = rng.below(data.size() + 1);
            const Bytes unit = rng.below(2) == 0 ? Bytes("\x01\xff") : Bytes(" 1");
            Bytes run;
            for (int k = 0; k < 3000; ++k) run += unit;
            data.insert(at, run);
            break;
        }
        default: {  // a big face over the vertices read so far, or a tag line
            const char* const lines[] = {"\nt crease 2/1/0 0 0 1\n",
                                         "\nt creese 2/1/0 0 1 1\n",
                                         "\nt corner 9/1/0 0 1 2 3 4 5 6 7 8 1\n",
                                         "\nf 1//1 2//1 3//99\n",
                                         "\xEF\xBB\xBF",
                                         "\nvn 0 0 1\n"};
            const std::size_t choice = rng.below(std::size(lines) + 1);
            if (choice < std::size(lines)) {
                data.insert(rng.below(data.size() + 1), lines[choice]);
            } else {
                Bytes face = "\nf";
                for (int k = 1; k <= 2000; ++k) {
                    face += ' ';  // appended piecewise: GCC 12's -Wrestrict misreads " " + std::string
                    face += std::to_string(k);
                }
                data += face + "\n";
            }
            break;
        }
    }
}

template <class Check>
void run_mutants(const char* kind, bool text, int mutants_per_file, Check check) {
    const auto files = corpus(kind);
    ASSERT_GE(files.size(), 20u) << "fuzz/corpus/" << kind << " is missing files";
    Rng rng(12345);
    int failures = 0, runs = 0;
    for (const auto& [name, bytes] : files) {
        const std::string original = check(bytes);
        EXPECT_EQ(original, "") << kind << "/" << name;
        for (int m = 0; m < mutants_per_file && failures < 10; ++m) {
            Bytes data = bytes;
            const std::size_t mutations = 1 + rng.below(4);
            for (std::size_t k = 0; k < mutations; ++k) mutate(data, rng, text);
            const std::string violation = check(data);
            ++runs;
            if (!violation.empty()) {
                ++failures;
                ADD_FAILURE() << kind << "/" << name << " mutant " << m << ": " << violation;
            }
        }
    }
    EXPECT_GT(runs, 2000);
}

std::string check_obj(const Bytes& b) {
    return patchcull::fuzz::check_obj_input(reinterpret_cast<const std::uint8_t*>(b.data()), b.size());
}
std::string check_png(const Bytes& b) {
    return patchcull::fuzz::check_png_input(reinterpret_cast<const std::uint8_t*>(b.data()), b.size());
}

}  // namespace

TEST(InputMutation, ObjReaderOnCorpusAndMutants) { run_mutants("obj", true, 120, check_obj); }

TEST(InputMutation, PngLoaderOnCorpusAndMutants) { run_mutants("png", false, 120, check_png); }

// The checks themselves must be able to fail, or the test above proves nothing.
TEST(InputMutation, ChecksRejectWhatTheyShould) {
    using namespace patchcull::fuzz;
    EXPECT_NE(check_message("two\nlines"), "");
    EXPECT_NE(check_message("bad \x1B[2J"), "");
    EXPECT_NE(check_message("bad \xFF"), "");
    EXPECT_NE(check_message(std::string(kMaxMessageBytes + 1, 'x').c_str()), "");
    EXPECT_EQ(check_message("fuzz.obj:3: unknown record 'x'"), "");
    patchcull::ControlMesh mesh;
    mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    mesh.face_offsets = {0, 3};
    mesh.face_vertices = {0, 1, 2};
    EXPECT_EQ(check_mesh(mesh), "");
    mesh.positions[1].y = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(check_mesh(mesh), "non-finite position");
    mesh.positions[1].y = 0;
    mesh.face_vertices[2] = 3;
    EXPECT_EQ(check_mesh(mesh), "face vertex out of range");
    mesh.face_vertices[2] = 2;
    mesh.creases.push_back({1, 1, 1.0f});
    EXPECT_EQ(check_mesh(mesh), "invalid crease");
}
