// Progress line on stderr (progress.h).
#include "progress.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <utility>

namespace patchcull::cli {
namespace {

// "42s", "3m05s", "2h05m": whole seconds are enough for a line redrawn ten times a second.
std::string format_duration(double seconds) {
    const long long s = static_cast<long long>(std::llround(std::max(0.0, seconds)));
    char text[48];
    if (s < 60)
        std::snprintf(text, sizeof text, "%llds", s);
    else if (s < 3600)
        std::snprintf(text, sizeof text, "%lldm%02llds", s / 60, s % 60);
    else
        std::snprintf(text, sizeof text, "%lldh%02lldm", s / 3600, s / 60 % 60);
    return text;
}

double steady_seconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void write_stderr(const std::string& bytes) {
    std::fputs(bytes.c_str(), stderr);
    std::fflush(stderr);
}

}  // namespace

bool progress_wanted(bool json) { return !json && isatty(fileno(stderr)) == 1; }

std::string format_progress(const std::string& label, const std::string& unit, std::uint64_t done, std::uint64_t total,
                            double elapsed_seconds, bool final_line) {
    done = std::min(done, total);
    const bool known = done > 0 && elapsed_seconds > 0;
    const double rate = known ? double(done) / elapsed_seconds : 0;
    char rate_text[32] = "--";
    if (known) std::snprintf(rate_text, sizeof rate_text, rate < 100 ? "%.3g" : "%.0f", rate);  // no exponents
    std::string line = label + ": " + std::to_string(done) + "/" + std::to_string(total) + " " + unit + "  " +
                       rate_text + " " + unit + "/s  ";
    if (done == total || final_line) return line + format_duration(elapsed_seconds);
    return line + "ETA " + (known ? format_duration(double(total - done) / rate) : std::string("--"));
}

Progress::Progress(std::string label, std::string unit, std::uint64_t total, bool enabled, Clock clock, Sink sink)
    : label_(std::move(label)),
      unit_(std::move(unit)),
      total_(total),
      enabled_(enabled),
      clock_(clock ? std::move(clock) : Clock(steady_seconds)),
      sink_(sink ? std::move(sink) : Sink(write_stderr)) {
    if (!enabled_) return;
    start_ = clock_();
    last_draw_ = start_;
}

Progress::~Progress() {
    if (enabled_ && !finished_) clear();
}

void Progress::step(std::uint64_t done) {
    if (!enabled_ || finished_ || done <= done_) return;
    done_ = std::min(done, total_);
    if (done_ == total_) {
        finish();
        return;
    }
    const double now = clock_();
    if (now - last_draw_ < kMinRedrawSeconds) return;
    last_draw_ = now;
    draw(false);
}

void Progress::finish() {
    if (!enabled_ || finished_) return;
    finished_ = true;
    if (erase_when_done_) {
        clear();
        return;
    }
    if (drawn_width_ == 0 && done_ == 0) return;
    draw(true);
}

void Progress::clear() {
    if (!enabled_ || drawn_width_ == 0) return;
    std::string erase(drawn_width_ + 2, ' ');  // built in place: GCC 12's -Wrestrict misreads "\r" + string
    erase.front() = '\r';
    erase.back() = '\r';
    sink_(erase);
    drawn_width_ = 0;
}

void Progress::draw(bool final_line) {
    std::string line = format_progress(label_, unit_, done_, total_, clock_() - start_, final_line);
    // Spaces over what a longer previous line left (the ETA shrinks as the run goes on).
    const std::size_t width = line.size();
    if (width < drawn_width_) line += std::string(drawn_width_ - width, ' ');
    sink_("\r" + line + (final_line ? "\n" : ""));
    drawn_width_ = final_line ? 0 : width;
}

}  // namespace patchcull::cli
