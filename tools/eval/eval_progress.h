// The CLI's progress line (progress.h) for an evaluation run of the eval_gl layer: the line is
// made when the run starts its loop (the run knows its total then) and lives as long as this.
#pragma once

#include <optional>
#include <string>
#include <utility>

#include "patchcull/eval_gl/run_progress.h"
#include "progress.h"

namespace patchcull::cli {

class EvalProgress {
public:
    /// json: the command prints JSON (then nothing is drawn, as progress_wanted says).
    EvalProgress(std::string label, std::string unit, bool json)
        : label_(std::move(label)), unit_(std::move(unit)), wanted_(progress_wanted(json)) {
        hooks_.start = [this](std::uint64_t total) { line_.emplace(label_, unit_, total, wanted_); };
        hooks_.step = [this](std::uint64_t done) { line_->step(done); };
    }
    EvalProgress(const EvalProgress&) = delete;
    EvalProgress& operator=(const EvalProgress&) = delete;

    const eval_gl::RunProgress& hooks() const { return hooks_; }
    /// Progress::finish of the line, when the run made one.
    void finish() {
        if (line_) line_->finish();
    }

private:
    std::string label_, unit_;
    bool wanted_ = false;
    std::optional<Progress> line_;
    eval_gl::RunProgress hooks_;
};

}  // namespace patchcull::cli
