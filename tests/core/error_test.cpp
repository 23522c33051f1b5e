// Escaping of untrusted text in error messages (patchcull/core/error.h): control bytes, invalid UTF-8
// and long input never reach the terminal raw.
#include <gtest/gtest.h>

#include "patchcull/core/error.h"

using namespace patchcull;

TEST(ErrorText, QuoteKeepsPrintableTextAndEscapesTheRest) {
    EXPECT_EQ(quote_input("abc"), "'abc'");
    EXPECT_EQ(quote_input(""), "''");
    EXPECT_EQ(quote_input("a\x01"
                          "b"),
              "'a\\x01b'");
    EXPECT_EQ(quote_input(std::string_view("a\0b", 3)), "'a\\x00b'");
    EXPECT_EQ(quote_input("a\nb\rc\td\x7F"), "'a\\nb\\rc\\td\\x7F'");
    EXPECT_EQ(quote_input("it's a\\b"), "'it\\'s a\\\\b'");
    EXPECT_EQ(quote_input("h\xC3\xA9llo \xE2\x82\xAC"), "'h\xC3\xA9llo \xE2\x82\xAC'");  // valid UTF-8 kept
}

TEST(ErrorText, InvalidUtf8IsEscapedBytewise) {
    EXPECT_EQ(quote_input("\xFF"), "'\\xFF'");
    EXPECT_EQ(quote_input("a\xC3"), "'a\\xC3'");                           // truncated sequence
    EXPECT_EQ(quote_input("\xC0\xAF"), "'\\xC0\\xAF'");                    // overlong '/'
    EXPECT_EQ(quote_input("\xED\xA0\x80"), "'\\xED\\xA0\\x80'");           // UTF-16 surrogate
    EXPECT_EQ(quote_input("\xF4\x90\x80\x80"), "'\\xF4\\x90\\x80\\x80'");  // above U+10FFFF
}

TEST(ErrorText, UnicodeControlsAndReorderingAreEscaped) {
    EXPECT_EQ(quote_input("\xC2\x85"), "'\\u0085'");      // NEL, a C1 control
    EXPECT_EQ(quote_input("\xE2\x80\xA8"), "'\\u2028'");  // line separator
    EXPECT_EQ(quote_input("\xE2\x80\xAE"
                          "abc"),
              "'\\u202Eabc'");  // right-to-left override
}

TEST(ErrorText, QuoteIsCutAfterMaxBytesOnACharacterBoundary) {
    EXPECT_EQ(quote_input(std::string(100, 'x'), 10), "'xxxxxxxxxx'...");
    EXPECT_EQ(quote_input(std::string(10, 'x'), 10), "'xxxxxxxxxx'");
    // Escapes and multi-byte characters are never split.
    EXPECT_EQ(quote_input("abcdefgh\x01", 10), "'abcdefgh'...");
    EXPECT_EQ(quote_input("abcdefghi\xC3\xA9", 10), "'abcdefghi'...");
    EXPECT_LE(quote_input(std::string(1 << 22, '\x01')).size(), 40u + 5u);  // 4 MB of control bytes
}

TEST(ErrorText, PrintableLineEscapesButKeepsQuotes) {
    EXPECT_EQ(printable_line("a.obj:1: bad 'x\\y'"), "a.obj:1: bad 'x\\y'");
    EXPECT_EQ(printable_line("two\nlines"), "two\\nlines");
    EXPECT_EQ(printable_line(std::string(1000, 'y'), 20), std::string(20, 'y') + "...");
    EXPECT_TRUE(is_printable_line(printable_line("\x1B[31mred\xFF\xE2\x80\xA8")));
}

TEST(ErrorText, IsPrintableLine) {
    EXPECT_TRUE(is_printable_line("mesh.obj:3: unknown record 'x' \xC3\xA9"));
    EXPECT_TRUE(is_printable_line(""));
    EXPECT_FALSE(is_printable_line("a\nb"));
    EXPECT_FALSE(is_printable_line("\x1B[2J"));
    EXPECT_FALSE(is_printable_line("\xFF"));
    EXPECT_FALSE(is_printable_line("\xC2\x9B"));
}
