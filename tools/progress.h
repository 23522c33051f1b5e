// Progress of the CLI's long commands (`cull` with many views, `eval`, `demo`) on stderr: one
// line, redrawn in place with '\r', "LABEL: DONE/TOTAL UNIT  R UNIT/s  ETA Ns". It is drawn only
// when stderr is a terminal and the command does not print JSON, so pipes, logs and --json output
// are byte for byte what they were without it. Commands call step() from their outer loops (per
// view, per frame), never from a kernel: a redraw is a few hundred bytes at most ten times a second.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

namespace patchcull::cli {

/// True when progress should be drawn: stderr is a terminal (isatty) and json is false.
bool progress_wanted(bool json);

/// The progress line for done of total units after elapsed_seconds (no '\r', no newline):
/// "LABEL: DONE/TOTAL UNIT  RATE UNIT/s  ETA T" while done < total, and
/// "LABEL: DONE/TOTAL UNIT  RATE UNIT/s  T" (T the elapsed time) once done == total or for the
/// final line (final_line: a loop that ended early shows its time, not an ETA). RATE is
/// done / elapsed_seconds with 3 significant digits (whole numbers from 100 on, never an
/// exponent), and "--" (ETA "--" too) while nothing is
/// done or no time has passed. T is "42s" below a minute, "3m05s" below an hour, "2h05m" above.
/// done above total is shown as total.
std::string format_progress(const std::string& label, const std::string& unit, std::uint64_t done, std::uint64_t total,
                            double elapsed_seconds, bool final_line = false);

/// One progress line. Construct it before the loop with the loop's total; call step(done) after
/// each unit of work. Not thread-safe: call it from the thread that runs the loop.
class Progress {
public:
    using Clock = std::function<double()>;                 ///< seconds, monotonic
    using Sink = std::function<void(const std::string&)>;  ///< receives the bytes to write

    /// enabled false (see progress_wanted) makes every call a no-op that writes nothing. The
    /// defaults write to stderr (flushed) and read std::chrono::steady_clock; tests inject both.
    Progress(std::string label, std::string unit, std::uint64_t total, bool enabled, Clock clock = {}, Sink sink = {});
    /// Erases a line left unfinished (an error is being thrown past the loop: its message then
    /// stays the only line), so finish() is the only way to leave the final line on the screen.
    ~Progress();
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;

    /// Records done units (monotonic; a smaller value than before is ignored). Redraws when at
    /// least kMinRedrawSeconds passed since the last draw (the start counts as one), and always
    /// when done reaches total; reaching total also ends the line (finish()).
    void step(std::uint64_t done);
    /// Ends the line: draws the final state (done as recorded, the elapsed time) and a newline,
    /// once. Nothing when nothing was drawn and nothing is done (a loop of zero units leaves no
    /// line); with erase_when_done() it erases the line instead.
    void finish();
    /// Erases the current line (for a command that prints a table row on stdout to the same
    /// terminal); the next step() draws it again.
    void clear();
    /// Makes finish() erase the line instead of ending it, for a command whose own table rows go
    /// to the same terminal and should not have a progress line among them (`demo`).
    void erase_when_done() { erase_when_done_ = true; }

    static constexpr double kMinRedrawSeconds = 0.1;  ///< at most ten redraws a second

private:
    void draw(bool final_line);

    std::string label_, unit_;
    std::uint64_t total_ = 0, done_ = 0;
    bool enabled_ = false, finished_ = false, erase_when_done_ = false;
    Clock clock_;
    Sink sink_;
    double start_ = 0, last_draw_ = 0;
    std::size_t drawn_width_ = 0;  ///< characters of the line on screen now (0: none)
};

}  // namespace patchcull::cli
