#include "hapsim/core/printable_text.h"

#include <gtest/gtest.h>

#include <string>

namespace hapsim {
namespace {

TEST(PrintableText, PlainTextAndUtf8PassUnchanged) {
  EXPECT_EQ(printable_text("scenes/knee.json"), "scenes/knee.json");
  EXPECT_EQ(printable_text("Kniegelenk \xc3\xa4 \xe2\x86\x92 \xf0\x9f\xa6\xb5"),
            "Kniegelenk \xc3\xa4 \xe2\x86\x92 \xf0\x9f\xa6\xb5");  // ä → and a 4-byte one
}

// Every byte that could drive a terminal is written as \xNN: C0 controls, DEL, the 8-bit CSI
// (0x9b) alone or as a UTF-8 C1 control (U+009B), and bytes that are not valid UTF-8.
TEST(PrintableText, ControlCharactersAndBadBytesAreEscaped) {
  EXPECT_EQ(printable_text("a\x1b[2Jb"), "a\\x1b[2Jb");
  EXPECT_EQ(printable_text("bell\x07 cr\r lf\n tab\t del\x7f"),
            "bell\\x07 cr\\x0d lf\\x0a tab\\x09 del\\x7f");
  EXPECT_EQ(printable_text(std::string("nul\0x", 5)), "nul\\x00x");
  EXPECT_EQ(printable_text("csi\x9b"
                           "31m"),
            "csi\\x9b31m");
  EXPECT_EQ(printable_text("c1\xc2\x9b"), "c1\\xc2\\x9b");
  EXPECT_EQ(printable_text("overlong\xc0\xaf cut\xe2\x86"), "overlong\\xc0\\xaf cut\\xe2\\x86");
  EXPECT_EQ(printable_text("back\\slash"), "back\\\\slash");  // so \x1b in a name is not faked
}

TEST(PrintableText, LongTextIsCut) {
  EXPECT_EQ(printable_text(std::string(300, 'k'), 10), "kkkkkkkkkk...");
  EXPECT_EQ(printable_text("short", 10), "short");
}

}  // namespace
}  // namespace hapsim
