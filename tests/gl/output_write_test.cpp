// A PNG that cannot be written completely is an error (src/gl/png_file.h): stbi_write_png ignored
// failed writes, so `render --out` on a full disk exited 0 with a truncated file. /dev/full
// passes the up-front path check (it opens for writing) and fails every write.
#include <gtest/gtest.h>

#include "cli/cli_test_util.h"

using namespace patchcull::cli_test;

TEST(GpuCliOutput, FailedPngWriteIsAnError) {
    expect_one_line_error(run("render teapot --size 16x16 --frames 1 --out /dev/full"), "write failed");
}
