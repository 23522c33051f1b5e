// PNG height maps (8- and 16-bit) load with the right values, scaling and row order.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "patchcull/core/error.h"
#include "patchcull/import/image.h"

using namespace patchcull;

namespace {
std::string data(const char* name) { return std::string(PATCHCULL_SOURCE_DIR) + "/tests/data/" + name; }
}  // namespace

TEST(Image, Loads8BitGreyWithRowsFlippedToTextureOrder) {
    // File rows, top first: {0,64,128,255}, {10,20,30,40}, {200,210,220,230}.
    const DisplacementMap m = load_displacement_png(data("height8.png"), 2.0f, 0.25f);
    ASSERT_EQ(m.width, 4);
    ASSERT_EQ(m.height, 3);
    EXPECT_FLOAT_EQ(m.scale, 2.0f);
    EXPECT_FLOAT_EQ(m.midlevel, 0.25f);
    // Row 0 of texels is t = 0, the bottom of the image: the file's last row.
    EXPECT_FLOAT_EQ(m.texels[0], 200 / 255.0f);
    EXPECT_FLOAT_EQ(m.texels[3], 230 / 255.0f);
    EXPECT_FLOAT_EQ(m.texels[2 * 4 + 3], 1.0f);
    EXPECT_FLOAT_EQ(m.texels[2 * 4 + 1], 64 / 255.0f);
    // D at a texel centre: scale * (h - midlevel).
    EXPECT_FLOAT_EQ(m.sample({3.5f / 4, 2.5f / 3}), 2.0f * (1.0f - 0.25f));
}

TEST(Image, Loads16BitGreyAtFullPrecision) {
    // File rows, top first: {0,1000,32768,65535}, {1,2,3,4}, {60000,50000,40000,30000}.
    const DisplacementMap m = load_displacement_png(data("height16.png"), 1.0f);
    ASSERT_EQ(m.width, 4);
    ASSERT_EQ(m.height, 3);
    EXPECT_FLOAT_EQ(m.texels[0], 60000 / 65535.0f);
    EXPECT_FLOAT_EQ(m.texels[1 * 4 + 0], 1 / 65535.0f);  // would be 0 if read as 8-bit
    EXPECT_FLOAT_EQ(m.texels[2 * 4 + 1], 1000 / 65535.0f);
    EXPECT_FLOAT_EQ(m.texels[2 * 4 + 3], 1.0f);
}

TEST(Image, UnreadableFilesNameThePath) {
    try {
        load_displacement_png(data("README.md"), 1.0f);
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()).rfind(data("README.md") + ": cannot read image", 0), 0u) << e.what();
    }
}

namespace {
std::string corpus(const char* name) { return std::string(PATCHCULL_SOURCE_DIR) + "/fuzz/corpus/png/" + name; }

std::string error_of(const std::string& path) {
    try {
        load_displacement_png(path, 1.0f);
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}
}  // namespace

TEST(Image, DecodesFromMemoryAsFromTheFile) {
    std::ifstream in(data("height16.png"), std::ios::binary);
    const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const DisplacementMap a = decode_displacement_png(bytes.data(), bytes.size(), "mem.png", 1.0f);
    const DisplacementMap b = load_displacement_png(data("height16.png"), 1.0f);
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.texels, b.texels);
}

TEST(Image, ColourImagesUseLuminance) {
    // fuzz/corpus/make_png_corpus.py: sample (x, y, c) = (37 x + 91 y + 53 c) % 256; the top-left
    // pixel is RGB (0, 53, 106), so h = (77*0 + 150*53 + 29*106) / 256 = 43 (stb_image's formula).
    const DisplacementMap m = load_displacement_png(corpus("rgb8_4x4.png"), 1.0f);
    ASSERT_EQ(m.width, 4);
    EXPECT_FLOAT_EQ(m.texels[3 * 4 + 0], 43 / 255.0f);  // last texel row = the file's first row
}

TEST(Image, MalformedFilesGiveOneShortLine) {
    const std::pair<const char*, const char*> cases[] = {
        {"not_png.jpg", "not a PNG file"},
        {"signature_only.png", "corrupt PNG: it does not start with an IHDR chunk (stb_image: first not IHDR)"},
        {"truncated_in_ihdr.png", "truncated PNG chunk"},
        {"truncated_in_idat.png", "truncated PNG chunk"},
        // 2^24 x 2^24 declared in 68 bytes: refused before stb_image reserves memory for it.
        {"huge_dimensions.png", "image data too short for 16777216x16777216"},
        {"zero_width.png", "corrupt PNG: its header gives a width or height of 0 (stb_image: 0-pixel image)"},
        {"bad_depth.png", "unsupported PNG: a bit depth other than 1, 2, 4, 8 or 16 (stb_image: 1/2/4/8/16-bit only)"},
    };
    for (const auto& [file, reason] : cases) {
        const std::string message = error_of(corpus(file));
        EXPECT_EQ(message, corpus(file) + ": cannot read image: " + reason);
        EXPECT_TRUE(is_printable_line(message)) << message;
    }
}

