// How an evaluation run (eval_gl/*_eval.h) reports its progress to a caller that shows it (the
// CLI's progress line). Both hooks are optional: an empty one is not called.
#pragma once

#include <cstdint>
#include <functional>

namespace patchcull::eval_gl {

struct RunProgress {
    /// Once, after the run's setup and before its loop: the units of work the loop steps through.
    std::function<void(std::uint64_t total)> start;
    /// After each unit: the units done so far (1..total, increasing).
    std::function<void(std::uint64_t done)> step;

    void begin(std::uint64_t total) const {
        if (start) start(total);
    }
    void done(std::uint64_t units) const {
        if (step) step(units);
    }
};

}  // namespace patchcull::eval_gl
