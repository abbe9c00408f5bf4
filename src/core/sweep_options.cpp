// sweep_options.cpp: direction azimuths and validation of the options every sweep shares.
#include "hfvis/sweep_options.hpp"

#include <cmath>
#include <numeric>
#include <string>

#include "core/number_text.hpp"
#include "core/sweep_geometry.hpp"
#include "hfvis/errors.hpp"

namespace hfvis {

double directionAzimuth(int k, const SweepOptions& options) {
  // k / K in lowest terms: a direction that two K share (every m-th of m K is one of K's) gets one
  // azimuth to the bit, so that a run extended by the directions between (the horizon angles'
  // maximum error) is a run at the larger K. 2 pi k / K as written rounds differently for K and
  // 3 K (about one direction in seven, from K = 16 on).
  if (options.directions < 1)
    throw InvalidArgument("the number of directions K must be at least 1 (got " +
                          std::to_string(options.directions) + ")");
  const int common = std::gcd(k, options.directions);
  return 2.0 * M_PI * (k / common) / (options.directions / common) + options.azimuth_offset;
}

void validate(const SweepOptions& options) {
  if (options.directions < 1 || options.directions > kMaxDirections) {
    throw InvalidArgument("the number of directions K must be in 1 .. " + std::to_string(kMaxDirections) +
                          " (got " + std::to_string(options.directions) + ")");
  }
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(options.samples_per_unit) || options.samples_per_unit > 64.0) {
    throw InvalidArgument("samples per unit must be in (0, 64] (got " +
                          std::to_string(options.samples_per_unit) + ")");
  }
  // (every direction has an offset within one turn; far beyond, 1e20 radians, the azimuths lost
  // every digit and the results were garbage, with no error)
  if (!std::isfinite(options.azimuth_offset) || std::abs(options.azimuth_offset) > 4.0 * M_PI)
    throw InvalidArgument("the azimuth offset must lie within -4 pi .. 4 pi radians (two turns), got " +
                          std::to_string(options.azimuth_offset));
  detail::validateCurvature(options.curvature, "the curvature coefficient");
  if (!std::isfinite(options.max_distance) || options.max_distance < 0.0) {
    throw InvalidArgument("the maximum distance must be finite and >= 0 ground units, 0 for the whole field (got " +
                          std::to_string(options.max_distance) + ")");
  }
}

namespace detail {

void validateCurvature(double curvature, const std::string& what) {
  // (far beyond, 1e36, the drops overflowed float and the viewshed saw farther: no error)
  if (!std::isfinite(curvature) || std::abs(curvature) > 1.0)
    throw InvalidArgument(what + " must be finite and within -1 .. 1 per ground unit (got " +
                          shortNumber(curvature) + "); earthCurvature() gives the Earth's in 1/m");
}

std::vector<SweepDirection> runDirections(const HeightField& field, const SweepOptions& options) {
  std::vector<SweepDirection> directions;
  for (int k = 0; k < options.directions; ++k) {
    directions.push_back(makeSweepDirection(field, directionAzimuth(k, options), options.samples_per_unit));
  }
  return directions;
}

void validateStripRows(int strip_rows, bool naive) {
  if (strip_rows < 0)
    throw InvalidArgument("the rows per strip must be 0 (automatic) or positive (got " + std::to_string(strip_rows) +
                          ")");
  if (strip_rows > 0 && naive)
    throw InvalidArgument("the naive method does not run in strips (each ray reads the whole field)");
}

}  // namespace detail
}  // namespace hfvis
