// patchcull/error.h: the one exception type thrown by patchcull's loaders and builders.
//
// Kernels never throw. Loaders and factories throw patchcull::Error whose what() is a complete
// one-line message naming the file and line (or the flag) at fault, e.g.
// "model.obj:12: non-finite coordinate 'nan'". The CLI prints it and exits with status 2.
#pragma once

#include <stdexcept>
#include <string>

namespace patchcull {

class Error : public std::runtime_error {
public:
    explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace patchcull
