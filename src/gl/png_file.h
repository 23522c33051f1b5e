// PNG output of the GL library (colour, status and id images, window screenshots). Not a public
// header.
#pragma once

#include <stb_image_write.h>

#include <cstdio>
#include <string>
#include <vector>

#include "patchcull/core/error.h"

namespace patchcull::gl::detail {

// Writes an 8-bit PNG (rows top first, stride bytes apart) to path: encoded in memory, then
// written and closed with every step checked, so a full disk or a failing device is an error
// (stbi_write_png ignores failed writes: a truncated file and success).
inline void write_png_file(const std::string& path, int width, int height, int channels, const void* pixels,
                           int stride) {
    std::vector<unsigned char> bytes;
    auto append = [](void* context, void* data, int size) {
        auto* out = static_cast<std::vector<unsigned char>*>(context);
        out->insert(out->end(), static_cast<unsigned char*>(data), static_cast<unsigned char*>(data) + size);
    };
    if (!stbi_write_png_to_func(append, &bytes, width, height, channels, pixels, stride))
        throw Error(path + ": cannot write PNG: encoding failed");
    std::FILE* file = std::fopen(path.c_str(), "wb");
    if (!file) throw Error(path + ": cannot write PNG: cannot open the file");
    const bool written = std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size();
    const bool flushed = std::fflush(file) == 0;
    const bool closed = std::fclose(file) == 0;
    if (!written || !flushed || !closed) throw Error(path + ": cannot write PNG: write failed (disk full?)");
}

}  // namespace patchcull::gl::detail
