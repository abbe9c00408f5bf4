// gdal_io.hpp: georeferenced rasters through GDAL (GeoTIFF, COG, HGT, AAIGrid, VRT, ...):
// reading heights and bands with their nodata value (those cells become NaN), geotransform and
// CRS, and writing results as GeoTIFF. OpenEXR keeps EXR, OpenImageIO PNG and other images
// (image_io.cpp decides by extension, then an EXR by its magic number).
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "hfvis/image_io.hpp"

namespace hfvis::detail {

// Ground metres per degree on the WGS84 ellipsoid at geodetic latitude `lat_deg`, along a
// meridian and along a parallel (both readers convert geographic spacing with it).
void metresPerDegree(double lat_deg, double* along_meridian, double* along_parallel);

// The cell sizes in the texts of the hfvis:cell_size_x/y attributes (null: absent) of the file
// `path` (both readers take them from files hfvis wrote): none when both are absent, else both,
// or an IoError when either is not a positive number (a damaged file must not fall back to 1).
std::optional<std::pair<double, double>> storedCellSize(const std::string& path, const char* x,
                                                        const char* y);

// The extension of `path` in lower case, with its dot ("" when it has none).
std::string lowercaseExtension(const std::string& path);

// Whether `path` names a raster format that GDAL reads rather than OpenEXR or OpenImageIO, by its
// extension.
bool isGdalRaster(const std::string& path);
// As isGdalRaster, and a regular file of TIFF bytes whatever its name: a height field (a GeoTIFF
// named .gtif, .cog or nothing keeps its nodata, cells and CRS). Other images (radiance,
// environments, albedo, light images) go by the extension: OpenImageIO reads a TIFF's channels
// by their names, and TIFF containers (.tx textures, camera raws) as the images they hold.
bool isGdalHeightField(const std::string& path);

// `path` and the files GDAL reads with it (a VRT's sources, nested VRTs' too, and what the
// dataset lists: sidecars, world files); `path` alone where it does not open. Throws IoError for
// a VRT source that is not a regular file, or standard input (see filesRead).
std::vector<std::string> gdalFilesRead(const std::string& path);

// Reads band `options.channel` ("" = the only band; an index "0".. or a band description) as
// heights: nodata cells NaN, the georeference from the file, cell sizes from the geotransform
// (geographic degrees in metres per row and at the field's centre latitude; without a geotransform, the
// hfvis_cell_size_x/y metadata items hfvis writes) unless the options give them. Throws IoError
// (unreadable, rotated or sheared geotransform, too large).
HeightField readGdalHeightField(const std::string& path, const HeightFieldReadOptions& options);

// A projected CRS's linear unit (given as WKT): its name and metres per unit; nullopt where the
// WKT is empty, unreadable or not projected (a geographic raster's cell sizes become metres when
// read).
std::optional<std::pair<std::string, double>> projectedLinearUnit(const std::string& wkt);

// Reads every band (see readImage). Throws IoError.
ImageChannels readGdalImage(const std::string& path);

// Throws IoError naming `path` (a raster read beside the height field `input`: an albedo, an exit
// radiance, a view mask, all taken pixel by pixel) when both are georeferenced and lie on other
// grids: other geotransforms (origins more than a thousandth of a pixel apart, pixel sizes more
// than a relative 1e-6; a south-up raster beside a north-up field) or other CRSs (OSRIsSame of
// their horizontal parts: a vertical datum on one side alone is no difference). A
// raster without a georeference, or beside a field without one, is taken by position.
void requireSameGrid(const std::string& path, const Georeference& side, const std::string& input,
                     const Georeference& field);

// Whether this GDAL has the GTiff driver that writeGeoTiff needs.
bool hasGeoTiffWriter();

// Writes `image`, already checked by writeImage, to the new file `file` as a GeoTIFF (see
// writeImage); errors are IoErrors naming `path`, the file the caller is writing for.
void writeGeoTiff(const std::string& file, const std::string& path, const ImageChannels& image);

}  // namespace hfvis::detail
