// unit_normals.hpp: every pixel's unit normal, for the operations that light the surface
// (sun shading, insolation, the lighting benchmark).
#pragma once

#include <vector>

#include "hfvis/height_field.hpp"

namespace hfvis::detail {

// Every pixel's unit normal as ambient occlusion's (pixelNormal, each row's cell sizes on
// latitude / longitude grids), four floats per pixel (x, y, z, 0); NaN at nodata.
std::vector<float> unitNormals(const HeightField& field);

}  // namespace hfvis::detail
