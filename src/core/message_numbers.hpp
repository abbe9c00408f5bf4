// message_numbers.hpp: how an error message shows a number the user gave or a file held: 6
// significant digits ("%g"), so that 1e300 is not spelled out in its 301 digits. Shared by the
// library's validation and readers and the CLI's parsers.
#pragma once

#include <cstdio>
#include <string>

namespace hfvis::detail {

inline std::string shortNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", value);
  return text;
}

}  // namespace hfvis::detail
