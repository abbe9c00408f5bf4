// sweep_geometry.hpp: the host side of the sweep framework that every operation and the
// scalar references share without OpenCL: the heights as the kernels see them, the ray
// geometry of one direction (mirrors `SweepDirection` in kernels/shared/sweep_framework.cl) and the
// scalar mirrors of the kernels' sampling helpers, so both sample the very same points.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "hfvis/height_field.hpp"
#include "hfvis/sweep_options.hpp"

namespace hfvis::detail {

// Sixteen 4-byte members, no padding: uploaded as is (see kernels/shared/sweep_framework.cl).
struct SweepDirection {
  float dir_x, dir_y;    // unit line direction in pixel axes (x = column, y = row)
  float perp_x, perp_y;  // (-dir_y, dir_x)
  float line_spacing;    // pixels between lines
  float lines_per_unit;
  float step_length;  // pixels between samples along a line
  float samples_per_unit;
  float ground_per_pixel;  // ground length of one pixel length along dir
  float cos_azimuth, sin_azimuth;
  std::int32_t line_first;  // line j at offset (line_first + j) * line_spacing along perp
  std::int32_t n_lines;
  std::int32_t step_top;  // step i at (step_top - i) * step_length along dir
  std::int32_t n_steps;
  std::uint32_t buffer_offset;  // unused by the naive marches (kept: the kernel struct's layout)

