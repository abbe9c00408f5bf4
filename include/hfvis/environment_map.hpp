// hfvis/environment_map.hpp: distant HDR light environments as images, the input of
// environment light (hfvis/environment_light.hpp).
//
// An environment is an equirectangular (latitude / longitude) image: row 0 at the zenith, the
// last row at the nadir, each row a band of equal zenith angle pi / height; the columns span the
// full circle of azimuth, the column at fraction u of the width (0 at the left edge, 1 at the
// right) looking toward compass azimuth 360 u + rotation_deg degrees, clockwise from north: the
// left edge north, a quarter of the way east, the middle south, three quarters west. Over a
// field whose row 0 is north (hfvis azimuth = compass azimuth - 90 degrees) that is hfvis
// azimuth 2 pi u + rotation - pi / 2. Radiance is constant over each pixel of the map.
//
#pragma once

#include <string>
#include <vector>

namespace hfvis {

struct EnvironmentMap {
  int width = 0;     // 2 * height
  int height = 0;    // zenith to nadir
  int channels = 0;  // 1 (Y) or 3 (R, G, B)
  // Radiance, planar: channel c's row-major plane at c * width * height; finite and >= 0.
  std::vector<float> radiance;
  std::vector<std::string> names;  // the channels' names: {"Y"} or {"R", "G", "B"}
  double rotation_deg = 0.0;       // compass degrees added to every column's azimuth
  // Bands of zenith angle in the tables, each the mean of the map's rows it spans, weighted by
  // solid angle; 0 = the map's own rows. 1 .. 65536.
  int table_rows = 0;
};

// Throws InvalidArgument for a map that is not width = 2 * height > 0, not 1 or 3 channels with
// as many names, the wrong number of values, a negative or non-finite radiance (naming the first
// such pixel), a non-finite rotation or a table_rows outside 0 .. 65536.
void validate(const EnvironmentMap& map);

// Reads an environment map (an EXR, a Radiance HDR, ..., as readImage does): one channel, or R,
// G, B (an alpha channel A beside them is ignored). Throws IoError naming the file for what
// readImage refuses, for a map with other channels, and for what validate refuses.
EnvironmentMap readEnvironmentMap(const std::string& path);

// The bands of zenith angle in the map's tables: table_rows, or the map's rows when 0.
int tableRows(const EnvironmentMap& map);

// A uniform environment of `radiance` in one channel, `height` rows (tests and tools).
EnvironmentMap uniformEnvironment(float radiance, int height = 8);

}  // namespace hfvis
