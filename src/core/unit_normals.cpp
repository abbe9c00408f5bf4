// unit_normals.cpp: every pixel's unit normal (see unit_normals.hpp).
#include "core/unit_normals.hpp"

#include <cmath>
#include <limits>

#include "core/horizon_common.hpp"

namespace hfvis {
namespace detail {

std::vector<float> unitNormals(const HeightField& field) {
  const PreparedHeights prepared = prepareHeights(field);
  const bool rows = hasRowSpacing(field);
  std::vector<float> normals(4 * field.pixelCount(), std::numeric_limits<float>::quiet_NaN());
  for (int r = 0; r < field.height; ++r) {
    const float cell_x = static_cast<float>(rows ? field.row_cell_size_x[r] : field.cell_size_x);
    const float cell_y = static_cast<float>(rows ? field.row_cell_size_y[r] : field.cell_size_y);
    for (int c = 0; c < field.width; ++c) {
      const std::size_t p = static_cast<std::size_t>(r) * field.width + c;
      if (std::isnan(prepared.heights[p])) continue;
      pixelNormal(prepared.heights, field.width, field.height, c, r, cell_x, cell_y, &normals[4 * p]);
      normals[4 * p + 3] = 0.0f;
    }
  }
  return normals;
}

}  // namespace detail

}  // namespace hfvis
