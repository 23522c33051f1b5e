// Runs the patchcull binary with stderr on a pseudo-terminal (util-linux `script`), for the
// tests of what the CLI prints only on a terminal (the progress line, tools/progress.h).
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <string>

#include "cli_test_util.h"

namespace patchcull::cli_test {

struct TerminalRun {
    int status = -1;
    std::string terminal;  ///< what the command wrote to the terminal: its stderr (stdout goes to out)
    std::string out;       ///< its stdout, redirected to a file inside the terminal session
};

inline bool have_script() { return std::system("command -v script >/dev/null 2>&1") == 0; }

/// `script -qec "patchcull ARGS >FILE" /dev/null`: stdin and stderr are the pseudo-terminal,
/// stdout a file, so `terminal` holds only stderr (with '\r', and '\n' as "\r\n"). args must
/// not hold single quotes.
inline TerminalRun run_on_terminal(const std::string& args) {
    const std::string out = scratch_dir() + "/terminal_stdout", log = scratch_dir() + "/terminal_log";
    const std::string inner = std::string(PATCHCULL_CLI) + " " + args + " >" + out;
    const std::string cmd = "script -qec '" + inner + "' /dev/null >" + log + " </dev/null";
    const int raw = std::system(cmd.c_str());
    TerminalRun r;
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.terminal = slurp(log);
    r.out = slurp(out);
    return r;
}

}  // namespace patchcull::cli_test
