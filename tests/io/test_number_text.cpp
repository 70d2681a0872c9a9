// io/number_text.hpp: every reader's number, against what C's strtod reads (the reference a user's tools share).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <string>

#include "rpem/io/number_text.hpp"

namespace rpem::io {
namespace {

TEST(NumberText, ReadsWhatStrtodReadsWholeIncludingALeadingPlus) {
  for (const char* text : {"3.5", "+3.5", "-3.5", "+0", "1e3", "+1.25e-3", "-0.0", "1e-400", "4.9e-324"}) {
    const NumberText read = read_number(text);
    ASSERT_EQ(read.kind, NumberText::Kind::kNumber) << text;
    EXPECT_EQ(read.value, std::strtod(text, nullptr)) << text;
  }
}

TEST(NumberText, TellsTextBeyondADoublesRangeFromTextThatIsNoNumber) {
  for (const char* text : {"1e400", "-1e400", "+2e308"}) {
    const NumberText read = read_number(text);
    EXPECT_EQ(read.kind, NumberText::Kind::kOutOfRange) << text;
    EXPECT_EQ(read.reason(text), std::string("'") + text + "' is beyond the range of a double (±1.8e308)");
  }
  for (const char* text : {"", "+", "++3", "+-3", "3.5x", " 3", "3 ", "abc", "24,9", "0x10"}) {
    const NumberText read = read_number(text);
    EXPECT_EQ(read.kind, NumberText::Kind::kNotANumber) << text;
    EXPECT_EQ(read.reason(text), std::string("'") + text + "' is not a number");
  }
}

}  // namespace
}  // namespace rpem::io
