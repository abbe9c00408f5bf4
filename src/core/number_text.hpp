// number_text.hpp: numbers as text, where users type them and messages and files show them.
// Shared by the library's validation and readers and the CLI's parsers and writers.
#pragma once

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace hfvis::detail {

// How an error message shows a number the user gave or a file held: 6 significant digits
// ("%g"), so that 1e300 is not spelled out in its 301 digits.
inline std::string shortNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", value);
  return text;
}

// The fewest significant digits, at least shortNumber's 6, that read back as the same double:
// where the last digits matter (a point a hair outside the field must not print as one inside;
// a JSON number must read back as the result).
inline std::string exactNumber(double value) {
  char text[40];
  for (int digits = 6; digits < 17; ++digits) {
    std::snprintf(text, sizeof(text), "%.*g", digits, value);
    if (std::strtod(text, nullptr) == value) return text;
  }
  std::snprintf(text, sizeof(text), "%.17g", value);
  return text;
}

// Reads all of `text` as a finite decimal number into `value`; false for anything else.
// strtod alone would also take hexadecimal ("0x10", which the integer options' base-10 parsing
// refuses), "inf" and "nan", and a number beyond double's range (as HUGE_VAL or 0).
inline bool decimalNumber(const std::string& text, double& value) {
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  value = std::strtod(begin, &end);
  // (strtod skips leading white space: " 5" was taken where "5 " was refused)
  return !text.empty() && !std::isspace(static_cast<unsigned char>(text[0])) && end == begin + text.size() &&
         errno != ERANGE && std::isfinite(value) && text.find_first_of("xX") == std::string::npos;
}

// Reads all of `text` as a base-10 whole number within long's range into `value`; false for
// anything else (white space before it too, which strtol would skip).
inline bool wholeNumber(const std::string& text, long& value) {
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  value = std::strtol(begin, &end, 10);
  return !text.empty() && !std::isspace(static_cast<unsigned char>(text[0])) && end == begin + text.size() &&
         errno != ERANGE;
}

}  // namespace hfvis::detail
