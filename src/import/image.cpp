// PNG height maps through stb_image (patchcull/image.h). libstb ships the implementation.
#include "patchcull/image.h"

#include <stb/stb_image.h>

#include <cmath>

#include "patchcull/error.h"

namespace patchcull {

DisplacementMap load_displacement_png(const std::string& path, float scale, float midlevel) {
    if (!std::isfinite(scale)) throw Error(path + ": displacement scale is not finite");
    int width = 0, height = 0, channels = 0;
    FILE* file = std::fopen(path.c_str(), "rb");
    if (!file) throw Error(path + ": cannot read image: cannot open file");
    const bool sixteen = stbi_is_16_bit_from_file(file);
    std::fseek(file, 0, SEEK_SET);
    DisplacementMap map;
    map.scale = scale;
    map.midlevel = midlevel;
    if (sixteen) {
        stbi_us* pixels = stbi_load_from_file_16(file, &width, &height, &channels, 1);
        std::fclose(file);
        if (!pixels) throw Error(path + ": cannot read image: " + stbi_failure_reason());
        map.width = width;
        map.height = height;
        map.texels.resize(static_cast<std::size_t>(width) * height);
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x)
                map.texels[static_cast<std::size_t>(height - 1 - y) * width + x] = pixels[y * width + x] / 65535.0f;
        stbi_image_free(pixels);
    } else {
        stbi_uc* pixels = stbi_load_from_file(file, &width, &height, &channels, 1);
        std::fclose(file);
        if (!pixels) throw Error(path + ": cannot read image: " + stbi_failure_reason());
        map.width = width;
        map.height = height;
        map.texels.resize(static_cast<std::size_t>(width) * height);
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x)
                map.texels[static_cast<std::size_t>(height - 1 - y) * width + x] = pixels[y * width + x] / 255.0f;
        stbi_image_free(pixels);
    }
    return map;
}

}  // namespace patchcull
