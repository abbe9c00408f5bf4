// cli/observer_files.hpp: the observers of "hfvis viewshed --observers FILE.csv".
#pragma once

#include <istream>
#include <string>
#include <vector>

#include "hfvis/viewshed.hpp"

namespace hfvis::cli {

// "col,row[,height]" per line; blank lines, lines starting with '#' and one header line before
// the first observer (fields that start with letters) are skipped; a missing height is
// `default_height`. Throws IoError naming `path`, the line and its first 60 bytes (control and
// non-ASCII bytes escaped) for a malformed line, a UTF-16 file, an eye below the surface (a
// negative height unless `absolute`) or no observer at all.
std::vector<Observer> parseObservers(const std::string& path, std::istream& in, double default_height,
                                     bool absolute);

// parseObservers on the file `path`, which must be a regular file (not a device or FIFO).
std::vector<Observer> readObserverFile(const std::string& path, double default_height, bool absolute);

}  // namespace hfvis::cli