  std::size_t entries() const {
    return static_cast<std::size_t>(n_lines) * static_cast<std::size_t>(n_steps);
  }
};
static_assert(sizeof(SweepDirection) == 64, "SweepDirection must match the kernel struct");

// The ray geometry at ground azimuth `azimuth` (radians) over `field` for the naive marches
// (direction, step, ground length, cos/sin); the line fields are what a sweep with one line
// per pixel length would have, which only the host's canonical line views use.
SweepDirection makeSweepDirection(const HeightField& field, double azimuth, double samples_per_unit);

// The sweep geometry of every direction of a run (buffer offsets left at 0).
std::vector<SweepDirection> runDirections(const HeightField& field, const SweepOptions& options);

// Checks an operation's rows per strip: 0 (automatic) or positive, and 0 for a naive method, whose
// rays read the whole field.
void validateStripRows(int strip_rows, bool naive);
// Throws InvalidArgument unless the curvature coefficient is finite and within -1 .. 1 per ground
// unit (every operation's rule); `what` names it in the message.
void validateCurvature(double curvature, const std::string& what);

// A point in pixel axes.
struct Point2 {
  float x, y;
};

// Mirrors of the kernels' helpers (same operations, same order, same rounding).
bool insideField(Point2 p, int width, int height);

// The bilinear surface from its corners' weights (w00 = 1 - the others) as h00 plus the weighted
// differences from it, exact where the corners are equal (kernels/shared/sweep_framework.cl,
// corner_bilinear, says why).
inline float cornerBilinear(float h00, float h10, float h01, float h11, float w10, float w01, float w11) {
  return h00 + (w10 * (h10 - h00) + w01 * (h01 - h00) + w11 * (h11 - h00));
}

// A sample beside nodata: NaN where a corner of positive weight is NaN (no surface inside a cell
// with a nodata corner, none along an edge with a nodata end), else the bilinear value over the
// corners of positive weight, from the first of them (bilinear_beside_nodata).
inline float bilinearBesideNodata(float h00, float h10, float h01, float h11, float w00, float w10, float w01,
                                  float w11) {
  const bool v00 = w00 > 0.0f && h00 == h00, v10 = w10 > 0.0f && h10 == h10;
  const bool v01 = w01 > 0.0f && h01 == h01, v11 = w11 > 0.0f && h11 == h11;
  if ((w00 > 0.0f && !v00) || (w10 > 0.0f && !v10) || (w01 > 0.0f && !v01) || (w11 > 0.0f && !v11))
    return std::numeric_limits<float>::quiet_NaN();
  const float base = v00 ? h00 : (v10 ? h10 : (v01 ? h01 : h11));
  const float sum = (v00 ? w00 * (h00 - base) : 0.0f) + (v10 ? w10 * (h10 - base) : 0.0f) +
                    (v01 ? w01 * (h01 - base) : 0.0f) + (v11 ? w11 * (h11 - base) : 0.0f);
  const float weight = (v00 ? w00 : 0.0f) + (v10 ? w10 : 0.0f) + (v01 ? w01 : 0.0f) + (v11 ? w11 : 0.0f);
  return weight > 0.0f ? base + sum / weight : std::numeric_limits<float>::quiet_NaN();
}

float sampleHeight(const std::vector<float>& heights, int width, int height, Point2 p);
// sampleHeight at (c + ox, r + oy), the fractions in its cell taken from the offsets, exact where
// |ox| >= 2 (the absolute position's rounding times a steep slope passed the tie rule's; the
// kernels' sample_height_from): the naive visible count's samples.
float sampleHeightFrom(const std::vector<float>& heights, int width, int height, int c, int r, float ox,
                       float oy);

// Heights as the kernels see them: (h - heightBase(field)) * z_scale in float, so that a plane
// at 8848 m keeps its millimetres, a pixel far below the rest or not (a field with an origin
// takes its larger field's base; prepared heights may be negative); every non-finite height
// becomes NaN. Throws InvalidArgument when a prepared height
// would exceed kMaxPreparedHeight: the kernels multiply height differences by distances (up to
// 2^31 pixels) and square them (the sky-view factor's and occlusion's terms) in float, which
// must stay finite (a cliff of 2e19 gave a sky-view factor of 1 at its foot, exit 0, when the
// bound was 1e28). HeightOrigin::Zero keeps the heights where
// they are (h * z_scale): the viewshed, region visibility and the ray caster, whose observers,
// sources and targets may stand at absolute heights; it throws when a height itself would
// exceed kMaxPreparedHeight, or lies so far from 0 that float32's spacing there passes a tenth
// of a cell.
constexpr double kMaxPreparedHeight = 1e18;
struct PreparedHeights {
  std::vector<float> heights;
  bool has_nodata = false;
  // The least and the greatest of `heights` that are not NaN (+INFINITY and -INFINITY where all
  // are), as prepareHeights sets them (a routine preparing heights of its own, as the bounce's,
  // leaves them so: only the region operation reads them, from prepareHeights).
  float lowest = std::numeric_limits<float>::infinity(), highest = -std::numeric_limits<float>::infinity();
  // The z-scaled height that `heights` hold as 0 (the shift: heightBase, or the base of the
  // field this one was cut from; 0 from HeightOrigin::Zero). The visibility tie rule
  // forgives the rounding of heights at their absolute value, prepared height + base.
  float base = 0.0f;
};
enum class HeightOrigin { Base, Zero };
// `bands`: the bands of rows it runs in (core/host_bands.hpp); 0, bandsFor's (tests give others:
// the result is the same for any).
PreparedHeights prepareHeights(const HeightField& field, HeightOrigin origin = HeightOrigin::Base,
                               int bands = 0);

// The kernels index pixels with 32-bit arithmetic: signed within a plane, unsigned across the
// `planes` planes of one buffer. Throws InvalidArgument for fields beyond that.
void checkPixelIndexing(const HeightField& field, int planes);

// Sample pitch at which positions count as inside; must equal HFVIS_EDGE_EPS.
constexpr float kEdgeEpsilon = 1e-3f;

// No maximum distance: more steps than any line or ray has.
constexpr int kAllSteps = 1 << 30;

// Steps of `step_ground` ground units within `max_distance` (0: kAllSteps): the steps a
// march or a uniformly sampled line takes within a maximum distance.
int stepsWithin(double max_distance, double step_ground);


}  // namespace hfvis::detail
