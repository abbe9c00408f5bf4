// horizon_reference.cpp: scalar mirrors of kernels/horizon.cl (presample, hull-stack
// sweep, reduction, naive march). Keep every expression in the kernels' order: the
// build disables FP contraction on both sides so the predicates decide identically.
#include <algorithm>
#include <cmath>
#include <limits>

#include "fast_math.hpp"
#include "hfvis/reference.hpp"
#include "horizon_common.hpp"
#include "reference_internal.hpp"

namespace hfvis {
namespace detail {
namespace {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kNearMargin = 4e-6f;  // HFVIS_NEAR_MARGIN

struct Normal {
  float x = 0.0f, y = 0.0f, z = 1.0f;
};

Normal surfaceNormal(const std::vector<float>& h, int width, int height, int c, int r, float hp, float cell_x,
                     float cell_y) {
  float nx = 0.0f, ny = 0.0f, nz = 0.0f;
  for (int sy = -1; sy <= 1; sy += 2) {
    for (int sx = -1; sx <= 1; sx += 2) {
      const int cx = c + sx, ry = r + sy;
      if (cx < 0 || cx >= width || ry < 0 || ry >= height) continue;
      const float hx = h[r * width + cx], hy = h[ry * width + c];
      if (std::isnan(hx) || std::isnan(hy)) continue;
      const float gx = (hx - hp) / (static_cast<float>(sx) * cell_x);
      const float gy = (hy - hp) / (static_cast<float>(sy) * cell_y);
      nx += -gx, ny += -gy, nz += 1.0f;
    }
  }
  if (!(nz > 0.0f)) return {};
  const float len = std::sqrt(nx * nx + ny * ny + nz * nz);
  return {nx / len, ny / len, nz / len};
}

// Every pixel's normal, as the kernels compute it (only needed for ambient occlusion).
std::vector<Normal> pixelNormals(const HeightField& field, const std::vector<float>& h, bool wanted) {
  std::vector<Normal> normals(field.pixelCount());
  if (!wanted) return normals;
  const auto cell_x = static_cast<float>(field.cell_size_x), cell_y = static_cast<float>(field.cell_size_y);
  for (int r = 0; r < field.height; ++r) {
    for (int c = 0; c < field.width; ++c) {
      const std::size_t pixel = static_cast<std::size_t>(r) * field.width + c;
      if (!std::isnan(h[pixel]))
        normals[pixel] = surfaceNormal(h, field.width, field.height, c, r, h[pixel], cell_x, cell_y);
    }
  }
  return normals;
}

float ambientTerm(float elevation, Normal n, float cos_az, float sin_az, int directions) {
  const float toward = n.x * cos_az + n.y * sin_az;
  float zenith = 0.5f * kPi - elevation;
  zenith = std::fmin(zenith, 0.5f * kPi + hfAtan(toward / n.z));
  const float s = hfSin(zenith);
  return n.z / static_cast<float>(directions) * s * s +
         hfSin(kPi / static_cast<float>(directions)) / kPi * (zenith - 0.5f * hfSin(2.0f * zenith)) * toward;
}

// Per-pixel sinks, as emit_direction / accumulate_pixel in the kernel.
struct PixelSums {
  float svf = 0.0f, ao = 0.0f;
};

void emitDirection(HorizonResult& result, int k, std::size_t pixel, float elevation, float distance, Normal n,
                   const SweepDirection& d, int directions, PixelSums& sums) {
  const std::size_t plane = static_cast<std::size_t>(result.width) * result.height;
  if (!result.angles.empty()) result.angles[k * plane + pixel] = elevation;
  if (!result.distances.empty()) result.distances[k * plane + pixel] = distance;
  sums.svf += hfSin(std::fmax(0.0f, elevation));
  sums.ao += ambientTerm(elevation, n, d.cos_azimuth, d.sin_azimuth, directions);
}

void accumulatePixel(HorizonResult& result, std::size_t pixel, bool nodata, const PixelSums& sums) {
  if (!result.sky_view_factor.empty())
    result.sky_view_factor[pixel] = nodata ? kNaN : result.sky_view_factor[pixel] + sums.svf;
  if (!result.ambient_occlusion.empty())
    result.ambient_occlusion[pixel] = nodata ? kNaN : result.ambient_occlusion[pixel] + sums.ao;
}

void sweepReference(const HeightField& field, const PreparedHeights& prepared, const HorizonOptions& options,
                    const HorizonOutputs& outputs, HorizonResult& result) {
  const int width = field.width, height = field.height;
  const auto& h = prepared.heights;
  const auto normals = pixelNormals(field, h, outputs.ambient_occlusion);
  const auto directions = runDirections(field, options);
  // Directions one at a time; the kernels sum per batch first, so the sums may differ from
  // the kernels' in the last bits.
  std::vector<PixelSums> sums(field.pixelCount());
  for (int k = 0; k < options.directions; ++k) {
    const SweepDirection& d = directions[k];
    const LineOccluders lines = referenceSweepLines(field, h, d);
    for (int r = 0; r < height; ++r) {
      for (int c = 0; c < width; ++c) {
        const std::size_t pixel = static_cast<std::size_t>(r) * width + c;
        const float hp = h[pixel];
        const float x = static_cast<float>(c), y = static_cast<float>(r);
        float weight = 0.0f, angle_sum = 0.0f, distance_sum = 0.0f;
        for (const CellCorner& corner : receiverCell(d, c, r)) {
          const float w = corner.weight;
          const int i = corner.step;
          const std::size_t e = corner.entry;
          if (w <= 0.0f) continue;
          const float rise = lines.rises[e], occ_step = lines.steps[e];
          if (occ_step < 0.0f) continue;
          const float ground = (static_cast<float>(i) - occ_step) * d.step_length * d.ground_per_pixel;
          weight += w;
          angle_sum += w * hfAtan2Ahead(rise, ground);
          distance_sum += w * ground;
        }
        // The exact near field of the receiver's own ray, as in horizon_reduce.
        float near_slope = 0.0f, near_t = 0.0f;
        bool near_found = false, ray_has_sample = false;
        for (int q = 1; q <= options.near_field_samples; ++q) {
          const float t =
              static_cast<float>(q) * (d.step_length / static_cast<float>(options.near_field_samples));
          const Point2 at{x + t * d.dir_x, y + t * d.dir_y};
          const bool inside = insideField(at, width, height);
          const float slope = (sampleHeight(h, width, height, at) - hp) / t;
          if (inside && !std::isnan(slope) && (!near_found || slope >= near_slope)) {
            near_slope = slope, near_t = t, near_found = true;
          }
          if (q == 1) ray_has_sample = inside;
        }
        const float near_elevation = hfAtan(near_slope / d.ground_per_pixel);
        float elevation = weight > 0.0f ? angle_sum / weight : -0.5f * kPi;
        float distance = weight > 0.0f ? distance_sum / weight : 0.0f;
        if (near_found && (!(weight > 0.0f) || near_elevation > elevation + kNearMargin)) {
          elevation = near_elevation, distance = near_t * d.ground_per_pixel;
        }
        if (!ray_has_sample) elevation = -0.5f * kPi, distance = 0.0f;
        if (std::isnan(hp)) elevation = distance = kNaN;
        PixelSums one;
        emitDirection(result, k, pixel, elevation, distance, normals[pixel], d, options.directions, one);
        sums[pixel].svf += one.svf;
        sums[pixel].ao += one.ao;
      }
    }
  }
  for (std::size_t p = 0; p < sums.size(); ++p) accumulatePixel(result, p, std::isnan(h[p]), sums[p]);
}

void naiveReference(const HeightField& field, const PreparedHeights& prepared, const HorizonOptions& options,
                    const HorizonOutputs& outputs, HorizonResult& result) {
  const int width = field.width, height = field.height;
  const auto& h = prepared.heights;
  const auto normals = pixelNormals(field, h, outputs.ambient_occlusion);
  const auto directions = runDirections(field, options);
  for (int r = 0; r < height; ++r) {
    for (int c = 0; c < width; ++c) {
      const std::size_t pixel = static_cast<std::size_t>(r) * width + c;
      const float hp = h[pixel];
      PixelSums sums;
      for (int k = 0; k < options.directions; ++k) {
        const SweepDirection& d = directions[k];
        float best_rise = 0.0f;
        int best_step = 0;
        // March until the ray has left the field for good (the kernel's trip count may be
        // longer; the extra samples are outside and masked).
        for (int i = 1;; ++i) {
          const float t = static_cast<float>(i) * d.step_length;
          const Point2 p{static_cast<float>(c) + t * d.dir_x, static_cast<float>(r) + t * d.dir_y};
          if (!insideField(p, width, height)) break;
          const float q = sampleHeight(h, width, height, p);
          const float rise = q - hp;
          if (!std::isnan(q) &&
              (best_step == 0 || rise * static_cast<float>(best_step) >= best_rise * static_cast<float>(i))) {
            best_rise = rise;
            best_step = i;
          }
        }
        const float ground = static_cast<float>(best_step) * d.step_length * d.ground_per_pixel;
        float elevation = best_step > 0 ? hfAtan2Ahead(best_rise, ground) : -0.5f * kPi;
        float distance = best_step > 0 ? ground : 0.0f;
        if (std::isnan(hp)) elevation = distance = kNaN;
        emitDirection(result, k, pixel, elevation, distance, normals[pixel], d, options.directions, sums);
      }
      accumulatePixel(result, pixel, std::isnan(hp), sums);
    }
  }
}

}  // namespace

LineOccluders referenceSweepLines(const HeightField& field, const std::vector<float>& prepared_heights,
                                  const SweepDirection& d) {
  LineOccluders out;
  const std::size_t entries = d.entries();
  out.samples.assign(entries, kNaN);
  out.rises.assign(entries, kNaN);
  out.steps.assign(entries, -1.0f);
  for (int j = 0; j < d.n_lines; ++j) {
    for (int i = 0; i < d.n_steps; ++i) {
      const Point2 p = sweepPosition(d, j, i);
      if (insideField(p, field.width, field.height))
        out.samples[static_cast<std::size_t>(i) * d.n_lines + j] =
            sampleHeight(prepared_heights, field.width, field.height, p);
    }
  }
  // Algorithm 1 of Timonen & Westerholm 2010 per line, as horizon_sweep.
  std::vector<std::pair<float, float>> stack;
  for (int j = 0; j < d.n_lines; ++j) {
    stack.clear();
    for (int i = 0; i < d.n_steps; ++i) {
      const std::size_t e = static_cast<std::size_t>(i) * d.n_lines + j;
      const float h = out.samples[e];
      if (std::isnan(h)) continue;
      const float here = static_cast<float>(i);
      if (!stack.empty()) {
        auto top = stack.back();
        float v1h = top.first - h, v1d = here - top.second;
        while (stack.size() > 1) {
          const auto below = stack[stack.size() - 2];
          const float v2h = below.first - h, v2d = here - below.second;
          if (v2h * v1d >= v1h * v2d) {
            top = below, v1h = v2h, v1d = v2d;
            stack.pop_back();
          } else {
            break;
          }
        }
        out.rises[e] = top.first - h;
        out.steps[e] = top.second;
      }
      stack.emplace_back(h, here);
    }
  }
  return out;
}

}  // namespace detail

HorizonResult referenceHorizons(const HeightField& field, const HorizonOptions& options,
                                const HorizonOutputs& outputs) {
  validate(field);
  validate(options, outputs);
  const detail::PreparedHeights prepared = detail::prepareHeights(field);
  HorizonResult result = detail::allocateResult(field, options, outputs);
  if (options.method == HorizonMethod::Sweep) {
    detail::sweepReference(field, prepared, options, outputs, result);
  } else {
    detail::naiveReference(field, prepared, options, outputs, result);
  }
  detail::finishReduction(options, result);
  return result;
}

}  // namespace hfvis
