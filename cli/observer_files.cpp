// cli/observer_files.cpp: the observers of "hfvis viewshed --observers FILE.csv" and the light's
// samples of "hfvis arealight --sources FILE.csv" (observer_files.hpp).
#include "observer_files.hpp"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <utility>

#include "core/number_text.hpp"
#include "hfvis/errors.hpp"
#include "io/output_files.hpp"

namespace hfvis::cli {
using detail::shortNumber;

namespace {

// A point of a CSV line: column, row (whole, or fractional where `whole` is false) and height.
struct CsvPoint {
  double col = 0.0, row = 0.0, height = 0.0;
};

// How the two files' lines differ: what a point is called and whether its column and row must be
// whole (an observer stands on a grid point; a light's sample may lie between them).
struct PointKind {
  bool whole;
  const char* expected;  // the line's form, for the message
  const char* below;     // why a negative height is refused
  const char* none;      // the message for a file without points
};

// "col,row[,height]" per line; blank lines, lines starting with '#' and one header line before
// the first point (fields that start with letters: row,col reads the columns in that order, names
// of map coordinates such as x,y are refused) are skipped; a missing height is
// `default_height`. Throws IoError naming `path`, the line and its first 60 bytes (control and
// non-ASCII bytes escaped) for a malformed line, a UTF-16 file, a negative height unless
// `absolute`, or no point at all.
std::vector<CsvPoint> parsePoints(const std::string& path, std::istream& in, double default_height,
                                  bool absolute, const PointKind& kind) {
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
  std::vector<CsvPoint> points;
  std::string line;
  bool header_seen = false, row_first = false;
  for (int number = 1; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    // A UTF-8 BOM starts the file, whatever its first line holds (a comment, nothing).
    if (number == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
    const std::size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    std::vector<std::string> fields;
    std::stringstream row(line);
    for (std::string f; std::getline(row, f, ',');) fields.push_back(f);
    auto number_in = [](const std::string& text, double& value) {
      const std::size_t a = text.find_first_not_of(" \t"), b = text.find_last_not_of(" \t");
      if (a == std::string::npos) return false;
      return detail::decimalNumber(text.substr(a, b - a + 1), value);
    };
    if (number == 1 && (line.rfind("\xFF\xFE", 0) == 0 || line.rfind("\xFE\xFF", 0) == 0))
      throw IoError(path, "is UTF-16 text; save it as UTF-8 (or ASCII) with lines col,row[,height]");
    // Without a byte-order mark UTF-16 shows as zero bytes between the characters (text has none).
    if (line.find('\0') != std::string::npos)
      throw IoError(path,
                    "line " + std::to_string(number) +
                        " holds zero bytes: UTF-16 text without a byte-order mark, or not text; save it "
                        "as UTF-8 (or ASCII) with lines col,row[,height]");
    double col = 0, row_index = 0, height = default_height;
    const bool numbers = fields.size() >= 2 && number_in(fields[0], col) && number_in(fields[1], row_index);
    // A header: before any point, a line whose fields all start with a letter and are no numbers
    // strtod reads ("nan,nan" was passed over as a header, where a later one is refused).
    bool words = true;
    for (const std::string& f : fields) {
      const std::size_t a = f.find_first_not_of(" \t"), b = f.find_last_not_of(" \t");
      words = words && a != std::string::npos && std::isalpha(static_cast<unsigned char>(f[a]));
      if (words) {
        const std::string word = f.substr(a, b - a + 1);
        char* end = nullptr;
        std::strtod(word.c_str(), &end);
        words = end != word.c_str() + word.size();
      }
    }
    if (!numbers && points.empty() && !header_seen && words) {
      // Its first two names may say the columns' order: row,col reads them so (every header was
      // passed over: a row,col file was read as col,row, exit 0). Names of map coordinates (x,y,
      // lat,lon, easting,northing) are refused: such a file was read as pixels. Others (col,row,
      // column,row, x_pixel,y_pixel) are taken as col,row, as before; a third name is not judged.
      std::vector<std::string> names;
      for (const std::string& f : fields) {
        const std::size_t a = f.find_first_not_of(" \t"), b = f.find_last_not_of(" \t");
        std::string name = f.substr(a, b - a + 1);
        for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        names.push_back(name);
      }
      const auto is = [](const std::string& name, std::initializer_list<const char*> any) {
        for (const char* n : any)
          if (name == n) return true;
        return false;
      };
      const auto column = [&](const std::string& n) {
        return is(n, {"col", "cols", "column", "columns", "c"});
      };
      const auto row_name = [&](const std::string& n) { return is(n, {"row", "rows", "r"}); };
      const auto map = [&](const std::string& n) {
        return is(n, {"x", "y", "lon", "lat", "long", "longitude", "latitude", "easting", "northing"});
      };
      if (names.size() >= 2 && (map(names[0]) || map(names[1])))
        throw IoError(path,
                      "line " + std::to_string(number) + ": the header '" + shown(line) +
                          "' names map coordinates: the file holds pixel columns and rows, col,row[,height] "
                          "(or row,col[,height]); convert the coordinates to pixels first");
      // The columns are read by position: a header that names a column or a row in another place,
      // or a height among the first two, says the file is laid out otherwise (id,col,row was read
      // as column 7, row 30, height 40, exit 0).
      const auto height_name = [&](const std::string& n) {
        return is(n, {"height", "heights", "h", "z", "elevation", "altitude", "alt", "eye"});
      };
      const auto place = [&](const std::string& n) { return column(n) || row_name(n); };
      // (a name the rule does not know beside a known one stays col,row: col,line, pixel_col,row)
      bool elsewhere =
          names.size() >= 2 &&
          (height_name(names[0]) || height_name(names[1]) || (column(names[1]) && !row_name(names[0])) ||
           (row_name(names[0]) && !column(names[1])) || (column(names[0]) && column(names[1])) ||
           (row_name(names[0]) && row_name(names[1])));
      for (std::size_t i = 2; i < names.size(); ++i) elsewhere = elsewhere || place(names[i]);
      if (elsewhere)
        throw IoError(path, "line " + std::to_string(number) + ": the header '" + shown(line) +
                                "' lays the columns out otherwise: the file's fields are read by position, "
                                "col,row[,height] (or row,col[,height]); reorder them");
      header_seen = true;
      row_first = names.size() >= 2 && row_name(names[0]) && column(names[1]);
      continue;
    }
    // (getline drops an empty last field: "1,1," would pass for "1,1" and "1,1,2," for "1,1,2")
    const bool trailing_comma = line[line.find_last_not_of(" \t")] == ',';
    // (a third field that is no finite number: named, not taken for a bad column or row)
    if (numbers && !trailing_comma && fields.size() == 3 && !number_in(fields[2], height))
      throw IoError(path, "line " + std::to_string(number) + ": the height '" + shown(fields[2]) +
                              "' is not a finite number, in '" + shown(line) + "'");
    if (!numbers || trailing_comma || fields.size() > 3 ||
        (kind.whole && (col != std::floor(col) || row_index != std::floor(row_index))))
      throw IoError(path, "line " + std::to_string(number) + ": expected " + kind.expected + ", got '" +
                              shown(line) + "'");
    // (beyond 1e9 a column or row lies outside any field this hfvis reads, and would not fit an int)
    if (!(std::fabs(col) <= 1e9 && std::fabs(row_index) <= 1e9))
      throw IoError(path, "line " + std::to_string(number) + ": the point " + shortNumber(col) + "," +
                              shortNumber(row_index) +
                              " lies outside the field (a column or row beyond 1e9)");
    if (!absolute && height < 0.0)
      throw IoError(path, "line " + std::to_string(number) + ": the height " + shortNumber(height) + " " +
                              kind.below + "; give a height >= 0 (or --absolute)");
    if (std::fabs(height) > 1e12)  // as --observer-height: what the kernels' single precision holds
      throw IoError(path, "line " + std::to_string(number) + ": the height " + shortNumber(height) +
                              " is beyond 1e+12, more than the kernels' single precision holds");
    if (row_first) std::swap(col, row_index);
    points.push_back({col, row_index, height});
  }
  if (points.empty()) throw IoError(path, kind.none);
  return points;
}

const PointKind kObserverKind{true, "col,row[,height] (whole column and row)",
                              "puts the eye below the surface, where it sees nothing",
                              "no observers (lines col,row[,height])"};
const PointKind kSourceKind{
    false, "col,row[,height] (numbers: column and row, fractional between pixel centres)",
    "puts the sample below the surface, where nothing sees it", "no sources (lines col,row[,height])"};

// The file `path`, which must be a regular file (not a device or FIFO), open for reading.
std::ifstream openCsv(const std::string& path) {
  detail::requireInputFile(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path, std::string("cannot open: ") + std::strerror(errno));
  return in;
}

}  // namespace

std::vector<Observer> parseObservers(const std::string& path, std::istream& in, double default_height,
                                     bool absolute) {
  std::vector<Observer> observers;
  for (const CsvPoint& p : parsePoints(path, in, default_height, absolute, kObserverKind))
    observers.push_back({static_cast<int>(p.col), static_cast<int>(p.row), p.height});
  return observers;
}

std::vector<RegionPoint> parseRegionPoints(const std::string& path, std::istream& in, double default_height,
                                           bool absolute) {
  std::vector<RegionPoint> points;
  for (const CsvPoint& p : parsePoints(path, in, default_height, absolute, kSourceKind))
    points.push_back({p.col, p.row, p.height});
  return points;
}

std::vector<RegionPoint> readRegionPointFile(const std::string& path, double default_height, bool absolute) {
  std::ifstream in = openCsv(path);
  return parseRegionPoints(path, in, default_height, absolute);
}

std::vector<Observer> readObserverFile(const std::string& path, double default_height, bool absolute) {
  std::ifstream in = openCsv(path);
  return parseObservers(path, in, default_height, absolute);
}

}  // namespace hfvis::cli
