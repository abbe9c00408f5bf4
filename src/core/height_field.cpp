// height_field.cpp: HeightField helpers and validation.
#include "hfvis/height_field.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "core/number_text.hpp"
#include "hfvis/errors.hpp"

namespace hfvis {
using detail::exactNumber;
using detail::shortNumber;

std::size_t HeightField::nodataCount() const {
  std::size_t count = 0;
  for (float h : heights) count += std::isfinite(h) ? 0 : 1;
  return count;
}

namespace {
bool held(double size) { return size >= kLeastCellSize && size <= kMostCellSize; }  // (false for NaN)
}  // namespace

bool cellSizesHeld(const HeightField& field) {
  bool all = held(field.cell_size_x) && held(field.cell_size_y);
  for (std::size_t r = 0; r < field.row_cell_size_x.size(); ++r) all = all && held(field.row_cell_size_x[r]);
  for (std::size_t r = 0; r < field.row_cell_size_y.size(); ++r) all = all && held(field.row_cell_size_y[r]);
  return all;
}

void requireHeightsKeptInFloat32(double rounding, double lowest, double highest, double cell_size) {
  if (rounding > std::max(1e-3 * (highest - lowest), 1e-2 * cell_size))
    throw InvalidArgument("the heights (" + exactNumber(lowest) + " .. " + exactNumber(highest) +
                          ") lie so far from 0 that float32, in which hfvis computes, rounds them by up to " +
                          shortNumber(rounding) +
                          ", more than a thousandth of their range and a hundredth of a cell: subtract a "
                          "constant from them first");
}

double heightBase(const HeightField& field) {
  // (a field whose heights are not width x height, which validate refuses, samples nothing)
  const bool sized = field.heights.size() == field.pixelCount();
  const long rows = sized ? std::min(field.height, 64) : 0, cols = std::min(field.width, 64);
  std::vector<float> sample;
  sample.reserve(static_cast<std::size_t>(rows * cols));
  for (long i = 0; i < rows; ++i) {
    const std::size_t row = static_cast<std::size_t>((2 * i + 1) * field.height / (2 * rows));
    for (long j = 0; j < cols; ++j) {
      const std::size_t col = static_cast<std::size_t>((2 * j + 1) * field.width / (2 * cols));
      const float h = field.heights[row * static_cast<std::size_t>(field.width) + col];
      if (std::isfinite(h)) sample.push_back(h);
    }
  }
  if (sample.empty()) {
    float lowest = std::numeric_limits<float>::infinity();
    for (const float h : field.heights) lowest = std::isfinite(h) ? std::min(lowest, h) : lowest;
    return lowest;
  }
  const auto middle = sample.begin() + static_cast<std::ptrdiff_t>((sample.size() - 1) / 2);
  std::nth_element(sample.begin(), middle, sample.end());
  return *middle;
}

void validate(const HeightField& field) {
  if (field.width <= 0 || field.height <= 0) {
    throw InvalidArgument("height field is empty (" + std::to_string(field.width) + " x " +
                          std::to_string(field.height) + " pixels)");
  }
  if (field.heights.size() != field.pixelCount()) {
    throw InvalidArgument("height field holds " + std::to_string(field.heights.size()) +
                          " heights for " + std::to_string(field.width) + " x " +
                          std::to_string(field.height) + " pixels");
  }
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  const std::string range = " is outside " + shortNumber(kLeastCellSize) + " .. " +
                            shortNumber(kMostCellSize) +
                            " ground units, what the kernels' single precision holds";
  if (!held(field.cell_size_x) || !held(field.cell_size_y)) {
    throw InvalidArgument("the cell size " + shortNumber(field.cell_size_x) + " x " +
                          shortNumber(field.cell_size_y) + range);
  }
  if (!field.row_cell_size_x.empty() || !field.row_cell_size_y.empty()) {
    if (field.row_cell_size_x.size() != static_cast<std::size_t>(field.height) ||
        field.row_cell_size_y.size() != static_cast<std::size_t>(field.height)) {
      throw InvalidArgument("per-row cell sizes need one entry per row (" + std::to_string(field.height) +
                            "), got " + std::to_string(field.row_cell_size_x.size()) + " and " +
                            std::to_string(field.row_cell_size_y.size()));
    }
    for (std::size_t r = 0; r < field.row_cell_size_x.size(); ++r) {
      if (!held(field.row_cell_size_x[r]) || !held(field.row_cell_size_y[r]))
        throw InvalidArgument("the cell size of row " + std::to_string(r) + " (" +
                              shortNumber(field.row_cell_size_x[r]) + " x " +
                              shortNumber(field.row_cell_size_y[r]) + ")" + range);
    }
  }
  if (!positive(field.z_scale)) {
    throw InvalidArgument("z-scale must be finite and positive (got " + shortNumber(field.z_scale) + ")");
  }
  if (field.nodataCount() == field.pixelCount()) {
    throw InvalidArgument("every height is nodata (NaN or infinite)");
  }
  const FieldOrigin& o = field.origin;
  if (o.present()) {
    if (o.col < 0 || o.row < 0 || long(o.col) + field.width > o.whole_width ||
        long(o.row) + field.height > o.whole_height) {
      throw InvalidArgument("the origin places the " + std::to_string(field.width) + " x " +
                            std::to_string(field.height) + " field at (" + std::to_string(o.col) + ", " +
                            std::to_string(o.row) + "), not inside its larger field of " +
                            std::to_string(o.whole_width) + " x " + std::to_string(o.whole_height));
    }
    if (!std::isfinite(o.base))
      throw InvalidArgument("the origin's base height (" + shortNumber(o.base) + ") must be finite");
    // With per-row spacing the larger field's rows, this field's among them; none without.
    const bool rows = !field.row_cell_size_x.empty();
    const std::size_t whole_rows = rows ? static_cast<std::size_t>(o.whole_height) : 0;
    bool matching = o.row_cell_size_x.size() == whole_rows && o.row_cell_size_y.size() == whole_rows;
    for (int r = 0; matching && rows && r < field.height; ++r)
      matching = o.row_cell_size_x[o.row + r] == field.row_cell_size_x[r] &&
                 o.row_cell_size_y[o.row + r] == field.row_cell_size_y[r];
    for (std::size_t r = 0; matching && r < whole_rows; ++r)
      matching = positive(o.row_cell_size_x[r]) && positive(o.row_cell_size_y[r]);
    if (!matching)
      throw InvalidArgument(rows ? "the origin's per-row cell sizes must be the larger field's " +
                                       std::to_string(o.whole_height) +
                                       " rows (finite and positive), this field's rows among them"
                                 : std::string("the origin has per-row cell sizes but the field has none"));
  }
}

}  // namespace hfvis
