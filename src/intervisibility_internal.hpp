// intervisibility_internal.hpp: what the intervisibility device path, its scalar reference,
// the horizon lists, the bounce and the tests share: direction geometry and the line-level
// view of one direction's sweep (per-sample counts, horizons, iterations and the bounce
// gather), to compare a sweep line by line.
#pragma once

#include <cstdint>
#include <vector>

#include "hfvis/device.hpp"
#include "hfvis/height_field.hpp"
#include "hfvis/intervisibility.hpp"
#include "sweep_geometry.hpp"

namespace hfvis::detail {

// 2*pi/K: the azimuthal sector one direction stands for in the area estimate.
float intervisibilitySector(const IntervisibilityOptions& options);

// Limits of the kernels' integer and exact arithmetic, checked before launching: a line
// has fewer than 2^24 steps (steps are exact floats), distance sums stay below 2^32 when
// the area is asked for, and |height| * steps stays far below FLT_MAX (the predicate's
// products). Throws InvalidArgument saying what to change.
void checkLineLimits(const std::vector<SweepDirection>& directions,
                     const std::vector<float>& prepared_heights, const IntervisibilityOutputs& outputs);

// One direction's per-sample results in step-major order whatever the device's line
// layout: entry (step i, line j) at i * geometry.n_lines + j. Absent samples: NaN sample,
// NaN count and distance sum, zero statistics and hash.
struct IntervisibilityLines {
  SweepDirection geometry{};
  std::vector<float> samples;                 // presampled heights
  std::vector<float> counts;                  // visible samples (farther along the line)
  std::vector<float> distance_sums;           // sum of their distances, in steps
  std::vector<std::uint32_t> horizons;        // m_i: distinct visibility horizons
  std::vector<std::uint32_t> iterations;      // t_i: convexity checks made (by the tuning)
  std::vector<std::uint32_t> horizon_hashes;  // FNV-1a over the horizons' steps, farthest first
  std::vector<std::uint32_t> walks_skipped;   // 1 where the safe zone skipped the walk
  // Reference only, when asked: the horizons' steps, farthest first, and where each one's
  // visible run ends (run_end(): the first hidden sample, the next horizon or the receiver),
  // so horizon h's visible samples are the present ones of steps [h, end).
  std::vector<std::vector<int>> horizon_steps;
  std::vector<std::vector<int>> horizon_run_ends;
};

// The bounce gather on one direction's lines (see hfvis/bounce.hpp for the formula), in the
// canonical step-major order of IntervisibilityLines. Inputs per entry: the exit radiance
// channels, then the receiver's unit normal (x, y, z), kBounceNormalFloats after them.
struct BounceLines {
  int channels = 1;
  float half_sector = 0.0f;       // D / 2, D = 2*pi/K: the wedge a direction stands for
  float wedge = 0.0f;             // 2 sin(D / 2): the wedge integral of cos(phi - phi_k)
  std::vector<float> attributes;  // (channels + 3) floats per entry
  std::vector<float> irradiance;  // output: channels floats per entry; NaN where absent
};
constexpr int kBounceNormalFloats = 3;

// The D / 2 and 2 sin(D / 2) of a run of K directions, as the host passes them to the kernels.
void bounceWedge(int directions, float* half_sector, float* wedge);

// Runs the reference hull-tree sweep over lines whose `geometry` (n_lines, n_steps, and
// the step's ground length) and `samples` are set: fills every other per-entry vector;
// keep_horizons fills horizon_steps and horizon_run_ends; `bounce`, when given, gathers.
void sweepPresampledLines(IntervisibilityLines& lines, const HullTreeTuning& tuning, bool keep_horizons,
                          BounceLines* bounce = nullptr);

// FNV-1a step of the horizon hash (kernel: `hash = (hash ^ step) * 16777619u`).
constexpr std::uint32_t kHorizonHashSeed = 2166136261u;
inline std::uint32_t hashHorizon(std::uint32_t hash, int step) {
  return (hash ^ static_cast<std::uint32_t>(step)) * 16777619u;
}

// Presampling and the hull-tree sweep kernels for one direction on prepared heights (see
// prepareHeights), with per-entry statistics.
IntervisibilityLines intervisibilityLinesOnDevice(const ComputeContext& context, const HeightField& field,
                                                  const std::vector<float>& prepared_heights,
                                                  const SweepDirection& direction,
                                                  const HullTreeTuning& tuning = {});

// The scalar mirror of the same; keep_horizons fills horizon_steps.
IntervisibilityLines referenceIntervisibilityLines(const HeightField& field,
                                                   const std::vector<float>& prepared_heights,
                                                   const SweepDirection& direction,
                                                   const HullTreeTuning& tuning = {},
                                                   bool keep_horizons = false);

}  // namespace hfvis::detail
