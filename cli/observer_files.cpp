// cli/observer_files.cpp: the observers of "hfvis viewshed --observers FILE.csv"
// (observer_files.hpp).
#include "observer_files.hpp"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "hfvis/errors.hpp"
#include "core/message_numbers.hpp"
#include "io/output_files.hpp"

namespace hfvis::cli {
using detail::shortNumber;

std::vector<Observer> parseObservers(const std::string& path, std::istream& in, double default_height,
                                     bool absolute) {
  // A line as a message shows it: its start, control and non-ASCII bytes escaped (a NUL or
  // UTF-16 byte would garble a terminal, and a 10 MB line would flood it).
  const auto shown = [](const std::string& line) {
    std::string text;
    for (std::size_t i = 0; i < line.size() && i < 60; ++i) {
      const unsigned char c = static_cast<unsigned char>(line[i]);
      if (c >= 0x20 && c < 0x7f) {
        text += static_cast<char>(c);
      } else {
        char escaped[8];
        std::snprintf(escaped, sizeof(escaped), "\\x%02x", c);
        text += escaped;
      }
    }
    return line.size() > 60 ? text + "... (" + std::to_string(line.size()) + " bytes)" : text;
  };
  std::vector<Observer> observers;
  std::string line;
  bool header_seen = false;
  for (int number = 1; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    std::vector<std::string> fields;
    std::stringstream row(line);
    for (std::string f; std::getline(row, f, ',');) fields.push_back(f);
    auto number_in = [](const std::string& text, double& value) {
      const std::size_t a = text.find_first_not_of(" \t"), b = text.find_last_not_of(" \t");
      if (a == std::string::npos) return false;
      const std::string t = text.substr(a, b - a + 1);
      char* end = nullptr;
      value = std::strtod(t.c_str(), &end);
      return end == t.c_str() + t.size() && std::isfinite(value);
    };
    if (number == 1 && (line.rfind("\xFF\xFE", 0) == 0 || line.rfind("\xFE\xFF", 0) == 0))
      throw IoError(path, "is UTF-16 text; save it as UTF-8 (or ASCII) with lines col,row[,height]");
    if (observers.empty() && fields[0].rfind("\xEF\xBB\xBF", 0) == 0) fields[0].erase(0, 3);  // a UTF-8 BOM
    double col = 0, row_index = 0, height = default_height;
    const bool numbers = fields.size() >= 2 && number_in(fields[0], col) && number_in(fields[1], row_index);
    // A header: before any observer, a line whose fields all start with a letter.
    bool words = true;
    for (const std::string& f : fields) {
      const std::size_t a = f.find_first_not_of(" \t");
      words = words && a != std::string::npos && std::isalpha(static_cast<unsigned char>(f[a]));
    }
    if (!numbers && observers.empty() && !header_seen && words) {
      header_seen = true;
      continue;
    }
    if (!numbers || fields.size() > 3 || (fields.size() == 3 && !number_in(fields[2], height)) ||
        col != std::floor(col) || row_index != std::floor(row_index) || std::fabs(col) > 1e9 ||
        std::fabs(row_index) > 1e9)
      throw IoError(path, "line " + std::to_string(number) +
                              ": expected col,row[,height] (whole column and row), got '" + shown(line) +
                              "'");
    if (!absolute && height < 0.0)
      throw IoError(path,
                    "line " + std::to_string(number) + ": the height " + shortNumber(height) +
                        " puts the eye below the surface, where it sees nothing; give a height >= 0 (or "
                        "--absolute)");
    if (std::fabs(height) > 1e12)  // as --observer-height: what the kernels' single precision holds
      throw IoError(path, "line " + std::to_string(number) + ": the height " + shortNumber(height) +
                              " is beyond 1e+12, more than the kernels' single precision holds");
    observers.push_back({static_cast<int>(col), static_cast<int>(row_index), height});
  }
  if (observers.empty()) throw IoError(path, "no observers (lines col,row[,height])");
  return observers;
}

std::vector<Observer> readObserverFile(const std::string& path, double default_height, bool absolute) {
  detail::requireInputFile(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path, std::string("cannot open: ") + std::strerror(errno));
  return parseObservers(path, in, default_height, absolute);
}

}  // namespace hfvis::cli
