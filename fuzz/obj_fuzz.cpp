// libFuzzer target: the OBJ reader (patchcull/import/obj.h) on arbitrary bytes. Only parsing and the
// mesh checks of input_checks.h run: subdivision (OpenSubdiv) is not part of this target.
#include <cstdio>
#include <cstdlib>

#include "input_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string violation = patchcull::fuzz::check_obj_input(data, size);
    if (!violation.empty()) {
        std::fprintf(stderr, "obj_fuzz: %s\n", violation.c_str());
        std::abort();  // libFuzzer reports it as a crash and saves the input
    }
    return 0;
}
