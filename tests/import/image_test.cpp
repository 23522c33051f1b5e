// PNG height maps (8- and 16-bit) load with the right values, scaling and row order.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <vector>

#include "patchcull/error.h"
#include "patchcull/image.h"

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
        {"signature_only.png", "first not IHDR"},
        {"truncated_in_ihdr.png", "truncated PNG chunk"},
        {"truncated_in_idat.png", "truncated PNG chunk"},
        // 2^24 x 2^24 declared in 68 bytes: refused before stb_image reserves memory for it.
        {"huge_dimensions.png", "image data too short for 16777216x16777216"},
        {"zero_width.png", "0-pixel image"},
        {"bad_depth.png", "1/2/4/8/16-bit only"},
    };
    for (const auto& [file, reason] : cases) {
        const std::string message = error_of(corpus(file));
        EXPECT_EQ(message, corpus(file) + ": cannot read image: " + reason);
        EXPECT_TRUE(is_printable_line(message)) << message;
    }
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
