// synthetic_fields.cpp: generated hard-case height fields (docs/TESTING.md).
#include "hfvis_testing/synthetic_fields.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <random>

#include "hfvis/errors.hpp"

namespace hfvis {
namespace {

using Generator = std::function<float(int c, int r, int w, int h, std::mt19937& rng)>;

// A hash of a block's indices into [0, 2^32), for its layout and heights.
std::uint32_t blockHash(long u, long v, std::uint32_t salt) {
  std::uint64_t x = static_cast<std::uint64_t>(u) * 0x9E3779B97F4A7C15ull ^ static_cast<std::uint64_t>(v) * 0xC2B2AE3D27D4EB4Full ^ salt;
  x ^= x >> 31;
  x *= 0xBF58476D1CE4E5B9ull;
  x ^= x >> 29;
  return static_cast<std::uint32_t>(x >> 16);
}

// A city DSM in pixel units: flat ground at 0 with blocks of buildings between streets of 1 to
// 3 pixels, on a grid along the axes in the west half and rotated by 27 degrees in the east
// half. A block (10 to 16 pixels a side with its street) is one of: a building filling the lot;
// four buildings touching only at their corners (a checkerboard of lot quarters, alternate
// quarters open); a courtyard (a ring of roof around an open court); a tower on a low podium;
// one-pixel walls across an open lot; strips of buildings of different heights side by side.
// Heights 3 to 60, on whole and half units (flat roofs). Along a diagonal the bilinear surface
// peaks inside cells here (two high corners off the line), which only the segment peaks catch.
float cityHeight(int c, int r, int w, int) {
  const bool rotated = c >= w / 2;
  const double angle = rotated ? 27.0 * M_PI / 180.0 : 0.0;
  const double x = c + 0.5, y = r + 0.5;
  const double u = x * std::cos(angle) + y * std::sin(angle) + (rotated ? 3.7 : 0.0);
  const double v = -x * std::sin(angle) + y * std::cos(angle) + (rotated ? 5.3 : 0.0);
  // Blocks of pitch_u x pitch_v pixels with their street (10 to 14 pixels along the axes, 12 to
  // 16 rotated).
  const int pitch_u = rotated ? 16 : 14, pitch_v = rotated ? 12 : 10;
  const long column = static_cast<long>(std::floor(u / pitch_u)), row = static_cast<long>(std::floor(v / pitch_v));
  double lu = u - column * pitch_u, lv = v - row * pitch_v;
  const std::uint32_t h = blockHash(column + (rotated ? 1000 : 0), row, 3);
  const int street = 1 + static_cast<int>(h % 3);
  if (lu < street || lv < street) return 0.0f;
  lu -= street;
  lv -= street;
  const double su = pitch_u - street, sv = pitch_v - street;  // the lot
  const float height = 3.0f + 0.5f * static_cast<float>((h >> 4) % 115);
  switch ((h >> 12) % 6) {
    case 0:
      return height;
    case 1:  // four buildings that touch only at their corners
      return ((lu < su / 2) != (lv < sv / 2)) ? height : 0.0f;
    case 2: {  // a courtyard
      const double ring = 2.0 + (h >> 20) % 2;
      return (lu < ring || lv < ring || lu >= su - ring || lv >= sv - ring) ? height : 0.0f;
    }
    case 3: {  // a tower on a podium
      const bool core = std::fabs(lu - su / 2) < su / 5 + 0.5 && std::fabs(lv - sv / 2) < sv / 5 + 0.5;
      return core ? std::min(60.0f, 2.0f * height) : 4.0f;
    }
    case 4:  // one-pixel walls across an open lot
      return (static_cast<int>(lu) % 4 == 1) ? height : 0.0f;
    default: {  // strips of different heights side by side
      const int strip = static_cast<int>(lv / 3.0);
      return 3.0f + 0.5f * static_cast<float>(blockHash(column, row * 16 + strip, 4) % 115);
    }
  }
}

const std::map<std::string, Generator>& generators() {
  static const std::map<std::string, Generator> table = {
      {"flat", [](int, int, int, int, std::mt19937&) { return 3.0f; }},
      {"tilted_plane",
       [](int c, int, int, int, std::mt19937&) { return static_cast<float>(8848.0 + 0.001 * c); }},
      {"terraces",
       [](int c, int r, int, int, std::mt19937&) { return static_cast<float>((c / 4 + r / 7) % 5); }},
      {"city", [](int c, int r, int w, int h, std::mt19937&) { return cityHeight(c, r, w, h); }},
      {"cliff", [](int c, int, int w, int, std::mt19937&) { return c < w / 2 ? 0.0f : 1e6f; }},
      {"spikes",
       [](int, int, int, int, std::mt19937& rng) {
         return std::uniform_int_distribution<int>(0, 16)(rng) == 0 ? 40.0f : 0.0f;
       }},
      {"sine", [](int c, int r, int, int,
                  std::mt19937&) { return static_cast<float>(4.0 * std::sin(c * 0.4) * std::sin(r * 0.3)); }},
      {"bowl",
       [](int c, int r, int w, int h, std::mt19937&) {
         const double x = c - (w - 1) / 2.0, y = r - (h - 1) / 2.0;
         // Every other point depressed: the worst case of the hull tree.
         return static_cast<float>(0.05 * (x * x + y * y) - ((c + r) % 2 ? 1.0 : 0.0));
       }},
      {"dome",
       [](int c, int r, int w, int h, std::mt19937&) {
         const double x = c - (w - 1) / 2.0, y = r - (h - 1) / 2.0, rad = std::max(w, h) / 2.0;
         return static_cast<float>(std::sqrt(std::max(0.0, rad * rad - x * x - y * y)));
       }},
      {"noise", [](int, int, int, int,
                   std::mt19937& rng) { return std::uniform_real_distribution<float>(0, 10)(rng); }},
      {"nan_holes",
       [](int c, int r, int, int, std::mt19937& rng) {
         const float h = std::uniform_real_distribution<float>(0, 5)(rng);
         return ((c / 3 + r / 2) % 4 == 1) ? std::numeric_limits<float>::quiet_NaN() : h;
       }},
      {"infinities",
       [](int c, int r, int, int, std::mt19937& rng) {
         const float h = std::uniform_real_distribution<float>(0, 5)(rng);
         if ((c * 7 + r * 3) % 11 == 5) return std::numeric_limits<float>::infinity();
         if ((c * 5 + r * 13) % 17 == 3) return -std::numeric_limits<float>::infinity();
         return h;
       }},
      {"denormals",
       [](int c, int r, int, int, std::mt19937&) {
         return std::numeric_limits<float>::denorm_min() * static_cast<float>((c * 3 + r * 5) % 9);
       }},
      {"negative",
       [](int c, int r, int, int, std::mt19937& rng) {
         return -100.0f + static_cast<float>(c % 5) - std::uniform_real_distribution<float>(0, 3)(rng) -
                0.5f * static_cast<float>(r % 3);
       }},
  };
  return table;
}

}  // namespace

const std::vector<std::string>& syntheticFieldNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const auto& [name, gen] : generators()) n.push_back(name);
    return n;
  }();
  return names;
}

HeightField makeSyntheticField(const std::string& name, int width, int height, std::uint32_t seed) {
  const auto it = generators().find(name);
  if (it == generators().end()) throw InvalidArgument("unknown synthetic field '" + name + "'");
  if (width <= 0 || height <= 0) throw InvalidArgument("synthetic field size must be positive");
  HeightField field;
  field.width = width;
  field.height = height;
  field.heights.resize(field.pixelCount());
  std::mt19937 rng(seed);
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c)
      field.heights[static_cast<std::size_t>(r) * width + c] = it->second(c, r, width, height, rng);
  return field;
}

}  // namespace hfvis
