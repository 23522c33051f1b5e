// PNG height maps through stb_image (patchcull/import/image.h). libstb ships the implementation.
//
// Only PNG is accepted (checked by its signature before stb_image sees the bytes): stb_image also
// decodes JPEG, GIF, PSD, HDR, TGA and others, but a height map needs 8 or 16 bits of grey, and
// every decoder not used is attack surface for a malformed file.
#include "patchcull/import/image.h"

#include <stb/stb_image.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "input_file.h"
#include "patchcull/core/error.h"

namespace patchcull {
namespace {

[[noreturn]] void fail(const std::string& name, const char* why) {
    // stb_image's reasons are short fixed strings (explained below); printable_line keeps that
    // true whatever the build of libstb returns (it may be compiled with STBI_NO_FAILURE_STRINGS: null).
    throw Error(name + ": cannot read image: " + printable_line(why ? why : "unknown reason", 160));
}

// stb_image's failure reasons are terse codes ("bad sizes", "zlib corrupt"): what each says is
// wrong with the file, in words, followed by the code itself for a bug report.
std::string explain_stb_failure(const char* code, const char* before) {
    // stb_image fails some inputs without a reason of its own (a deflate block of the reserved
    // type 3): its last reason is then stale, the one set on purpose before decoding.
    if (code == before) return "corrupt PNG: its pixel data cannot be decoded (stb_image gives no reason)";
    const std::string why = code ? code : "";
    if (why.empty()) return "unknown reason";
    static const char* const kDeflate[] = {"bad codelengths",  "bad sizes",       "bad huffman code",
                                           "bad dist",         "bad zlib header", "no preset dict",
                                           "bad compression",  "zlib corrupt",    "output buffer limit",
                                           "read past buffer", "outofdata"};
    static const std::pair<const char*, const char*> kWords[] = {
        {"first not IHDR", "corrupt PNG: it does not start with an IHDR chunk"},
        {"multiple IHDR", "corrupt PNG: more than one IHDR chunk"},
        {"bad IHDR len", "corrupt PNG: an IHDR chunk of the wrong length"},
        {"0-pixel image", "corrupt PNG: its header gives a width or height of 0"},
        {"invalid width", "corrupt PNG: its header gives an invalid width"},
        {"1/2/4/8/16-bit only", "unsupported PNG: a bit depth other than 1, 2, 4, 8 or 16"},
        {"bad ctype", "corrupt PNG: an invalid colour type in its header"},
        {"bad comp method", "corrupt PNG: an unknown compression method in its header"},
        {"bad filter method", "corrupt PNG: an unknown filter method in its header"},
        {"bad interlace method", "corrupt PNG: an unknown interlace method in its header"},
        {"no PLTE", "corrupt PNG: a palette image without a palette (PLTE chunk)"},
        {"invalid PLTE", "corrupt PNG: an invalid palette (PLTE chunk)"},
        {"tRNS after IDAT", "corrupt PNG: a transparency chunk (tRNS) after the pixel data"},
        {"tRNS before PLTE", "corrupt PNG: a transparency chunk (tRNS) before the palette"},
        {"bad tRNS len", "corrupt PNG: a transparency chunk (tRNS) of the wrong length"},
        {"tRNS with alpha", "corrupt PNG: a transparency chunk (tRNS) in an image with alpha"},
        {"no IDAT", "corrupt PNG: no pixel data (no IDAT chunk)"},
        {"not enough pixels", "corrupt PNG: its pixel data is shorter than the size in its header"},
        {"too large", "corrupt PNG: its pixel data does not match the size in its header"},
        {"invalid filter", "corrupt PNG: a row of pixels has an invalid filter type"},
        {"outofmem", "out of memory while decoding"},
    };
    std::string what = "PNG decoding failed";
    if (std::find(std::begin(kDeflate), std::end(kDeflate), why) != std::end(kDeflate))
        what = "corrupt PNG: its compressed pixel data (the zlib stream in its IDAT chunks) is damaged";
    for (const auto& [known, words] : kWords)
        if (why == known) what = words;
    return what + " (stb_image: " + why + ")";
}

struct StbiFree {
    void operator()(void* pixels) const { stbi_image_free(pixels); }
};

// Copies stb_image's rows (top first) into texels (bottom first), as heights in [0,1].
template <class Pixel>
void copy_flipped(const Pixel* pixels, float full_scale, DisplacementMap& map) {
    const auto w = static_cast<std::size_t>(map.width), h = static_cast<std::size_t>(map.height);
    map.texels.resize(w * h);
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t x = 0; x < w; ++x) map.texels[(h - 1 - y) * w + x] = pixels[y * w + x] / full_scale;
}

std::uint32_t big_endian32(const unsigned char* p) {
    return std::uint32_t{p[0]} << 24 | std::uint32_t{p[1]} << 16 | std::uint32_t{p[2]} << 8 | p[3];
}

// Checks the chunk layout and the header's size against the data before stb_image allocates
// anything. stb_image trusts both: an IDAT chunk whose length field claims 2 GB in a 100-byte
// file makes it reserve 2 GB before it notices the data is missing, and it sizes its buffers by
// the header's width x height before it has decompressed a byte. A file whose chunks run past
// its end is truncated; one whose pixels cannot come out of the compressed data it holds
// (deflate expands at most 1032:1) is corrupt. Both are refused here; what passes is exactly
// what stb_image could decode, so no valid file is refused.
void check_png_layout(const unsigned char* data, std::size_t size, const std::string& name) {
    std::size_t at = 8;  // after the signature
    std::uint64_t width = 0, height = 0, bits_per_pixel = 0, compressed = 0;
    for (bool first = true; size - at >= 8; first = false) {  // a chunk header: length and type
        const std::uint32_t length = big_endian32(data + at);
        if (size - at < 12 || length > size - at - 12) fail(name, "truncated PNG chunk");
        const unsigned char* type = data + at + 4;
        const unsigned char* body = data + at + 8;
        if (first) {
            if (std::memcmp(type, "IHDR", 4) != 0 || length != 13) fail(name, "PNG does not start with IHDR");
            width = big_endian32(body);
            height = big_endian32(body + 4);
            const unsigned depth = body[8], colour = body[9];
            const unsigned samples = colour == 2 ? 3 : colour == 4 ? 2 : colour == 6 ? 4 : 1;
            bits_per_pixel = std::uint64_t{samples} * depth;  // bad depths and colours: stb_image says so
            if (width > (1u << 24) || height > (1u << 24)) fail(name, "image too large");
        }
        if (std::memcmp(type, "IDAT", 4) == 0) compressed += length;
        if (std::memcmp(type, "IEND", 4) == 0) break;
        at += 12 + std::size_t{length};
    }
    if (width == 0) return;  // no complete header: stb_image names what is missing
    const std::uint64_t pixel_bytes = (width * height * bits_per_pixel + 7) / 8;
    if (pixel_bytes > 1100 * compressed + 1024)
        fail(name, ("image data too short for " + std::to_string(width) + "x" + std::to_string(height)).c_str());
}

}  // namespace

