// The CLI's progress line (tools/progress.h) with a fake clock and a captured sink: the text, the
// rate and ETA, the redraw limit, the final line, and that a disabled reporter writes nothing.
#include <gtest/gtest.h>

#include <string>

#include "progress.h"

namespace patchcull::cli {
namespace {

// What erasing a drawn line writes: a carriage return, as many spaces as the line, a carriage
// return (appended piecewise: GCC 12's -Wrestrict misreads "\r" + std::string).
std::string erased(const std::string& line) {
    std::string text = "\r";
    text.append(line.size(), ' ');
    text += '\r';
    return text;
}

struct Fake {
    static constexpr double kStart = 100.0;  // any origin: only differences count
    double now = kStart;
    std::string written;
    int writes = 0;
    Progress::Clock clock() {
        return [this] { return now; };
    }
    Progress::Sink sink() {
        return [this](const std::string& bytes) {
            written += bytes;
            ++writes;
        };
    }
};

TEST(ProgressFormat, RateAndEta) {
    // 30 of 120 views in 12 s: 2.5 views/s, 90 left: 36 s.
    EXPECT_EQ(format_progress("cull", "views", 30, 120, 12.0), "cull: 30/120 views  2.5 views/s  ETA 36s");
    // 1 of 1000 in 0.5 s: 2 per second, 999 left: 499.5 s -> 8m20s (rounded to the second).
    EXPECT_EQ(format_progress("eval temporal", "frames", 1, 1000, 0.5),
              "eval temporal: 1/1000 frames  2 frames/s  ETA 8m20s");
    // Hours and minutes above an hour: 1 of 10000 in 1 s, 9999 s left.
    EXPECT_EQ(format_progress("x", "u", 1, 10000, 1.0), "x: 1/10000 u  1 u/s  ETA 2h46m");
    // Three significant digits, whole numbers from 100 on (no exponent).
    EXPECT_EQ(format_progress("x", "u", 1000, 3000, 3.0), "x: 1000/3000 u  333 u/s  ETA 6s");
    EXPECT_EQ(format_progress("x", "u", 20000, 40000, 0.03125), "x: 20000/40000 u  640000 u/s  ETA 0s");
    EXPECT_EQ(format_progress("x", "u", 1, 40000, 64.0), "x: 1/40000 u  0.0156 u/s  ETA 711h05m");
}

TEST(ProgressFormat, UnknownRateAndTheFinalLine) {
    EXPECT_EQ(format_progress("x", "u", 0, 10, 5.0), "x: 0/10 u  -- u/s  ETA --");
    EXPECT_EQ(format_progress("x", "u", 3, 10, 0.0), "x: 3/10 u  -- u/s  ETA --");
    // Done: the elapsed time instead of an ETA.
    EXPECT_EQ(format_progress("x", "u", 10, 10, 65.0), "x: 10/10 u  0.154 u/s  1m05s");
    // A final line before the total (a loop that ended early) shows the elapsed time too.
    EXPECT_EQ(format_progress("x", "u", 4, 10, 2.0, true), "x: 4/10 u  2 u/s  2s");
    // More than the total is shown as the total.
    EXPECT_EQ(format_progress("x", "u", 12, 10, 5.0), "x: 10/10 u  2 u/s  5s");
}

TEST(Progress, RedrawsAtMostTenTimesASecondAndEndsWithANewline) {
    // Times in binary fractions of a second, so that the 0.1 s limit is compared exactly.
    Fake fake;
    {
        Progress p("cull", "views", 100, true, fake.clock(), fake.sink());
        fake.now += 0.0625;
        p.step(1);  // 0.0625 s after the start: not yet
        EXPECT_EQ(fake.writes, 0);
        fake.now += 0.0625;
        p.step(2);  // 0.125 s: drawn; 16 views/s, 98 left
        EXPECT_EQ(fake.writes, 1);
        EXPECT_EQ(fake.written, "\rcull: 2/100 views  16 views/s  ETA 6s");
        for (int i = 3; i < 50; ++i) {  // 47 steps within 47/1024 s: none drawn
            fake.now += 1.0 / 1024;
            p.step(std::uint64_t(i));
        }
        EXPECT_EQ(fake.writes, 1);
        fake.now = Fake::kStart + 1.0;
        p.step(50);  // 1 s: drawn
        EXPECT_EQ(fake.writes, 2);
        fake.now = Fake::kStart + 10.0;
        p.step(100);  // the total: drawn at once, with its newline
        EXPECT_EQ(fake.writes, 3);
        p.step(100);
        p.finish();  // already finished: nothing more
        EXPECT_EQ(fake.writes, 3);
    }
    EXPECT_EQ(fake.writes, 3);  // the destructor of a finished line writes nothing
    // The final line: the elapsed time, no ETA, and the newline; padded over the longer line
    // before it ("cull: 50/100 views  50 views/s  ETA 1s").
    const std::string before = "cull: 50/100 views  50 views/s  ETA 1s", last = "cull: 100/100 views  10 views/s  10s";
    ASSERT_LT(last.size(), before.size() + 1);
    EXPECT_EQ(fake.written, "\rcull: 2/100 views  16 views/s  ETA 6s\r" + before + "\r" + last +
                                std::string(before.size() > last.size() ? before.size() - last.size() : 0, ' ') + "\n");
}

TEST(Progress, PadsOverALongerPreviousLine) {
    Fake fake;
    Progress p("x", "u", 10, true, fake.clock(), fake.sink());
    fake.now = Fake::kStart + 100;
    p.step(1);  // 0.01 u/s, 900 s left
    const std::string first = "x: 1/10 u  0.01 u/s  ETA 15m00s";
    EXPECT_EQ(fake.written, "\r" + first);
    fake.written.clear();
    fake.now = Fake::kStart + 100.125;
    p.step(9);  // 9 / 100.125 = 0.0899 u/s, 11 s left: a shorter line
    const std::string second = "x: 9/10 u  0.0899 u/s  ETA 11s";
    ASSERT_LT(second.size(), first.size());
    EXPECT_EQ(fake.written, "\r" + second + std::string(first.size() - second.size(), ' '));
}

TEST(Progress, DisabledWritesNothing) {
    Fake fake;
    {
        Progress p("cull", "views", 3, false, fake.clock(), fake.sink());
        for (int i = 1; i <= 3; ++i) {
            fake.now += 1;
            p.step(std::uint64_t(i));
        }
        p.clear();
        p.finish();
    }
    EXPECT_EQ(fake.writes, 0);
    EXPECT_EQ(fake.written, "");
}

TEST(Progress, AnUnfinishedLineIsErasedWhenTheLoopIsLeftByAnError) {
    Fake fake;
    {
        Progress p("eval occlusion", "views", 10, true, fake.clock(), fake.sink());
        fake.now += 1;
        p.step(3);
    }  // unwinding: the error message that follows must be the only line
    const std::string drawn = "\reval occlusion: 3/10 views  3 views/s  ETA 2s";
    EXPECT_EQ(fake.written, drawn + "\r" + std::string(drawn.size() - 1, ' ') + "\r");
}

TEST(Progress, ClearErasesAndTheNextStepRedraws) {
    Fake fake;
    Progress p("demo", "frames", 10, true, fake.clock(), fake.sink());
    p.erase_when_done();
    fake.now += 1;
    p.step(1);
    fake.written.clear();
    p.clear();
    EXPECT_EQ(fake.written, erased("demo: 1/10 frames  1 frames/s  ETA 9s"));
    fake.written.clear();
    p.clear();  // nothing on screen: nothing to erase
    EXPECT_EQ(fake.written, "");
    fake.now += 1;
    p.step(2);  // drawn again
    EXPECT_EQ(fake.written, "\rdemo: 2/10 frames  1 frames/s  ETA 8s");
    fake.written.clear();
    fake.now += 1;
    p.step(10);  // erase_when_done: the line goes, no newline
    EXPECT_EQ(fake.written, erased("demo: 2/10 frames  1 frames/s  ETA 8s"));
}

TEST(Progress, DoneNeverGoesBackAndZeroUnitsLeaveNoLine) {
    Fake fake;
    {
        Progress p("x", "u", 10, true, fake.clock(), fake.sink());
        p.finish();  // nothing done, nothing drawn
    }
    EXPECT_EQ(fake.writes, 0);
    Progress p("x", "u", 10, true, fake.clock(), fake.sink());
    fake.now += 1;
    p.step(5);
    fake.now += 1;
    p.step(4);  // ignored
    EXPECT_EQ(fake.writes, 1);
    p.finish();
    EXPECT_EQ(fake.written.substr(fake.written.rfind('\r')), "\rx: 5/10 u  2.5 u/s  2s  \n");
}

}  // namespace
}  // namespace patchcull::cli
