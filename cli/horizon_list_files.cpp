// cli/horizon_list_files.cpp: writing the horizon lists as JSON and CSV text.
#include "horizon_list_files.hpp"

#include <cmath>
#include <cstdio>
#include <iomanip>
#include <sstream>

#include "core/number_text.hpp"
#include "pipeline.hpp"

namespace hfvis::cli {
namespace {

// Shortest text that reads back as the same double (JSON and CSV readers parse doubles).
std::string number(double value) { return std::isfinite(value) ? detail::exactNumber(value) : "null"; }

// The same for a float (the input heights): the shortest text that reads back as that float.
std::string number(float value) {
  if (!std::isfinite(value)) return "null";
  for (int digits = 6; digits < 9; ++digits) {
    std::ostringstream shorter;
    shorter << std::setprecision(digits) << value;
    if (std::stof(shorter.str()) == value) return shorter.str();
  }
  std::ostringstream out;
  out << std::setprecision(9) << value;
  return out.str();
}

constexpr const char* kAzimuthConvention =
    "phi_k = 2*pi*k/K + offset, radians, on the ground from the +column axis toward +row; "
    "compass azimuth = 90 deg + phi_k when row 0 is north";
constexpr const char* kRayConvention =
    "samples i = 1, 2, ... of the receiver's own ray from its pixel centre, i / samples_per_unit pixel "
    "lengths along direction k, bilinear heights, while inside the field (the naive method's samples)";
constexpr const char* kVisibleConvention =
    "a sample is visible when its slope from the receiver is >= the slope of every sample between them "
    "and of every peak between them, the bilinear surface's highest point above the chord of two "
    "consecutive samples where it rises above it (grazing samples are visible), or when the steepest of them "
    "hides it only within the heights' rounding (2^-22 of the sum of the heights compared, counted from "
    "the field's base height, and of the highest one's absolute value), as it does every hidden sample "
    "between "
    "them (each decision an exact sign)";
constexpr const char* kHorizonConvention =
    "nearest first; a horizon is the farthest visible sample of its segment (a peak that is a horizon: the "
    "sample right after it; a sample forgiven its rounding farther out, which may stand a hair lower than "
    "the next horizon); its segment is the visible "
    "samples [segment_begin, segment_end) toward the receiver, up to the first hidden sample or the next "
    "horizon; the segments hold every visible sample once";
constexpr const char* kUnits =
    "distance, near_distance, sample_spacing: ground units (pixels times cell size; on a latitude / "
    "longitude grid each step of the ray at its own row's spacing, sample_spacing the first step's); "
    "elevation_rad, azimuth_rad: radians; heights in the input's units";

}  // namespace

std::string horizonListsJson(const RunArguments& run, const HeightField& field,
                             const std::vector<ReceiverHorizons>& lists) {
  std::ostringstream out;
  out << "{\n";
  out << "  \"format\": \"hfvis horizon lists 1\",\n";
  out << "  \"input\": " << jsonString(run.input) << ",\n";
  out << "  \"width\": " << field.width << ",\n  \"height\": " << field.height << ",\n";
  out << "  \"cell_size\": [" << number(field.cell_size_x) << ", " << number(field.cell_size_y) << "],\n";
  out << "  \"z_scale\": " << number(field.z_scale) << ",\n";
  out << "  \"directions\": " << run.directions << ",\n";
  out << "  \"azimuth_offset_deg\": " << number(run.azimuth_offset_deg) << ",\n";
  out << "  \"samples_per_unit\": " << number(run.samples_per_unit) << ",\n";
  out << "  \"conventions\": {\n";
  out << "    \"azimuth\": " << jsonString(kAzimuthConvention) << ",\n";
  out << "    \"ray\": " << jsonString(kRayConvention) << ",\n";
  out << "    \"visible\": " << jsonString(kVisibleConvention) << ",\n";
  out << "    \"horizons\": " << jsonString(kHorizonConvention) << ",\n";
  out << "    \"units\": " << jsonString(kUnits) << "\n";
  out << "  },\n";
  out << "  \"receivers\": [";
  for (std::size_t r = 0; r < lists.size(); ++r) {
    const ReceiverHorizons& receiver = lists[r];
    out << (r ? "," : "") << "\n    {\"col\": " << receiver.pixel.col << ", \"row\": " << receiver.pixel.row
        << ", \"height\": " << number(receiver.height)
        << ", \"nodata\": " << (receiver.nodata ? "true" : "false") << ",\n     \"directions\": [";
    for (std::size_t k = 0; k < receiver.directions.size(); ++k) {
      const DirectionHorizons& d = receiver.directions[k];
      out << (k ? "," : "") << "\n       {\"k\": " << d.direction
          << ", \"azimuth_rad\": " << number(d.azimuth)
          << ", \"sample_spacing\": " << number(d.sample_spacing) << ", \"ray_samples\": " << d.ray_samples
          << ", \"visible_samples\": " << d.visible_samples << ",\n        \"horizons\": [";
      for (std::size_t h = 0; h < d.horizons.size(); ++h) {
        const VisibilityHorizon& z = d.horizons[h];
        out << (h ? "," : "") << "\n          {\"sample\": " << z.sample
            << ", \"distance\": " << number(z.distance) << ", \"elevation_rad\": " << number(z.elevation)
            << ", \"segment_begin\": " << z.segment_begin << ", \"segment_end\": " << z.segment_end
            << ", \"near_distance\": " << number(z.near_distance)
            << ", \"visible_samples\": " << z.visible_samples << "}";
      }
      out << (d.horizons.empty() ? "" : "\n        ") << "]}";
    }
    out << "\n     ]}";
  }
  out << (lists.empty() ? "" : "\n  ") << "]\n}\n";
  return out.str();
}

const char* horizonListsCsvHeader() {
  return "col,row,direction,azimuth_rad,horizon,sample,distance,elevation_rad,segment_begin,segment_end,"
         "near_distance,visible_samples,nodata";
}

std::string horizonListsCsv(const std::vector<ReceiverHorizons>& lists) {
  std::ostringstream out;
  out << horizonListsCsvHeader() << "\n";
  for (const ReceiverHorizons& receiver : lists) {
    for (const DirectionHorizons& d : receiver.directions) {
      const std::string prefix = std::to_string(receiver.pixel.col) + "," +
                                 std::to_string(receiver.pixel.row) + "," + std::to_string(d.direction) +
                                 "," + number(d.azimuth) + ",";
      // No horizon: a ray leaving the field at once, or a nodata receiver (the last column
      // tells them apart).
      if (d.horizons.empty()) out << prefix << ",,,,,,,0," << (receiver.nodata ? 1 : 0) << "\n";
      for (std::size_t h = 0; h < d.horizons.size(); ++h) {
        const VisibilityHorizon& z = d.horizons[h];
        out << prefix << h << "," << z.sample << "," << number(z.distance) << "," << number(z.elevation)
            << "," << z.segment_begin << "," << z.segment_end << "," << number(z.near_distance) << ","
            << z.visible_samples << ",0\n";
      }
    }
  }
  return out.str();
}

}  // namespace hfvis::cli
