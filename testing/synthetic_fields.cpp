// synthetic_fields.cpp: generated hard-case height fields (README, Tests).
#include "hfvis/synthetic_fields.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <random>

#include "hfvis/errors.hpp"

namespace hfvis {
namespace {

using Generator = std::function<float(int c, int r, int w, int h, std::mt19937& rng)>;

const std::map<std::string, Generator>& generators() {
  static const std::map<std::string, Generator> table = {
      {"flat", [](int, int, int, int, std::mt19937&) { return 3.0f; }},
      {"tilted_plane",
       [](int c, int, int, int, std::mt19937&) { return static_cast<float>(8848.0 + 0.001 * c); }},
      {"terraces",
       [](int c, int r, int, int, std::mt19937&) { return static_cast<float>((c / 4 + r / 7) % 5); }},
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
