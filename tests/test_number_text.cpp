// Numbers as text (src/core/number_text.hpp): what the CLI and the readers accept as a number, and
// the digits messages and JSON show.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "core/number_text.hpp"

namespace {

using hfvis::detail::decimalNumber;
using hfvis::detail::exactNumber;
using hfvis::detail::wholeNumber;

TEST(NumberText, DecimalNumbersAreReadWhole) {
  double v = -1.0;
  EXPECT_TRUE(decimalNumber("12.5", v));
  EXPECT_EQ(v, 12.5);
  EXPECT_TRUE(decimalNumber("-3e2", v));
  EXPECT_EQ(v, -300.0);
  EXPECT_TRUE(decimalNumber(".5", v));
  EXPECT_EQ(v, 0.5);
}

TEST(NumberText, AnythingButAFiniteDecimalNumberIsRefused) {
  double v = 0.0;
  for (const std::string& text :
       std::initializer_list<std::string>{"", "0x10", "0X1p3", "inf", "-Infinity", "nan", "1e400", "-1e400",
                                          "1e-400", "12abc", "1,5", "5 ", " 5", "\t5", std::string("5\0", 2)})
    EXPECT_FALSE(decimalNumber(text, v)) << "'" << text << "'";
}

TEST(NumberText, WholeNumbersAreReadWhole) {
  long v = 0;
  EXPECT_TRUE(wholeNumber("-12", v));
  EXPECT_EQ(v, -12);
  for (const std::string& text : std::initializer_list<std::string>{"", " 5", "5 ", "\t5", "1e3", "5.0",
                                                                    "0x10", "99999999999999999999"})
    EXPECT_FALSE(wholeNumber(text, v)) << "'" << text << "'";
}

TEST(NumberText, ExactNumbersReadBackAsThemselves) {
  EXPECT_EQ(exactNumber(300.0), "300");
  EXPECT_EQ(exactNumber(0.1), "0.1");
  // A point a hair outside a 64-pixel field: 6 digits would print 63.
  EXPECT_EQ(exactNumber(63.0000001), "63.0000001");
  for (double v : {1.0 / 3.0, 2.0 / 3.0 * 1e-300, 123456.789012345678, -0.0, 1.7976931348623157e308})
    EXPECT_EQ(std::strtod(exactNumber(v).c_str(), nullptr), v) << exactNumber(v);
}

}  // namespace