DisplacementMap decode_displacement_png(const unsigned char* data, std::size_t size, const std::string& name,
                                        float scale, float midlevel) {
    if (!std::isfinite(scale)) throw Error(name + ": displacement scale is not finite");
    static constexpr unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    if (size < sizeof kSignature || std::memcmp(data, kSignature, sizeof kSignature) != 0) fail(name, "not a PNG file");
    if (size > static_cast<std::size_t>(INT_MAX)) fail(name, "file too large");
    check_png_layout(data, size, name);
    const int length = static_cast<int>(size);
    int width = 0, height = 0, channels = 0;
    DisplacementMap map;
    map.scale = scale;
    map.midlevel = midlevel;
    // A failure reason set on purpose (no format starts with a zero byte), to tell a stale one.
    static constexpr unsigned char kNoImage[1] = {0};
    int ignored = 0;
    stbi_info_from_memory(kNoImage, 1, &ignored, &ignored, &ignored);
    const char* const before = stbi_failure_reason();
    if (stbi_is_16_bit_from_memory(data, length)) {
        const std::unique_ptr<stbi_us, StbiFree> pixels(
            stbi_load_16_from_memory(data, length, &width, &height, &channels, 1));
        if (!pixels) fail(name, explain_stb_failure(stbi_failure_reason(), before).c_str());
        map.width = width;
        map.height = height;
        copy_flipped(pixels.get(), 65535.0f, map);
    } else {
        const std::unique_ptr<stbi_uc, StbiFree> pixels(
            stbi_load_from_memory(data, length, &width, &height, &channels, 1));
        if (!pixels) fail(name, explain_stb_failure(stbi_failure_reason(), before).c_str());
        map.width = width;
        map.height = height;
        copy_flipped(pixels.get(), 255.0f, map);
    }
    return map;
}

DisplacementMap load_displacement_png(const std::string& path, float scale, float midlevel) {
    if (!std::isfinite(scale)) throw Error(path + ": displacement scale is not finite");
    if (const std::string problem = detail::input_file_problem(path, kMaxPngFileBytes, "PNG"); !problem.empty())
        fail(path, problem.c_str());
    std::ifstream file(path, std::ios::binary);
    if (!file) fail(path, "cannot open file");
    const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    if (file.bad()) fail(path, "read error");
    return decode_displacement_png(bytes.data(), bytes.size(), path, scale, midlevel);
}

}  // namespace patchcull