namespace {
// A 1x1 8-bit grey PNG whose IDAT holds `deflate` after a zlib header (CRCs zero: stb_image skips them).
std::vector<unsigned char> png_with_deflate(const std::vector<unsigned char>& deflate) {
    std::vector<unsigned char> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    const auto chunk = [&png](const char* type, const std::vector<unsigned char>& body) {
        const std::uint32_t n = static_cast<std::uint32_t>(body.size());
        for (int shift = 24; shift >= 0; shift -= 8) png.push_back(static_cast<unsigned char>(n >> shift));
        png.insert(png.end(), type, type + 4);
        png.insert(png.end(), body.begin(), body.end());
        png.insert(png.end(), 4, 0);
    };
    chunk("IHDR", {0, 0, 0, 1, 0, 0, 0, 1, 8, 0, 0, 0, 0});
    std::vector<unsigned char> idat = {0x78, 0x9C};
    idat.insert(idat.end(), deflate.begin(), deflate.end());
    idat.insert(idat.end(), 16, 0);
    chunk("IDAT", idat);
    chunk("IEND", {});
    return png;
}

std::string decode_error(const std::vector<unsigned char>& png) {
    try {
        decode_displacement_png(png.data(), png.size(), "bad.png", 1.0f);
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}
}  // namespace

TEST(Image, ACorruptPngSaysWhatIsWrongWithIt) {
    // A dynamic-Huffman block whose 19 code-length codes are all 1 bit long: more codes of one
    // length than that length allows (stb_image's terse "bad sizes").
    std::vector<unsigned char> bits = {1, 0, 1};                      // final block, type 2 (dynamic)
    bits.insert(bits.end(), 10, 0);                                   // HLIT = 0, HDIST = 0
    bits.insert(bits.end(), {1, 1, 1, 1});                            // HCLEN = 15: 19 code-length codes
    for (int k = 0; k < 19; ++k) bits.insert(bits.end(), {1, 0, 0});  // each 1 bit long
    std::vector<unsigned char> deflate((bits.size() + 7) / 8, 0);
    for (std::size_t i = 0; i < bits.size(); ++i) deflate[i / 8] |= static_cast<unsigned char>(bits[i] << (i % 8));
    EXPECT_EQ(decode_error(png_with_deflate(deflate)),
              "bad.png: cannot read image: corrupt PNG: its compressed pixel data (the zlib stream in its IDAT chunks) "
              "is damaged (stb_image: bad sizes)");
    // A block of the reserved type 3: stb_image fails without a reason; none is made up.
    EXPECT_EQ(decode_error(png_with_deflate({0x07})),
              "bad.png: cannot read image: corrupt PNG: its pixel data cannot be decoded (stb_image gives no reason)");
    // The same file with a valid stored block decodes: the failures above are the damage's.
    EXPECT_EQ(decode_error(png_with_deflate({0x01, 0x02, 0x00, 0xFD, 0xFF, 0x00, 0x80})), "(no error)");
}

TEST(Image, ChunkLengthPastTheEndIsRefusedBeforeAllocating) {
    // A valid 1x1 grey PNG cut after its IDAT's first 8 bytes, then an IDAT header claiming
    // 0x7FFFFFF0 bytes: stb_image alone reserved 2 GB for it before finding the data missing.
    std::ifstream in(corpus("grey8_1x1.png"), std::ios::binary);
    std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    bytes.resize(33);  // signature + IHDR chunk
    const unsigned char huge_idat[] = {0x7F, 0xFF, 0xFF, 0xF0, 'I', 'D', 'A', 'T', 0x78, 0xDA};
    bytes.insert(bytes.end(), std::begin(huge_idat), std::end(huge_idat));
    try {
        decode_displacement_png(bytes.data(), bytes.size(), "cut.png", 1.0f);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(), "cut.png: cannot read image: truncated PNG chunk");
    }
}

TEST(Image, ValidCorpusFilesOfEveryKindLoad) {
    for (const char* file : {"grey8_4x3.png", "grey16_4x3.png", "grey1_9x2.png", "grey4_5x5.png", "grey_alpha8_3x3.png",
                             "grey_alpha16_2x2.png", "rgb8_4x4.png", "rgb16_3x2.png", "rgba8_2x5.png", "rgba16_2x2.png",
                             "palette8_4x4.png", "palette2_6x3.png", "grey8_1x1.png", "interlaced_grey8_9x9.png",
                             "text_chunk_grey8_4x4.png"}) {
        const DisplacementMap m = load_displacement_png(corpus(file), 1.0f);
        EXPECT_GT(m.width * m.height, 0) << file;
        EXPECT_EQ(m.texels.size(), static_cast<std::size_t>(m.width * m.height)) << file;
    }
}
