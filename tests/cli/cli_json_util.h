// JSON helpers for the CLI tests that read `--json` output (tests/gl/*_cli_test.cpp): the run that
// must succeed and print one JSON value, and an object's key set (for contracts).
#pragma once

#include <gtest/gtest.h>

#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"

namespace patchcull::cli_test {

/// Runs the CLI and parses its JSON; a failed run (exit status not 0) or non-JSON output fails the
/// test (and an empty object comes back).
inline nlohmann::json run_json(const std::string& args) {
    const CliRun r = run(args);
    EXPECT_EQ(r.status, 0) << args << "\n" << r.err << r.out.substr(0, 2000);
    const nlohmann::json j = nlohmann::json::parse(r.out, nullptr, false);
    EXPECT_FALSE(j.is_discarded()) << args << ": not JSON: " << r.out.substr(0, 2000) << r.err;
    return j.is_discarded() ? nlohmann::json::object() : j;
}

/// The keys of a JSON object.
inline std::set<std::string> json_keys(const nlohmann::json& object) {
    std::set<std::string> out;
    for (auto it = object.begin(); it != object.end(); ++it) out.insert(it.key());
    return out;
}

}  // namespace patchcull::cli_test
