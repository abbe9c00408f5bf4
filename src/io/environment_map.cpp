// environment_map.cpp: environment maps (hfvis/environment_map.hpp): checks, reading and a
// uniform sky.
#include "hfvis/environment_map.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "hfvis/errors.hpp"
#include "hfvis/image_io.hpp"
#include "io/image_reading.hpp"

namespace hfvis {

constexpr float kMostRadiance = 1e30f;

void validate(const EnvironmentMap& map) {
  if (!(map.height > 0 && map.width == 2 * map.height))
    throw InvalidArgument("an environment map must be equirectangular, twice as wide as tall (got " +
                          std::to_string(map.width) + " x " + std::to_string(map.height) + ")");
  if ((map.channels != 1 && map.channels != 3) || map.names.size() != static_cast<std::size_t>(map.channels))
    throw InvalidArgument("an environment map needs one channel or three (R, G, B), each named (got " +
                          std::to_string(map.channels) + ")");
  const std::size_t plane = static_cast<std::size_t>(map.width) * map.height;
  if (map.radiance.size() != plane * map.channels)
    throw InvalidArgument("the environment map holds " + std::to_string(map.radiance.size()) +
                          " values, not " + std::to_string(plane * map.channels));
  for (std::size_t i = 0; i < map.radiance.size(); ++i) {
    const float v = map.radiance[i];
    // The tables sum radiance times solid angle over up to millions of pixels in single
    // precision: 1e30 leaves room for that below float's 3.4e38.
    if (!(std::isfinite(v) && v >= 0.0f && v <= kMostRadiance)) {
      const std::size_t p = i % plane;
      std::ostringstream s;
      s << "the environment's radiance must be finite, >= 0 and at most " << kMostRadiance << "; channel "
        << map.names[i / plane] << " at column " << p % map.width << ", row " << p / map.width << " is " << v;
      throw InvalidArgument(s.str());
    }
  }
  if (!std::isfinite(map.rotation_deg)) throw InvalidArgument("the environment's rotation must be finite");
  if (map.table_rows < 0 || map.table_rows > 65536)
    throw InvalidArgument("the environment table's rows must be 0 (the map's) or 1 .. 65536 (got " +
                          std::to_string(map.table_rows) + ")");
}

EnvironmentMap readEnvironmentMap(const std::string& path) {
  ImageChannels image = readColourImage(path, "an environment map");
  detail::requireFloatRadiance(image.integers, path, "an environment map");
  EnvironmentMap map;
  map.width = image.width;
  map.height = image.height;
  map.channels = static_cast<int>(image.planes.size());
  map.names = image.names;
  for (const std::vector<float>& plane : image.planes)
    map.radiance.insert(map.radiance.end(), plane.begin(), plane.end());
  try {
    validate(map);
  } catch (const InvalidArgument& e) {
    throw IoError(path, e.what());
  }
  return map;
}

int tableRows(const EnvironmentMap& map) { return map.table_rows > 0 ? map.table_rows : map.height; }

EnvironmentMap uniformEnvironment(float radiance, int height) {
  EnvironmentMap map;
  map.width = 2 * height;
  map.height = height;
  map.channels = 1;
  map.names = {"Y"};
  map.radiance.assign(static_cast<std::size_t>(map.width) * height, radiance);
  return map;
}

}  // namespace hfvis
