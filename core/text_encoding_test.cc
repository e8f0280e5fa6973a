#include "core/text_encoding.h"

#include <gtest/gtest.h>

namespace arcwheel {
namespace {

TEST(IsValidUtf8, AcceptsWellFormedTextAndRefusesWhatRfc3629Forbids) {
  EXPECT_TRUE(IsValidUtf8(""));
  EXPECT_TRUE(IsValidUtf8("SYN-ARC-3fa19e"));
  EXPECT_TRUE(IsValidUtf8("Zo\xC3\xAB \xE5\xBC\xA0\xE4\xB8\x89 \xF0\x9F\x94\xA7"));  // Zoë 张三 and U+1F527
  EXPECT_FALSE(IsValidUtf8("Zo\xEB"));                                               // Latin-1 ë
  EXPECT_FALSE(IsValidUtf8("\xC0\xAF"));                                             // overlong '/'
  EXPECT_FALSE(IsValidUtf8("\xED\xA0\x80"));                                         // surrogate U+D800
  EXPECT_FALSE(IsValidUtf8("\xF4\x90\x80\x80"));                                     // past U+10FFFF
  EXPECT_FALSE(IsValidUtf8("\xE5\xBC"));                                             // cut short
  EXPECT_FALSE(IsValidUtf8("\x80"));  // a lone continuation byte
}

TEST(Latin1ToUtf8, MapsEachByteToTheCodePointOfTheSameNumber) {
  EXPECT_EQ(Latin1ToUtf8("M\xFCller, Zo\xEB \xB5m"), "M\xC3\xBCller, Zo\xC3\xAB \xC2\xB5m");
  bool was_latin1 = false;
  EXPECT_EQ(AsUtf8("Zo\xC3\xAB", was_latin1), "Zo\xC3\xAB");
  EXPECT_FALSE(was_latin1);
  EXPECT_EQ(AsUtf8("Zo\xEB", was_latin1), "Zo\xC3\xAB");
  EXPECT_TRUE(was_latin1);
  EXPECT_TRUE(IsValidUtf8(Latin1ToUtf8(std::string("\x00\x7F\x80\xFF", 4))));
}

TEST(AsciiLower, FoldsOnlyAsciiLetters) {
  EXPECT_EQ(AsciiLower("Radius_Sign \xC3\x89"), "radius_sign \xC3\x89");
}

}  // namespace
}  // namespace arcwheel
