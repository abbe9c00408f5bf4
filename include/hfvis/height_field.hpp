// hfvis/height_field.hpp: the height field every operation reads.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace hfvis {

// Where a raster lies on the Earth, as the file it was read from says, so that results written
// as GeoTIFF overlay their input in a GIS. hfvis computes nothing from it (the cell sizes are
// what the operations use); it is carried from the input to the outputs as it was.
struct Georeference {
  // GDAL's geotransform of the pixel corners: ground x = t[0] + col * t[1] + row * t[2],
  // y = t[3] + col * t[4] + row * t[5] (north-up: t[2] = t[4] = 0, t[5] < 0). None when the
  // file had none.
  std::optional<std::array<double, 6>> geotransform;
  // The coordinate reference system as WKT; empty when the file had none.
  std::string crs_wkt;

  bool empty() const { return !geotransform && crs_wkt.empty(); }
};

// Where a field lies within a larger one it was cut from: a tile or a chunk computed apart, with
// a halo around the part whose results are kept (hfvis's Python package does so for Dask
// arrays). The horizon sweep then places every line's positions as along the larger field's
// lines and takes the larger field's base (heightBase) as the heights' base, so that a pixel's
// horizon, sky-view factor, occlusion and sun are the larger field's bit for bit wherever its
// maximum distance (and the bilinear cell and normal beyond it) lies inside this field: a
// pixel's samples and the cut at the maximum distance fall where they fall in the larger field.
// With per-row spacing (a latitude / longitude grid) positions are whole units of ground length
// (of the larger field's size and largest cell size) summed along the larger field's lines, so
// the origin carries the larger field's per-row cell sizes too. The hull tree
// (intervisibility, the horizon lists) is exact either way; it takes the base and the unit too.
struct FieldOrigin {
  int col = 0, row = 0;                  // this field's pixel (0, 0) in the larger field
  int whole_width = 0, whole_height = 0;  // the larger field's size; 0 x 0: no larger field
  double base = 0.0;                      // the larger field's heightBase() (before z_scale)
  // With per-row spacing: the larger field's per-row cell sizes (whole_height each), whose rows
  // [row, row + height) are this field's; empty without per-row spacing.
  std::vector<double> row_cell_size_x, row_cell_size_y;

  bool present() const { return whole_width > 0 || whole_height > 0; }
};

// A W x H grid of heights, row-major, row 0 first as stored in the image.
// Pixel (col, row) sits at ground position (col * cell_size_x, row * cell_size_y);
// between grid points the surface is the bilinear interpolation of the four corners.
//
// Nodata policy: every non-finite height (NaN, +inf, -inf) is nodata. A nodata point
// neither casts nor receives: outputs at nodata receivers are NaN. A cell with a nodata corner
// has no surface inside, an edge with a nodata end none along it (a valid grid point, and an
// edge between two, are surface): a sample there is absent, so a hole never turns a valid
// neighbour's result into NaN.
struct HeightField {
  int width = 0;
  int height = 0;
  std::vector<float> heights;  // width * height values
  double cell_size_x = 1.0;    // ground units per pixel along columns
  double cell_size_y = 1.0;    // ground units per pixel along rows
  // Per-row spacing (latitude / longitude grids, whose east-west spacing shrinks with
  // latitude): empty, or one entry per row, row r's cell sizes; cell_size_x/y are then those
  // at the centre latitude. The horizon operation (horizon angles and distances, sky-view
  // factor, occlusion) measures ground lengths along its lines and rays step by step with
  // them, and takes each row's normals, step directions and quadrature weights from them;
  // so do intervisibility and the horizon lists (their positions along lines and rays in
  // whole units of ground length); the bounce takes cell_size_x/y for the whole field.
  std::vector<double> row_cell_size_x, row_cell_size_y;
  double z_scale = 1.0;        // multiplies every height
  FieldOrigin origin;          // where it lies in a larger field it was cut from; none by default
  Georeference georeference;   // from a georeferenced raster; empty for a field filled in memory

  float at(int col, int row) const { return heights[static_cast<std::size_t>(row) * width + col]; }
  std::size_t pixelCount() const { return static_cast<std::size_t>(width) * height; }
  std::size_t nodataCount() const;
};

// The cell sizes (ground units per pixel) the kernels' single precision holds: 1e300 gave a
// sky-view factor of 1 everywhere and 1e-30 a visible area of 0, without a word.
constexpr double kLeastCellSize = 1e-6, kMostCellSize = 1e9;

// The largest magnitude of a height an operation takes besides the field's (a region's samples,
// a PVS view band), as the command line's options: beyond float's range (1e39) it became
// infinite in the kernels and a light at 1e300 was seen from everywhere, without a word.
constexpr double kMostGivenHeight = 1e12;

// Whether every cell size of the field (per-row ones included) lies in kLeastCellSize ..
// kMostCellSize.
bool cellSizesHeld(const HeightField& field);

// Heights held in float32, in which hfvis computes, keep their differences unless float32 rounded
// them (`rounding`, the largest rounding of one height) by more than a thousandth of their range
// (lowest .. highest) and a hundredth of the smaller cell size (a slope error of 1 % across a
// cell): UInt32 heights near 4e9 round by up to 256, and walls of 50 came out flat. Throws
// InvalidArgument naming the heights otherwise. The file readers and the Python package ask it of
// heights of any wider type (a float64 DSM of a flat roof at 4000 on cells of 0.1, rounded by
// 2.4e-4 as a float32 one is, passes).
void requireHeightsKeptInFloat32(double rounding, double lowest, double highest, double cell_size);

// The height the sweeps count a field's heights from on the device (before z_scale): the median
// of the finite heights at up to 64 x 64 pixels spread evenly over it (rows (2 i + 1) H / (2 n),
// i < n = min(H, 64), and columns likewise, in integers; the lower of the two middle ones), or
// the lowest finite height
// where none of those is finite. Float32 holds a height counted from it to the spacing at its
// distance from it: counted from the lowest, one height far below the rest (an undeclared void of
// -32768 or -1e6) held every other to steps of 1/16 near 8848 and horizons came out degrees off.
// A field cut from a larger one takes the larger one's (FieldOrigin::base).
double heightBase(const HeightField& field);

// Throws InvalidArgument when the field is empty, its sizes disagree, a cell size (per-row
// ones included, one per row) is not finite or outside kLeastCellSize .. kMostCellSize, the
// z-scale is not finite and positive, every height is
// nodata, or an origin does not place it inside its larger field or gives a base that is not
// finite.
void validate(const HeightField& field);

}  // namespace hfvis
