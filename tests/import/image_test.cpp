// PNG height maps (8- and 16-bit) load with the right values, scaling and row order.
#include <gtest/gtest.h>

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
