// environment_map.cpp: environment maps (hfvis/environment_map.hpp): checks, reading and a
// uniform sky.
#include "hfvis/environment_map.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "hfvis/errors.hpp"
#include "hfvis/image_io.hpp"

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
    throw InvalidArgument("the environment map holds " + std::to_string(map.radiance.size()) + " values, not " +
                          std::to_string(plane * map.channels));
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
  ImageChannels image = readImage(path);
  std::vector<std::size_t> take;
  auto find = [&](const char* name) {
    for (std::size_t i = 0; i < image.names.size(); ++i)
      if (image.names[i] == name) return static_cast<int>(i);
    return -1;
  };
  const int r = find("R"), g = find("G"), b = find("B");
  const bool rgb = r >= 0 && g >= 0 && b >= 0;
  const std::size_t others = image.names.size() - (rgb ? 3 : 0) - (rgb && find("A") >= 0 ? 1 : 0);
  if (rgb && others == 0) {
    take = {static_cast<std::size_t>(r), static_cast<std::size_t>(g), static_cast<std::size_t>(b)};
  } else if (image.names.size() == 1) {
    take = {0};
  } else {
    std::string names;
    for (const std::string& n : image.names) names += (names.empty() ? "" : ", ") + n;
    throw IoError(path, "an environment map needs one channel or R, G, B (and A, ignored); it has " +
                            (names.empty() ? std::string("none") : names));
  }
  EnvironmentMap map;
  map.width = image.width;
  map.height = image.height;
  map.channels = static_cast<int>(take.size());
  map.names = take.size() == 1 ? std::vector<std::string>{"Y"} : std::vector<std::string>{"R", "G", "B"};
  for (std::size_t i : take) map.radiance.insert(map.radiance.end(), image.planes[i].begin(), image.planes[i].end());
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
