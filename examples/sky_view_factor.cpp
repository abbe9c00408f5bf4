// sky_view_factor: the sky-view factor of a height field through the installed hfvis
// library. With a file argument it reads the field and prints the mean sky-view factor; without
// one it checks the library on a plane tilted by 30 degrees, whose sky-view factor is known in
// closed form, and fails when the result is off.
//
// On a plane of slope angle alpha the horizon in azimuth phi from the fall line is
// atan(tan(alpha) cos(phi)) uphill and absent downhill, so with hfvis's sky-view factor,
// 1 - (1 / 2 pi) * integral of sin(max(0, elevation)) over the circle, an interior point gets
// 1 - alpha / pi.
#include <cmath>
#include <cstdio>
#include <exception>
#include <vector>

// [readme]
#include "hfvis/hfvis.hpp"

// The sky-view factor of every pixel (NaN at nodata). One context serves many calls: it
// keeps the compiled kernels and the scratch buffers.
std::vector<float> skyViewFactor(const hfvis::ComputeContext& context, const hfvis::HeightField& field) {
  hfvis::HorizonOptions options;  // 64 directions, 1 sample per pixel length, ...
  return hfvis::computeSkyViewFactor(context, field, options).values;
}
// [/readme]

namespace {

hfvis::HeightField tiltedPlane(int size, double slope_degrees) {
  hfvis::HeightField field;
  field.width = field.height = size;
  field.heights.resize(field.pixelCount());
  const double rise = std::tan(slope_degrees * M_PI / 180.0);  // per ground unit along the columns
  for (int row = 0; row < size; ++row)
    for (int col = 0; col < size; ++col) field.heights[row * size + col] = static_cast<float>(rise * col);
  return field;
}

}  // namespace

int main(int argc, char** argv) try {
  std::printf("hfvis %s\n", hfvis::versionString());
  const hfvis::ComputeContext context = hfvis::ComputeContext::create();  // a GPU if there is one, else a CPU
  if (argc > 1) {
    const hfvis::HeightField field = hfvis::readHeightField(argv[1]);
    const std::vector<float> svf = skyViewFactor(context, field);
    double sum = 0.0;
    std::size_t count = 0;
    for (float v : svf)
      if (std::isfinite(v)) sum += v, ++count;
    std::printf("%s: %d x %d on %s, mean sky-view factor %.4f\n", argv[1], field.width, field.height,
                context.device().name.c_str(), count ? sum / count : 0.0);
    return 0;
  }
  const double slope = 30.0;
  const hfvis::HeightField field = tiltedPlane(128, slope);
  const float centre = skyViewFactor(context, field)[(field.height / 2) * field.width + field.width / 2];
  const double expected = 1.0 - slope / 180.0;  // 1 - alpha / pi
  const bool ok = std::fabs(centre - expected) < 2e-3;
  std::printf("plane tilted by %.0f deg, centre pixel on %s: sky-view factor %.5f, closed form %.5f: %s\n",
              slope, context.device().name.c_str(), centre, expected, ok ? "ok" : "WRONG");
  return ok ? 0 : 1;
} catch (const std::exception& error) {
  std::fprintf(stderr, "sky_view_factor: %s\n", error.what());
  return 1;
}
