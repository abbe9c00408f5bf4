// insolation_reference.cpp: see hfvis_testing/insolation_reference.hpp.
#include "hfvis_testing/insolation_reference.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/unit_normals.hpp"
#include "hfvis_testing/horizon_reference.hpp"
#include "ops/insolation_steps.hpp"

namespace hfvis {
namespace {

// disc_above in kernels/insolation.cl, in float. The kernel's acos and sqrt may differ from
// C++'s by an ulp or so (OpenCL allows acos 4 ulp): the tests compare within a tolerance.
float discAbove(float above, float radius) {
  const float t = std::clamp(above / radius, -1.0f, 1.0f);
  return 1.0f - (std::acos(t) - t * std::sqrt(1.0f - t * t)) / static_cast<float>(M_PI);
}

}  // namespace

InsolationResult referenceInsolation(const HeightField& field, const InsolationOptions& options,
                                     const SweepOptions& sweep) {
  validate(field);
  validate(options);
  const float radius = static_cast<float>(detail::sunDiscRadius(options));
  const auto buckets = detail::sunStepsByBucket(options);
  const std::size_t pixels = field.pixelCount();
  const std::vector<float> normals = detail::unitNormals(field);
  InsolationResult out;
  out.width = field.width;
  out.height = field.height;
  out.sun_hours.assign(pixels, 0.0f);
  out.direct.assign(pixels, 0.0f);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (std::size_t p = 0; p < pixels; ++p)
    if (std::isnan(normals[4 * p])) out.sun_hours[p] = out.direct[p] = nan;
  for (const auto& [bucket, steps] : buckets) {
    HorizonOutputs outputs;
    outputs.horizon_angles = true;
    const HorizonResult h = referenceHorizons(field, detail::bucketSweep(bucket, options, sweep), outputs);
    for (std::size_t p = 0; p < pixels; ++p) {
      if (std::isnan(h.angles[p])) {
        out.sun_hours[p] = out.direct[p] = nan;
        continue;
      }
      const float limit = std::max(h.angles[p], 0.0f);  // level ground beyond the field
      const float* n = &normals[4 * p];
      float up = 0.0f, light = 0.0f;
      for (const detail::SunStep& s : steps) {
        const float cosine = n[0] * s.x + n[1] * s.y + n[2] * s.z;
        up += s.elevation > limit ? s.hours : 0.0f;
        light += s.hours * discAbove(s.elevation - limit, radius) * std::max(cosine, 0.0f);
      }
      out.sun_hours[p] += up;
      out.direct[p] += light;
    }
    out.steps += static_cast<int>(steps.size());
    ++out.sweeps;
  }
  return out;
}

}  // namespace hfvis
