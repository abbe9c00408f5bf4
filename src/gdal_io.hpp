// gdal_io.hpp: georeferenced rasters through GDAL (GeoTIFF, COG, HGT, AAIGrid, VRT, ...):
// heights with their nodata value (those cells become NaN), geotransform and CRS.
// OpenImageIO keeps EXR, PNG and other images (image_io.cpp decides by extension).
#pragma once

#include <string>

#include "hfvis/image_io.hpp"

namespace hfvis::detail {

// Ground metres per degree on the WGS84 ellipsoid at geodetic latitude `lat_deg`, along a
// meridian and along a parallel (both readers convert geographic spacing with it).
void metresPerDegree(double lat_deg, double* along_meridian, double* along_parallel);

// Whether `path` names a raster format that GDAL reads rather than OpenImageIO.
bool isGdalRaster(const std::string& path);

// Reads band `options.channel` ("" = the only band; an index "0".. or a band description) as
// heights: nodata cells NaN, cell sizes from the geotransform (geographic degrees in metres at
// the field's centre latitude) unless the options give them. Throws IoError (unreadable,
// rotated or sheared geotransform, too large).
HeightField readGdalHeightField(const std::string& path, const HeightFieldReadOptions& options);

}  // namespace hfvis::detail
