// hfvis/height_field.hpp: the height field every operation reads.
#pragma once

#include <cstddef>
#include <vector>

namespace hfvis {

// A W x H grid of heights, row-major, row 0 first as stored in the image.
// Pixel (col, row) sits at ground position (col * cell_size_x, row * cell_size_y);
// between grid points the surface is the bilinear interpolation of the four corners.
//
// Nodata policy: every non-finite height (NaN, +inf, -inf) is nodata. A nodata cell
// neither casts nor receives: outputs at nodata receivers are NaN, and a bilinear sample
// uses only the valid corners of its cell (weights renormalised), so a hole never turns
// a valid neighbour's result into NaN. A sample with no valid corner is simply absent.
struct HeightField {
  int width = 0;
  int height = 0;
  std::vector<float> heights;  // width * height values
  double cell_size_x = 1.0;    // ground units per pixel along columns
  double cell_size_y = 1.0;    // ground units per pixel along rows
  double z_scale = 1.0;        // multiplies every height

  float at(int col, int row) const { return heights[static_cast<std::size_t>(row) * width + col]; }
  std::size_t pixelCount() const { return static_cast<std::size_t>(width) * height; }
  std::size_t nodataCount() const;
};

// Throws InvalidArgument when the field is empty, its sizes disagree, a cell size or the
// z-scale is not finite and positive, or every height is nodata.
void validate(const HeightField& field);

}  // namespace hfvis
