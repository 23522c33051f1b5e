// libFuzzer target: the PNG height-map loader (patchcull/import/image.h) on arbitrary bytes.
#include <cstdio>
#include <cstdlib>

#include "input_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string violation = patchcull::fuzz::check_png_input(data, size);
    if (!violation.empty()) {
        std::fprintf(stderr, "png_fuzz: %s\n", violation.c_str());
        std::abort();  // libFuzzer reports it as a crash and saves the input
    }
    return 0;
}
