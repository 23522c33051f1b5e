// Loaders read only regular files of bounded size (src/import/input_file.h): a device such as
// /dev/zero used to be read until memory ran out, a FIFO without a writer blocked forever. Both
// are refused before any read with one line, exit 2, for models and height maps alike.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <string>

#include "cli/cli_test_util.h"

using namespace patchcull::cli_test;

TEST(CliInputFile, DevicesAndDirectoriesAreRefusedBeforeAnyRead) {
    expect_one_line_error(run("info /dev/zero"), "not a regular file");
    expect_one_line_error(run("info " + scratch_dir()), "not a regular file");
    expect_one_line_error(run("cull " + model("bigguy.obj") + " --views 1 --displace /dev/zero"), "not a regular file");
}

TEST(CliInputFile, FifoIsRefusedWithoutBlocking) {
    const std::string fifo = scratch_dir() + "/model.fifo";
    ::unlink(fifo.c_str());
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    expect_one_line_error(run("info " + fifo), "not a regular file");  // would block without the check
    ::unlink(fifo.c_str());
}
