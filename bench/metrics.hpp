// bench/metrics.hpp: what the benchmark measures besides the methods themselves: repeated
// timings, horizon / sky-view / ambient-occlusion errors against the ground truth, the
// host formulas of SVF and AO (the library's, in double), and the hull stack's statistics.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "ground_truth.hpp"
#include "hfvis/height_field.hpp"

namespace hfvis::bench {

// How often to repeat a timed run: at least min_reps, then until budget_seconds of timed
// runs have passed or max_reps are done.
struct TimingPolicy {
  int min_reps = 3;
  int max_reps = 7;
  double budget_seconds = 4.0;
};

struct Timing {
  std::vector<double> seconds;      // wall clock of every timed run, in order
  std::vector<double> cpu_seconds;  // CPU time of this process (all threads) in each run
  double min() const;
  double median() const;
  double cpuMin() const;
};

// Times `run` under `policy`: wall clock (steady_clock) and process CPU time (getrusage),
// which stays close to the work done when other processes share the cores. Warm-up is the
// caller's business.
Timing timeRepeated(const std::function<void()>& run, const TimingPolicy& policy);

// The process's CPU time so far (every thread's, user and system), in seconds: on a shared machine
// a call's CPU time moves less with the load than its wall time.
double processCpuSeconds();

// The library's formulas (kernels/horizon.cl surface_normal, ambient_term; svf = 1 - mean
// sin(max(0, elevation))), in double, for one receiver from its K elevation angles, each
// direction weighted 1/K (the library's weights when it computes the K angle planes).
// ambientOcclusion's directions are at `azimuths` (radians; the library's
// HorizonResult::azimuths), or at 2 pi k / K when none are given.
struct Normal {
  double x = 0.0, y = 0.0, z = 1.0;
};
Normal surfaceNormal(const HeightField& field, int col, int row);
double skyViewFactor(const std::vector<double>& elevations);
double ambientOcclusion(const std::vector<double>& elevations, const Normal& normal,
                        const std::vector<double>& azimuths = {});

// Errors of a method's horizons (K planes of width * height, radians) against the ground
// truth on its receivers, in the truth's directions k * truth.directions / K (K must divide
// it). Angles in degrees; SVF and AO of both computed by the formulas above.
struct ErrorStats {
  std::size_t samples = 0;  // receiver-direction pairs
  std::size_t nan_samples = 0;
  double mean_deg = 0.0, p99_deg = 0.0, max_deg = 0.0, bias_deg = 0.0;
  // The same over receivers at least two pixels from every edge of the field.
  std::size_t interior_samples = 0;
  double interior_mean_deg = 0.0, interior_p99_deg = 0.0, interior_max_deg = 0.0;
  double svf_mean = 0.0, svf_max = 0.0, ao_mean = 0.0, ao_max = 0.0;
};
ErrorStats horizonErrors(const HeightField& field, const GroundTruth& truth, const std::vector<float>& angles,
                         int directions);

// Difference between two methods' horizons on the truth's receivers (the same stats, with
// `reference` in place of the truth): isolates what separates two methods.
ErrorStats horizonDifference(const HeightField& field, const GroundTruth& truth,
                             const std::vector<float>& angles, const std::vector<float>& reference,
                             int directions);

// Error of a sky-view factor plane (width * height, e.g. an SVF-only run's output) on the
// truth's receivers against the SVF of the exact horizons in K directions 2 pi k / K (K must
// divide the truth's directions): 1 - (1/K) sum_k sin(max(0, exact_k)). The SVF is
// compared as it is, whatever directions and weights the method integrated over.
struct SvfErrorStats {
  std::size_t receivers = 0, nan_receivers = 0;
  double mean_abs = 0.0, max_abs = 0.0, bias = 0.0;  // bias: mean of method - truth
};
SvfErrorStats svfErrors(const HeightField& field, const GroundTruth& truth, const std::vector<float>& svf,
                        int directions);

// Mean and largest absolute difference of two planes (NaN pairs skipped).
struct PlaneDifference {
  double mean_abs = 0.0, max_abs = 0.0;
};
PlaneDifference planeDifference(const std::vector<float>& a, const std::vector<float>& b);

// The hull stack of Algorithm 1 (Timonen & Westerholm 2010) run on the host over every line
// of the library's lattice sweep (src/core/lattice_geometry.hpp) in `directions` directions as an
// SVF / AO run takes them (quadrature directions), one sample per unit (the default),
// counting what the kernel horizon_lattice does per sample: the samples of each line's
// periods farthest first, then the receiver.
struct StackStats {
  std::size_t samples = 0;    // samples pushed, receivers included
  std::size_t receivers = 0;  // receiver-direction pairs (pixels x directions)
  double pops_per_sample = 0.0;
  double mean_depth = 0.0;  // stack size each sample is tested against
  int max_depth = 0;
};
StackStats hullStackStatistics(const HeightField& field, int directions);

}  // namespace hfvis::bench
