// The consumers' one check: prints "ok: WHAT" or "FAILED: WHAT" and counts the failures (the
// program's exit status is 1 when any failed).
#pragma once

#include <cstdio>
#include <string>

inline int failures = 0;

inline void check(bool ok, const std::string& what) {
    std::printf("%s: %s\n", ok ? "ok" : "FAILED", what.c_str());
    if (!ok) ++failures;
}
