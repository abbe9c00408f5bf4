// cli/observer_files.hpp: the observers of "hfvis viewshed --observers FILE.csv" and the light's
// samples of "hfvis arealight --sources FILE.csv": points read from CSV lines, one reader for both.
#pragma once

#include <istream>
#include <string>
#include <vector>

#include "hfvis/region_visibility.hpp"
#include "hfvis/viewshed.hpp"

namespace hfvis::cli {

// "col,row[,height]" per line; blank lines, lines starting with '#' and one header line before
// the first observer (fields that start with letters: row,col reads the columns in that order,
// names of map coordinates such as x,y are refused) are skipped; a missing height is
// `default_height`. Throws IoError naming `path`, the line and its first 60 bytes (control and
// non-ASCII bytes escaped) for a malformed line, a UTF-16 file, an eye below the surface (a
// negative height unless `absolute`) or no observer at all.
std::vector<Observer> parseObservers(const std::string& path, std::istream& in, double default_height,
                                     bool absolute);

// parseObservers on the file `path`, which must be a regular file (not a device or FIFO).
std::vector<Observer> readObserverFile(const std::string& path, double default_height, bool absolute);

// The same lines as parseObservers, read as sample points: the column and row may be fractional
// (between pixel centres); a negative height is refused unless `absolute` (a sample below the
// surface is hidden from everything). Throws IoError as parseObservers.
std::vector<RegionPoint> parseRegionPoints(const std::string& path, std::istream& in, double default_height,
                                           bool absolute);
// parseRegionPoints on the regular file `path`.
std::vector<RegionPoint> readRegionPointFile(const std::string& path, double default_height, bool absolute);

}  // namespace hfvis::cli
