// horizon.cpp: the horizon operation on the device. Per direction, one launch of the
// lattice sweep (receiver-exact hull stacks, reduced straight into the requested outputs)
// or of the naive march; per batch of directions, the requested planes are downloaded.
#include "hfvis/horizon.hpp"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <numeric>
#include <sstream>

#include "core/environment_swaths.hpp"
#include "core/fast_math.hpp"
#include "core/horizon_angle_error.hpp"
#include "core/horizon_common.hpp"
#include "core/lattice_geometry.hpp"
#include "core/opencl_context.hpp"
#include "core/sweep_framework.hpp"
#include "core/sweep_routine.hpp"
#include "hfvis/errors.hpp"

namespace hfvis {
namespace detail {
namespace {

constexpr std::size_t kStackEntryBytes = 2 * sizeof(float);  // (height, position)

std::string programOptions(const HorizonOutputs& outputs, bool has_nodata, int lanes, bool curvature,
                           bool max_distance, bool row_spacing) {
  std::ostringstream s;
  s << "-DHFVIS_LANES=" << lanes << " -DHFVIS_HAS_NODATA=" << has_nodata << " -DHFVIS_CURVATURE=" << curvature
    << " -DHFVIS_MAX_DISTANCE=" << max_distance << " -DHFVIS_ROW_SPACING=" << row_spacing
    << " -DHFVIS_WANT_ANGLES=" << outputs.horizon_angles
    << " -DHFVIS_WANT_DISTANCES=" << outputs.horizon_distances
    << " -DHFVIS_WANT_SVF=" << outputs.sky_view_factor << " -DHFVIS_WANT_AO=" << outputs.ambient_occlusion
    << " -DHFVIS_WANT_ENV=" << (outputs.environment != nullptr)
    << " -DHFVIS_ENV_CHANNELS=" << (outputs.environment ? outputs.environment->channels : 1);
  return s.str();
}

// One direction of a run, whichever method: what the kernels and the outputs need.
struct RunDirection {
  LatticeDirection lattice;  // sweep (azimuth and weight for both methods)
  SweepDirection ray;        // naive march
  std::vector<LatticeSample> samples;
  std::vector<CellSegment> segments;  // sweep: the segment ending at each sample
  std::size_t stack_per_period = 0;   // sweep: hull-stack entries a period can push
  float cos_azimuth = 1.0f, sin_azimuth = 0.0f;  // as the scalar reference rounds them
  std::vector<LatticeLine> lines;                // sweep: the direction's lines over the field
  LatticeWindow window;                          // sweep: the maximum distance along its lines
  int max_steps = kAllSteps;                     // naive march: the steps within the maximum distance
  // Per-row spacing: length and terms by row (latticeRowTables: units; rayRowTables: ground
  // lengths), and where the sweep's lines start (RowTable::beyond).
  std::vector<float> row_length, row_terms;
  std::vector<std::uint32_t> row_beyond;
  int index = 0;  // k
};

// Planes per pixel an environment's sums take (one per channel), and the bytes of its map and of
// the tables of `directions` directions.
std::size_t environmentPlanes(const HorizonOutputs& outputs) {
  return outputs.environment ? outputs.environment->channels : 0;
}

// Planes per pixel the sky-view factor's and occlusion's sums take: two each with the error
// estimate (HorizonOutputs::error_estimate), the odd directions' sums apart.
std::size_t skySumPlanes(const HorizonOutputs& outputs) {
  return (std::size_t{outputs.sky_view_factor} + outputs.ambient_occlusion) * (1 + outputs.error_estimate);
}
std::size_t environmentBytes(const HorizonOutputs& outputs, std::size_t directions) {
  if (!outputs.environment) return 0;
  const EnvironmentMap& map = *outputs.environment;
  return (map.radiance.size() + directions * tableRows(map) * map.channels * kEnvTerms) * sizeof(float);
}

// How a run uses its device memory budget: directions per downloaded batch of planes, the
// hull-stack scratch (entries) every launch of the sweep shares, and the strips.
struct RunPlan {
  int directions_per_batch = 1;
  std::size_t stack_entries = 0;
  int strip_rows = 0;             // rows per strip: the field's height when it runs in one piece
  int halo_rows = 0;              // strips: rows of heights on each side beyond a strip's own
  std::size_t carry_entries = 0;  // strips: entries the two buffers of carried stacks may take together
  std::size_t budget = 0, per_row = 0, halo_bytes = 0;  // strips: what they were planned from
};

// A field beyond the budget (or asked to): strips of as many rows as half the budget holds, the
// rest for the hull stacks.
RunPlan planStrips(const HeightField& field, const HorizonOptions& options, const HorizonOutputs& outputs,
                   const std::vector<RunDirection>& directions, std::size_t budget, std::size_t max_alloc) {
  RunPlan plan;
  // A receiver's period reaches a step (|b| rows) away, the normals one row; within a maximum
  // distance the window's pass reaches back to the start of the block before, up to two
  // windows and a period along the line.
  // With per-row spacing the window is in units: so many of the shortest periods.
  const bool window = options.max_distance > 0.0, positions = window && hasRowSpacing(field);
  plan.halo_rows = 1;
  for (const RunDirection& d : directions) {
    double periods = 1.0;
    if (positions) {
      const double shortest = *std::min_element(d.row_length.begin(), d.row_length.end());
      const double longest = *std::max_element(d.row_length.begin(), d.row_length.end());
      periods = (2.0 * d.window.window + 2.0 * longest) / shortest;
    } else if (window) {
      periods = (2.0 * d.window.window + 2.0 * d.lattice.period) / d.lattice.period;
    }
    plan.halo_rows = std::max(plan.halo_rows, static_cast<int>(std::ceil(periods * std::abs(d.lattice.b))) + 1);
  }
  const std::size_t halo_rows = plan.halo_rows;
  const std::size_t row = field.width * sizeof(float);
  // Per row of a strip: heights, the sums, the normals' two slopes, one direction's planes, the
  // window's float2 (and with per-row spacing the receivers' positions, which also take the
  // halo's rows).
  const std::size_t per_row =
      row * (1 + skySumPlanes(outputs) + (outputs.ambient_occlusion || outputs.environment) * 2 +
             environmentPlanes(outputs) + outputs.horizon_angles +
             outputs.horizon_distances + window * 2 + positions);
  // The halo's rows, and the environment's map and tables.
  const std::size_t halo = 2 * halo_rows * row * (1 + positions) + environmentBytes(outputs, directions.size());
  std::size_t rows = budget / 2 > halo ? (budget / 2 - halo) / per_row : 0;
  // The largest buffers: a strip's heights with its halo, and its normals.
  rows = std::min({rows, max_alloc / row > 2 * halo_rows ? max_alloc / row - 2 * halo_rows : 0,
                   max_alloc / (2 * row)});
  if (options.strip_rows > 0) rows = std::min<std::size_t>(rows, options.strip_rows);
  if (rows < 1)
    throw MemoryBudgetError("a strip of one row needs " + mebibytes(2 * (per_row + halo)) +
                            " of device memory but the budget is " + mebibytes(budget) +
                            " (largest single buffer " + mebibytes(max_alloc) + "); raise the memory budget");
  plan.strip_rows = static_cast<int>(std::min<std::size_t>(rows, field.height));
  plan.budget = budget;
  plan.per_row = per_row;
  plan.halo_bytes = halo;
  const std::size_t rest = budget - (plan.strip_rows * per_row + halo);
  // An eighth for the scratch (lines run in chunks of it), the rest for the two buffers of
  // carried stacks (those a strip starts with and those it hands on), which must hold every
  // line under way at once: smooth terrain keeps a hundred or more samples of a line on its
  // hull (the sine field at 4096^2: 190 entries per line crossing a strip's edge).
  plan.stack_entries = std::min(rest / 8, max_alloc) / kStackEntryBytes;
  plan.carry_entries = rest / 8 * 7 / kStackEntryBytes;
  return plan;
}

RunPlan planRun(const HeightField& field, const HorizonOptions& options, const HorizonOutputs& outputs,
                const std::vector<RunDirection>& directions, const DeviceInfo& device) {
  const bool sweep = options.method == HorizonMethod::Sweep;
  const std::size_t budget = memoryBudget(options.memory_budget_bytes, device);
  const std::size_t max_alloc = device.max_allocation_bytes ? device.max_allocation_bytes : budget;
  const std::size_t plane = field.pixelCount() * sizeof(float);
  // Heights, the sums, the normals' two slopes, the window's float2 per pixel (and with per-row
  // spacing the receivers' positions).
  const bool window = sweep && options.max_distance > 0.0;
  const std::size_t fixed =
      plane * (1 + skySumPlanes(outputs) + (outputs.ambient_occlusion || outputs.environment) * 2 +
               environmentPlanes(outputs) + window * 2 +
               (window && hasRowSpacing(field))) +
      environmentBytes(outputs, directions.size());
  const std::size_t per_direction = plane * (outputs.horizon_angles + outputs.horizon_distances);
  // Scratch: all of a direction's stacks in one launch when it fits; one line at a time at least.
  std::size_t whole = 0, longest = 0;
  if (sweep) {
    for (const RunDirection& d : directions) {
      std::size_t total = 0;
      for (const LatticeLine& line : d.lines) {
        const std::size_t capacity = lineCapacity(line, d.stack_per_period);
        total += capacity;
        longest = std::max(longest, capacity);
      }
      whole = std::max(whole, total);
    }
  }
  const std::size_t least = fixed + per_direction + longest * kStackEntryBytes;
  const bool fits = least <= budget && per_direction <= max_alloc && longest * kStackEntryBytes <= max_alloc;
  if (!fits || (options.strip_rows > 0 && options.strip_rows < field.height)) {
    if (sweep) return planStrips(field, options, outputs, directions, budget, max_alloc);
    throw MemoryBudgetError("one direction needs " + mebibytes(least) + " of device memory but the budget is " +
                            mebibytes(budget) + " (largest single buffer " + mebibytes(max_alloc) +
                            "), and the naive method needs the whole field at once (no strips); raise the memory "
                            "budget or use a smaller field");
  }
  const std::size_t available = budget - fixed;
  RunPlan plan;
  plan.strip_rows = field.height;
  // Planes of up to kMaxDirectionsPerBatch directions, leaving the scratch at least half.
  const std::size_t stack_bytes = std::min(whole * kStackEntryBytes, max_alloc);
  const std::size_t for_planes =
      available - std::min(stack_bytes, std::max(available / 2, longest * kStackEntryBytes));
  plan.directions_per_batch = static_cast<int>(
      std::min<std::size_t>({static_cast<std::size_t>(std::min(options.directions, kMaxDirectionsPerBatch)),
                             per_direction ? std::max<std::size_t>(1, for_planes / per_direction)
                                           : std::size_t(kMaxDirectionsPerBatch),
                             per_direction ? std::max<std::size_t>(1, max_alloc / per_direction)
                                           : std::size_t(kMaxDirectionsPerBatch)}));
  // Plane offsets within a batch are 32-bit in the kernels.
  plan.directions_per_batch = static_cast<int>(std::min<std::size_t>(
      plan.directions_per_batch, std::max<std::size_t>(1, std::size_t(0xffffffffu) / field.pixelCount())));
  plan.stack_entries = std::min(
      whole, std::min(available - plan.directions_per_batch * per_direction, max_alloc) / kStackEntryBytes);
  return plan;
}

// The lines of step (a, b) that reach a pixel of `wanted` (non-zero per pixel), each cut after its
// last receiver there: receiver i's horizon comes from the part of its line beyond it (receivers 0
// .. i - 1 and the samples between), which the cut leaves as it was.
std::vector<LatticeLine> linesReaching(const std::vector<LatticeLine>& lines, int a, int b, int width,
                                       const std::vector<char>& wanted) {
  std::vector<LatticeLine> kept;
  for (LatticeLine line : lines) {
    int last = -1;
    for (int i = 0; i < line.receivers; ++i)
      if (wanted[static_cast<std::size_t>(line.row - i * b) * width + (line.col - i * a)]) last = i;
    if (last < 0) continue;
    line.receivers = last + 1;
    kept.push_back(line);
  }
  return kept;
}

// `wanted` (null: every pixel): the sweep runs only the lines that reach those pixels
// (linesReaching); the others' outputs are left unfinished. `subset` (the sweep with exact
// azimuths, the horizon planes alone): of the directions of a run at subset->of, those at
// subset->indices, in that order (options.directions their count), each as that run takes it.
std::vector<RunDirection> runDirectionsOf(const HeightField& field, const HorizonOptions& options,
                                          const HorizonOutputs& outputs, const std::vector<char>* wanted,
                                          const DirectionSubset* subset) {
  std::vector<RunDirection> out;
  if (subset && (options.method != HorizonMethod::Sweep || !exactAzimuths(outputs) || outputs.sky_view_factor ||
                 outputs.ambient_occlusion || outputs.environment ||
                 int(subset->indices.size()) != options.directions))
    throw std::logic_error("a subset of directions: the sweep's horizon planes alone, options.directions of them");
  if (options.method == HorizonMethod::Sweep) {
    std::vector<LatticeDirection> directions;
    if (subset) {
      HorizonOptions whole = options;
      whole.directions = subset->of;
      const std::vector<LatticeDirection> all = horizonDirections(field, whole, outputs);
      for (const int k : subset->indices) directions.push_back(all.at(std::size_t(k)));
    } else {
      directions = horizonDirections(field, options, outputs);
    }
    std::vector<RowTable> rows;
    if (hasRowSpacing(field)) rows = latticeRowTables(field, directions, !exactAzimuths(outputs), outputs.error_estimate);
    for (std::size_t k = 0; k < directions.size(); ++k) {
      const LatticeDirection& d = directions[k];
      std::vector<CellSegment> segments = cellSegments(d, options.samples_per_unit);
      const std::size_t per_period = stackEntriesPerPeriod(segments);
      out.push_back({d,
                     SweepDirection{},
                     latticeSamples(d, options.samples_per_unit),
                     std::move(segments),
                     per_period,
                     static_cast<float>(std::cos(d.azimuth)),
                     static_cast<float>(std::sin(d.azimuth)),
                     latticeLines(d, field.width, field.height),
                     latticeWindow(field, d, options.max_distance),
                     kAllSteps,
                     {},
                     {},
                     {},
                     static_cast<int>(k)});
      if (wanted) out.back().lines = linesReaching(out.back().lines, d.a, d.b, field.width, *wanted);
      if (!rows.empty()) {
        out.back().row_length = std::move(rows[k].length);
        out.back().row_terms = std::move(rows[k].terms);
        out.back().row_beyond = std::move(rows[k].beyond);
      }
    }
  } else {
    const std::vector<SweepDirection> rays = runDirections(field, options);
    std::vector<RowTable> rows;
    if (hasRowSpacing(field)) rows = rayRowTables(field, rays);
    for (int k = 0; k < options.directions; ++k) {
      const SweepDirection& d = rays[k];
      RunDirection r;
      r.index = k;
      r.ray = d;
      r.lattice.azimuth = directionAzimuth(k, options);
      r.lattice.weight = 1.0 / options.directions;
      r.cos_azimuth = d.cos_azimuth;
      r.sin_azimuth = d.sin_azimuth;
      // With per-row spacing the march cuts at the ground length itself (horizon_naive's max_ground).
      r.max_steps = hasRowSpacing(field) ? kAllSteps
                                         : stepsWithin(options.max_distance, double(d.step_length) * d.ground_per_pixel);
      if (!rows.empty()) {
        r.row_length = std::move(rows[k].length);
        r.row_terms = std::move(rows[k].terms);
      }
      out.push_back(r);
    }
  }
  return out;
}

// Hull stacks that outgrow what the budget leaves beside the strips; `rows`: thinner strips that
// leave room for them (computeHorizons retries with those), 0 when none do.
struct StacksBeyondStrips : MemoryBudgetError {
  StacksBeyondStrips(const std::string& message, int strip_rows) : MemoryBudgetError(message), rows(strip_rows) {}
  int rows;
};

class HorizonRoutine : public SweepRoutine {
 public:
  // `wanted`, `subset`: as runDirectionsOf takes them.
  HorizonRoutine(ContextState& st, const HeightField& field, const HorizonOptions& options,
                 const HorizonOutputs& outputs, const std::vector<char>* wanted = nullptr,
                 const DirectionSubset* subset = nullptr)
      : SweepRoutine(st, field, options),
        horizon_(options),
        outputs_(outputs),
        lanes_(simdLanes(st)),
        directions_(runDirectionsOf(field, options, outputs, wanted, subset)),
        plan_(planRun(field, options, outputs, directions_, st.info)) {
    // A window's blocks are per line, so its strips, and with per-row spacing its whole sweep
    // (positions differ by line there), run one line per work-item.
    if ((inStrips() || hasRowSpacing(field)) && options.max_distance > 0.0) lanes_ = 1;
    // A field cut from a larger one: each line's positions count from its own place there, so
    // (without per-row spacing, whose lanes start at positions of their own) a work-item's lanes
    // take lines that start at the same index there (laneGroups): not in strips, where lines
    // resume at indices of their own, nor where the lanes' lines together outgrow the scratch.
    if (shiftedPositions() && (inStrips() || lanes_ * longestLineEntries() > plan_.stack_entries)) lanes_ = 1;
  }

  HorizonResult take() { return std::move(result_); }

 private:
  std::string programFile() const override { return "horizon.cl"; }
  std::string programOptions() const override {
    return detail::programOptions(outputs_, prepared_.has_nodata, lanes_, horizon_.curvature != 0.0,
                                  horizon_.max_distance > 0.0, hasRowSpacing(field_)) +
           " -DHFVIS_STRIPS=" + std::to_string(inStrips()) +
           " -DHFVIS_ORIGIN=" + std::to_string(field_.origin.present());
  }
  // Positions along a larger field's lines shared by a work-item's lanes (HeightField::origin; with
  // per-row spacing each lane starts at its own).
  bool shiftedPositions() const { return field_.origin.present() && !hasRowSpacing(field_); }
  bool heightsResident() const override { return !inStrips(); }
  bool needsNormals() const { return outputs_.ambient_occlusion || outputs_.environment; }
  int environmentChannels() const { return static_cast<int>(environmentPlanes(outputs_)); }
  bool inStrips() const { return plan_.strip_rows < field_.height; }

  void allocate() override {
    result_ = allocateResult(field_, horizon_, outputs_);
    for (int k = 0; k < horizon_.directions; ++k) result_.azimuths[k] = directions_[k].lattice.azimuth;
    // Device planes and sums cover a strip's rows (all of them in one piece).
    const std::size_t plane = static_cast<std::size_t>(plan_.strip_rows) * field_.width;
    const std::size_t planes_bytes = plan_.directions_per_batch * plane * sizeof(float);
    angles_ = st_.reusableBuffer("horizon angles", outputs_.horizon_angles ? planes_bytes : 0);
    distances_ = st_.reusableBuffer("horizon distances", outputs_.horizon_distances ? planes_bytes : 0);
    svf_ = zeros(outputs_.sky_view_factor ? plane : 0);
    ao_ = zeros(outputs_.ambient_occlusion ? plane : 0);
    svf_odd_ = zeros(outputs_.sky_view_factor && outputs_.error_estimate ? plane : 0);
    ao_odd_ = zeros(outputs_.ambient_occlusion && outputs_.error_estimate ? plane : 0);
    if (inStrips() && outputs_.error_estimate) {
      if (outputs_.sky_view_factor) svf_odd_host_.assign(field_.pixelCount(), 0.0f);
      if (outputs_.ambient_occlusion) ao_odd_host_.assign(field_.pixelCount(), 0.0f);
    }
    env_sum_ = zeros(environmentChannels() * plane);
    normals_ = deviceBuffer(st_, needsNormals() ? 2 * plane * sizeof(float) : 0);
    env_tables_ = environmentTables();
    stacks_ = st_.reusableBuffer("lattice stacks", plan_.stack_entries * kStackEntryBytes);
    const bool window = horizon_.method == HorizonMethod::Sweep && horizon_.max_distance > 0.0;
    window_far_ = deviceBuffer(st_, window ? 2 * plane * sizeof(float) : 0);
    // Per-row spacing within a maximum distance: the receivers' positions, over the heights' rows
    // (in strips the halo's too: those of earlier strips come from the host, which holds them all).
    const bool positions = window && hasRowSpacing(field_);
    const std::size_t position_rows =
        inStrips() ? std::min<std::size_t>(plan_.strip_rows + 2 * plan_.halo_rows, field_.height) : field_.height;
    receiver_base_ = deviceBuffer(st_, positions ? position_rows * field_.width * sizeof(float) : 0);
    if (positions && inStrips()) receiver_positions_.assign(field_.pixelCount(), 0.0f);
    placeholder_ = deviceBuffer(st_, 0);
    row_cells_ = rowCells();
    if (inStrips()) {
      heights_ = deviceBuffer(
          st_, std::min<std::size_t>(plan_.strip_rows + 2 * plan_.halo_rows, field_.height) * field_.width *
                   sizeof(float));
    } else if (needsNormals()) {
      computeNormals(0, 0, field_.height);
    }
  }

  // Every direction's table of the environment (environment_tables), in one buffer: direction
  // k's from k * envTableFloats() on. A placeholder without an environment.
  cl::Buffer environmentTables() {
    if (!outputs_.environment) return deviceBuffer(st_, 0);
    const EnvironmentMap& map = *outputs_.environment;
    std::vector<LatticeDirection> directions;
    for (const RunDirection& d : directions_) directions.push_back(d.lattice);
    const EnvironmentSwaths swaths = environmentSwaths(map, directions);
    // The tables are one buffer, each direction's found at a 32-bit offset.
    const std::size_t table_bytes = directions_.size() * envTableFloats() * sizeof(float);
    const std::size_t max_alloc = st_.info.max_allocation_bytes ? st_.info.max_allocation_bytes : table_bytes;
    if (directions_.size() * envTableFloats() >= (std::size_t(1) << 32) || table_bytes > max_alloc)
      throw MemoryBudgetError("the environment's tables take " + mebibytes(table_bytes) +
                              ", beyond the device's largest buffer or 2^32 values; take fewer directions or "
                              "fewer table rows (EnvironmentMap::table_rows, --env-rows)");
    auto upload = [&](const void* data, std::size_t bytes) {
      return cl::Buffer(st_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, bytes, const_cast<void*>(data));
    };
    const cl::Buffer env = upload(map.radiance.data(), map.radiance.size() * sizeof(float));
    const cl::Buffer bins = upload(swaths.bins.data(), swaths.bins.size() * sizeof(swaths.bins[0]));
    const cl::Buffer spans = upload(swaths.spans.data(), swaths.spans.size() * sizeof(swaths.spans[0]));
    cl::Buffer tables = deviceBuffer(st_, table_bytes);
    NamedKernel kernel(st_, program_, "environment_tables");
    kernel.set("env", env);
    kernel.set("env_width", map.width);
    kernel.set("env_height", map.height);
    kernel.set("channels", map.channels);
    kernel.set("rows", tableRows(map));
    kernel.set("directions", static_cast<int>(directions_.size()));
    kernel.set("bins", bins);
    kernel.set("spans", spans);
    kernel.set("tables", tables);
    st_.launch(kernel, cl::NDRange(roundUp(directions_.size(), kLineGroup)), cl::NDRange(kLineGroup));
    st_.queue.finish();  // before the map, bins and spans go
    return tables;
  }

  // Floats of one direction's table.
  std::size_t envTableFloats() const {
    return outputs_.environment ? std::size_t(tableRows(*outputs_.environment)) * outputs_.environment->channels * kEnvTerms
                                : 0;
  }

  int directionCount() const override { return horizon_.directions; }
  int batchSize() const override { return plan_.directions_per_batch; }

  void sweep(int k, int slot) override {
    const RunDirection& d = directions_[k];
    const bool planes = outputs_.horizon_angles || outputs_.horizon_distances;
    if (d.lattice.weight == 0.0 && !planes) return;  // merged into an equal step (latticeDirections)
    const cl_uint plane_offset = static_cast<cl_uint>(slot * field_.pixelCount());
    if (horizon_.method == HorizonMethod::Naive) {
      launchNaive(d, plane_offset);
    } else if (inStrips()) {
      sweepInStrips(d, k);
    } else {
      launchSweep(d, plane_offset);
    }
  }

  void endBatch(int first, int count) override {
    if (inStrips()) return;  // each strip's planes came back with it
    const std::size_t plane = field_.pixelCount();
    const std::size_t batch_bytes = count * plane * sizeof(float), at = first * plane;
    if (outputs_.horizon_angles) st_.queue.enqueueReadBuffer(angles_, CL_TRUE, 0, batch_bytes, &result_.angles[at]);
    if (outputs_.horizon_distances)
      st_.queue.enqueueReadBuffer(distances_, CL_TRUE, 0, batch_bytes, &result_.distances[at]);
  }

  void finish() override {
    if (inStrips()) {
      // The sums are on the host; the last pass of occlusion and irradiance runs strip by strip.
      if (needsNormals()) {
        for (int s0 = 0; s0 < field_.height; s0 += plan_.strip_rows) {
          const int s1 = std::min(field_.height, s0 + plan_.strip_rows);
          loadStrip(s0, s1);
          scaleByNormals(s1 - s0);
          readSkySumRows(s0, s1);
          copyEnvironmentRows(s0, s1);
        }
      }
    } else {
      const std::size_t bytes = field_.pixelCount() * sizeof(float);
      if (needsNormals()) scaleByNormals(field_.height);
      if (outputs_.error_estimate) {
        if (outputs_.sky_view_factor) svf_odd_host_.resize(field_.pixelCount());
        if (outputs_.ambient_occlusion) ao_odd_host_.resize(field_.pixelCount());
      }
      readSkySumRows(0, field_.height);
      if (outputs_.environment)
        st_.queue.enqueueReadBuffer(env_sum_, CL_TRUE, 0, environmentChannels() * bytes, result_.irradiance.data());
    }
    if (outputs_.error_estimate) splitHalves();
    finishReduction(result_);
    if (horizon_.method == HorizonMethod::Sweep) {
      double samples = 0.0;
      for (const RunDirection& d : directions_) {
        std::size_t receivers = 0;
        for (const LatticeLine& line : d.lines) receivers += line.receivers;
        samples += static_cast<double>(d.samples.size()) * receivers;
      }
      result_.samples_per_receiver = samples / static_cast<double>(field_.pixelCount());
    }
  }

  // The sky-view factor's and occlusion's sums of rows [s0, s1) from the device (the odd
  // directions' apart with the halves' difference); writes them back with `to_device`.
  void readSkySumRows(int s0, int s1, bool to_device = false) {
    const auto copy = [&](const cl::Buffer& rows, std::vector<float>& host) {
      if (host.empty()) return;
      const std::size_t width = field_.width, bytes = (s1 - s0) * width * sizeof(float);
      if (to_device)
        st_.queue.enqueueWriteBuffer(rows, CL_FALSE, 0, bytes, &host[s0 * width]);
      else
        readRows(rows, host, s0, s1);
    };
    copy(svf_, result_.sky_view_factor);
    copy(ao_, result_.ambient_occlusion);
    copy(svf_odd_, svf_odd_host_);
    copy(ao_odd_, ao_odd_host_);
  }

  // The error estimate (HorizonOutputs::error_estimate) from the halves' sums.
  void splitHalves() {
    double even_weight = 0.0, odd_weight = 0.0, cubes = 0.0;
    for (const RunDirection& d : directions_) {
      (d.index % 2 ? odd_weight : even_weight) += d.lattice.weight;
      cubes += d.lattice.weight * d.lattice.weight * d.lattice.weight;
    }
    splitErrorHalves(result_, svf_odd_host_, ao_odd_host_, even_weight, odd_weight, field_, prepared_.heights,
                     cubes / (even_weight + odd_weight));
  }

  // The occlusion and irradiance sums of the rows on the device made those of unit normals
  // (occlusion_scale).
  void scaleByNormals(int rows) {
    const std::size_t pixels = static_cast<std::size_t>(rows) * field_.width;
    auto scale = [&](const cl::Buffer& sums, int planes) {
      NamedKernel kernel(st_, program_, "occlusion_scale");
      kernel.set("normals", normals_);
      kernel.set("pixels", static_cast<cl_uint>(pixels));
      kernel.set("planes", planes);
      kernel.set("stride", sumStride());
      kernel.set("sums", sums);
      st_.launch(kernel, cl::NDRange(roundUp(pixels, kLineGroup)), cl::NDRange(kLineGroup));
    };
    if (outputs_.ambient_occlusion) scale(ao_, 1);
    if (outputs_.ambient_occlusion && outputs_.error_estimate) scale(ao_odd_, 1);
    if (outputs_.environment) scale(env_sum_, environmentChannels());
  }

  // Between the planes of the environment's sums on the device: a strip's pixels (the field's
  // in one piece).
  cl_uint sumStride() const { return static_cast<cl_uint>(static_cast<std::size_t>(plan_.strip_rows) * field_.width); }

  // Strips: the irradiance sums of rows [s0, s1) from the device (or to it, `to_device`).
  void copyEnvironmentRows(int s0, int s1, bool to_device = false) {
    const std::size_t width = field_.width, bytes = (s1 - s0) * width * sizeof(float);
    for (int c = 0; c < environmentChannels(); ++c) {
      float* host = &result_.irradiance[c * field_.pixelCount() + s0 * width];
      const std::size_t at = c * sumStride() * sizeof(float);
      if (to_device)
        st_.queue.enqueueWriteBuffer(env_sum_, CL_FALSE, at, bytes, host);
      else
        st_.queue.enqueueReadBuffer(env_sum_, CL_TRUE, at, bytes, host);
    }
  }

  // The normals of rows [s0, s1) from heights_, which holds the field's rows from row0 on.
  void computeNormals(int row0, int s0, int s1) {
    NamedKernel normals(st_, program_, "pixel_normals");
    normals.set("heights", heights_);
    normals.set("width", field_.width);
    normals.set("height", field_.height);
    normals.set("row0", row0);
    normals.set("out_row0", s0);
    normals.set("rows", s1 - s0);
    normals.set("cell_x", static_cast<float>(field_.cell_size_x));
    normals.set("cell_y", static_cast<float>(field_.cell_size_y));
    normals.set("row_cells", row_cells_);
    normals.set("normals", normals_);
    st_.launch(normals, cl::NDRange(roundUp(field_.width, kTileX), roundUp(s1 - s0, kTileY)),
               cl::NDRange(kTileX, kTileY));
  }

  // Strips: puts rows [s0, s1) on the device (their heights with the halo's rows around, their
  // sums so far, their normals); returns the first row of the heights there.
  int loadStrip(int s0, int s1) {
    const std::size_t width = field_.width;
    const int row0 = std::max(0, s0 - plan_.halo_rows), row1 = std::min(field_.height, s1 + plan_.halo_rows);
    st_.queue.enqueueWriteBuffer(heights_, CL_FALSE, 0, (row1 - row0) * width * sizeof(float),
                                 &prepared_.heights[row0 * width]);
    if (!receiver_positions_.empty())
      st_.queue.enqueueWriteBuffer(receiver_base_, CL_FALSE, 0, (row1 - row0) * width * sizeof(float),
                                   &receiver_positions_[row0 * width]);
    readSkySumRows(s0, s1, true);
    copyEnvironmentRows(s0, s1, true);
    if (needsNormals()) computeNormals(row0, s0, s1);
    return row0;
  }

  // Rows [s0, s1) of the device's `rows` (a strip's) into `host` from `at` on.
  void readRows(const cl::Buffer& rows, std::vector<float>& host, int s0, int s1, std::size_t at = 0) {
    const std::size_t width = field_.width;
    st_.queue.enqueueReadBuffer(rows, CL_TRUE, 0, (s1 - s0) * width * sizeof(float), &host[at + s0 * width]);
  }

  // The Earth's drop per pixel length squared along a direction of that ground length per pixel.
  float curvatureDrop(double ground_per_pixel) const {
    return static_cast<float>(horizon_.curvature * ground_per_pixel * ground_per_pixel);
  }

  // Per-row spacing: every row's cell sizes (x, y) as floats, for the normals (a placeholder
  // without).
  cl::Buffer rowCells() {
    if (!hasRowSpacing(field_)) return deviceBuffer(st_, 0);
    std::vector<float> cells;
    for (int r = 0; r < field_.height; ++r) {
      cells.push_back(static_cast<float>(field_.row_cell_size_x[r]));
      cells.push_back(static_cast<float>(field_.row_cell_size_y[r]));
    }
    return cl::Buffer(st_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, cells.size() * sizeof(float),
                      cells.data());
  }

  // The ground length of a unit of position along the sweep's lines: pixels of that ground
  // length, or (per-row spacing) units of sweepUnit.
  double latticeUnit(double ground_per_pixel) const {
    return hasRowSpacing(field_) ? sweepUnit(field_) : ground_per_pixel;
  }
  // The same along the naive march's rays: pixels, or (per-row spacing) ground units.
  double rayUnit(double ground_per_pixel) const { return hasRowSpacing(field_) ? 1.0 : ground_per_pixel; }

  // The per-row tables of a direction (placeholders without per-row spacing), set as the
  // kernel's row_length and row_terms (and the sweep's row_beyond); the caller keeps them until
  // the launch.
  std::vector<cl::Buffer> setRowTables(NamedKernel& kernel, const RunDirection& d, bool sweep) {
    auto table = [&](const auto& values) {
      if (values.empty()) return deviceBuffer(st_, 0);
      return cl::Buffer(st_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                        values.size() * sizeof(values[0]),
                        const_cast<void*>(static_cast<const void*>(values.data())));
    };
    std::vector<cl::Buffer> tables{table(d.row_length), table(d.row_terms)};
    kernel.set("row_length", tables[0]);
    kernel.set("row_terms", tables[1]);
    if (sweep) {
      tables.push_back(table(d.row_beyond));
      kernel.set("row_beyond", tables[2]);
    }
    return tables;
  }

  // The arguments every direction's kernel ends with: its outputs.
  void setOutputs(NamedKernel& kernel, const RunDirection& d, cl_uint plane_offset) {
    kernel.set("cos_azimuth", d.cos_azimuth);
    kernel.set("sin_azimuth", d.sin_azimuth);
    kernel.set("weight", static_cast<float>(d.lattice.weight));
    kernel.set("swath", swathFactor(static_cast<float>(d.lattice.weight)));
    kernel.set("plane", plane_offset);
    if (horizon_.method == HorizonMethod::Sweep) {  // the stride is set per chunk
      kernel.set("stacks", stacks_);
      kernel.set("line_state", placeholder_);  // line_state and carry_in, used in strips
      kernel.set("carry_in", placeholder_);
      kernel.set("window_far", window_far_);
      kernel.set("receiver_base", receiver_base_);
    }
    kernel.set("normals", normals_);
    kernel.set("angles", angles_);
    kernel.set("distances", distances_);
    const bool odd = outputs_.error_estimate && d.index % 2 == 1;
    kernel.set("svf_sum", odd ? svf_odd_ : svf_);
    kernel.set("ao_sum", odd ? ao_odd_ : ao_);
    kernel.set("env_tables", env_tables_);
    kernel.set("env_offset", static_cast<cl_uint>(d.index * envTableFloats()));
    kernel.set("env_rows", outputs_.environment ? tableRows(*outputs_.environment) : 0);
    kernel.set("env_sum", env_sum_);
    kernel.set("env_stride", sumStride());
  }

  // horizon_lattice for direction d with everything but the chunk's lines set (rows from 0 on,
  // no line states); `keep` holds the buffers it takes until the launch.
  NamedKernel sweepKernel(const RunDirection& d, cl_uint plane_offset, std::vector<cl::Buffer>& keep) {
    keep.emplace_back(st_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, d.samples.size() * sizeof(LatticeSample),
                      const_cast<LatticeSample*>(d.samples.data()));
    NamedKernel kernel(st_, program_, "horizon_lattice");
    kernel.set("heights", heights_);
    kernel.set("width", field_.width);
    kernel.set("height", field_.height);
    kernel.set("row0", 0);
    kernel.set("out_row0", 0);
    kernel.set("samples", keep.back());
    keep.emplace_back(st_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, d.segments.size() * sizeof(CellSegment),
                      const_cast<CellSegment*>(d.segments.data()));
    kernel.set("segments", keep.back());
    kernel.set("n_samples", static_cast<int>(d.samples.size()));
    kernel.set("a", d.lattice.a);
    kernel.set("b", d.lattice.b);
    kernel.set("period", static_cast<float>(d.lattice.period));
    const double unit = latticeUnit(d.lattice.ground_per_pixel);
    kernel.set("ground_per_pixel", static_cast<float>(unit));
    kernel.set("period_ground", static_cast<float>(d.lattice.period * d.lattice.ground_per_pixel));
    kernel.set("drop", curvatureDrop(unit));
    kernel.set("window", d.window.window);
    kernel.set("inv_window", d.window.inv_window);
    const FieldOrigin& origin = field_.origin;
    kernel.set("origin_col", origin.col);
    kernel.set("origin_row", origin.row);
    kernel.set("whole_width", origin.present() ? origin.whole_width : field_.width);
    kernel.set("whole_height", origin.present() ? origin.whole_height : field_.height);
    for (cl::Buffer& table : setRowTables(kernel, d, true)) keep.push_back(table);
    setOutputs(kernel, d, plane_offset);
    return kernel;
  }

  // Work-items per group of horizon_lattice. With lanes, groups of one work-item: 64
  // work-items of 8 lines would put all of a 512-line direction in one group, on one core.
  std::size_t sweepGroup() const { return lanes_ > 1 ? 1 : kLineGroup; }

  void launchSweep(const RunDirection& d, cl_uint plane_offset) {
    std::vector<cl::Buffer> keep;
    NamedKernel kernel = sweepKernel(d, plane_offset, keep);
    const bool grouped = shiftedPositions() && lanes_ > 1;
    launchLineChunks(st_, kernel, grouped ? laneGroups(d) : d.lines, d.stack_per_period, plan_.stack_entries, lanes_,
                     sweepGroup(), grouped);
  }

  // Direction d's lines ordered by the index of their first receiver along the larger field's
  // lines (receiverIndex), each run of equal indices led by lines without receivers up to a
  // multiple of the lanes: every work-item's lanes then start at one index and share their
  // positions (HFVIS_ORIGIN). The empty lines take the stack of the line after them.
  std::vector<LatticeLine> laneGroups(const RunDirection& d) const {
    std::vector<std::pair<int, LatticeLine>> indexed;
    for (const LatticeLine& line : d.lines)
      indexed.emplace_back(receiverIndex(field_, d.lattice.a, d.lattice.b, line.col, line.row), line);
    std::stable_sort(indexed.begin(), indexed.end(),
                     [](const auto& x, const auto& y) { return x.first < y.first; });
    const std::size_t lanes = static_cast<std::size_t>(lanes_);
    std::vector<LatticeLine> lines;
    for (std::size_t j = 0; j < indexed.size();) {
      std::size_t end = j;
      while (end < indexed.size() && indexed[end].first == indexed[j].first) ++end;
      const LatticeLine empty{indexed[j].second.col, indexed[j].second.row, 0, 0};
      lines.insert(lines.end(), (lanes - (end - j) % lanes) % lanes, empty);
      for (; j < end; ++j) lines.push_back(indexed[j].second);
    }
    return lines;
  }

  // Scratch entries of the longest line of any direction.
  std::size_t longestLineEntries() const {
    std::size_t longest = 0;
    for (const RunDirection& d : directions_)
      for (const LatticeLine& line : d.lines) longest = std::max(longest, lineCapacity(line, d.stack_per_period));
    return longest;
  }

  // Direction k over a field in strips: the strips in the order its lines run through them
  // (toward -(a, b)), each line's part in a strip resuming its sweep with the stack it left the
  // strip before with (horizon_lattice, HFVIS_STRIPS), which carry_stacks moves from the scratch
  // into a compact buffer between strips. The sums go up and down with each strip.
  void sweepInStrips(const RunDirection& d, int k) {
    const int rows = plan_.strip_rows, strips = (field_.height + rows - 1) / rows;
    const int a = d.lattice.a, b = d.lattice.b;
    const std::size_t per_period = d.stack_per_period;
    // Within a maximum distance the window's pass pushes the samples of the block before, up to a
    // window and two periods of them, above a resumed line's stack.
    // (With per-row spacing the window is in units: so many of the shortest periods.)
    const double shortest_period =
        d.row_length.empty() ? d.lattice.period : *std::min_element(d.row_length.begin(), d.row_length.end());
    const std::size_t window_periods =
        horizon_.max_distance > 0.0 ? static_cast<std::size_t>(std::ceil(d.window.window / shortest_period)) + 2 : 0;
    // Each line's sweep so far: (unused, its stack's size, the stack's offset in carry_in,
    // its position's float bits).
    std::vector<cl_int4> resume(d.lines.size(), cl_int4{{0, 0, 0, 0}});
    std::vector<char> waiting(d.lines.size(), 0);  // whether its stack waits in carry_in
    cl::Buffer carry_in = placeholder_;
    std::size_t carried_in = 0;  // entries in carry_in
    std::vector<cl::Buffer> keep;
    NamedKernel kernel = sweepKernel(d, 0, keep);  // the strip's rows and lines set per strip
    for (int step = 0; step < strips; ++step) {
      const int s = b > 0 ? strips - 1 - step : step;  // rows fall along a line when b > 0
      const int s0 = s * rows, s1 = std::min(field_.height, s0 + rows);
      const int row0 = loadStrip(s0, s1);
      kernel.set("row0", row0);
      kernel.set("out_row0", s0);
      kernel.set("carry_in", carry_in);
      // The strip's part of every line that has receivers in it.
      std::vector<LatticeLine> lines;
      std::vector<cl_int4> states;
      std::vector<std::size_t> capacities, owner;
      for (std::size_t j = 0; j < d.lines.size(); ++j) {
        const LatticeLine& line = d.lines[j];
        const auto [first, end] = receiversInRows(line, b, s0, s1);
        if (first == end) continue;
        lines.push_back({line.col - first * a, line.row - first * b, end - first, 0});
        cl_int4 state = resume[j];
        state.s[0] = first;
        states.push_back(state);
        capacities.push_back(static_cast<std::size_t>(state.s[1]) + (end - first + window_periods) * per_period);
        if (capacities.back() > plan_.stack_entries)  // the scratch is an eighth of the rest
          failCarry("one line's hull stack", capacities.back(), capacities.back() * kStackEntryBytes * 8);
        owner.push_back(j);
      }
      std::size_t carried = 0, capacity = 0;  // entries in carry_out
      cl::Buffer carry_out;
      // Stacks from `source` (entry k of line i at lines[i].w + k stride, states[i].y entries) into
      // carry_out at `offsets` (from `carried` on; -1: none).
      auto carryOut = [&](const cl::Buffer& lines_buffer, const cl::Buffer& states_buffer,
                          const std::vector<cl_int>& offsets, const cl::Buffer& source, cl_uint stride) {
        if (carried > capacity) {
          if (carried_in + carried > plan_.carry_entries || carried > maxAllocationEntries() ||
              carried >= (std::size_t(1) << 31))
            failCarry("the hull stacks carried into the next strip", carried_in + carried,
                      (carried_in + carried) * kStackEntryBytes / 7 * 8);
          const std::size_t grown =
              std::min({std::max(carried, 2 * capacity), plan_.carry_entries - carried_in, maxAllocationEntries()});
          cl::Buffer bigger = deviceBuffer(st_, grown * kStackEntryBytes);
          if (capacity) st_.queue.enqueueCopyBuffer(carry_out, bigger, 0, 0, capacity * kStackEntryBytes);
          carry_out = bigger;
          capacity = grown;
        }
        if (std::none_of(offsets.begin(), offsets.end(), [](cl_int o) { return o >= 0; })) return;
        const cl::Buffer offsets_buffer(st_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                                        offsets.size() * sizeof(cl_int), const_cast<cl_int*>(offsets.data()));
        NamedKernel move(st_, program_, "carry_stacks");
        move.set("lines", lines_buffer);
        move.set("line_state", states_buffer);
        move.set("offsets", offsets_buffer);
        move.set("n_lines", static_cast<int>(offsets.size()));
        move.set("stacks", source);
        move.set("stride", stride);
        move.set("carry_out", carry_out);
        st_.launch(move, cl::NDRange(roundUp(offsets.size(), kLineGroup)), cl::NDRange(kLineGroup));
        st_.queue.finish();  // before the caller's buffers go
      };
      std::vector<char> next_waiting(d.lines.size(), 0);
      for (const LineChunk& chunk : chunkLines(lines, capacities, plan_.stack_entries, lineMajorLayout(st_))) {
        const cl::Buffer chunk_lines(st_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                                     chunk.count * sizeof(LatticeLine), lines.data() + chunk.first);
        const cl::Buffer chunk_states(st_.context, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR,
                                      chunk.count * sizeof(cl_int4), states.data() + chunk.first);
        kernel.set("lines", chunk_lines);
        kernel.set("n_lines", static_cast<int>(chunk.count));
        kernel.set("stride", static_cast<cl_uint>(chunk.stride));
        kernel.set("line_state", chunk_states);
        const std::size_t items = (chunk.count + lanes_ - 1) / lanes_;
        st_.launch(kernel, cl::NDRange(roundUp(items, sweepGroup())), cl::NDRange(sweepGroup()));
        st_.queue.enqueueReadBuffer(chunk_states, CL_TRUE, 0, chunk.count * sizeof(cl_int4),
                                    states.data() + chunk.first);
        // Where the stacks of the lines that go on into the next strip wait for it.
        std::vector<cl_int> offsets(chunk.count, -1);
        for (std::size_t i = 0; i < chunk.count; ++i) {
          const std::size_t at = chunk.first + i, j = owner[at];
          cl_int4& state = states[at];
          if (state.s[0] + lines[at].receivers == d.lines[j].receivers) continue;  // the line ends here
          offsets[i] = static_cast<cl_int>(carried);
          state.s[2] = offsets[i];
          resume[j] = state;
          next_waiting[j] = 1;
          carried += state.s[1];
        }
        carryOut(chunk_lines, chunk_states, offsets, stacks_, static_cast<cl_uint>(chunk.stride));
      }
      // Lines with no receiver in this strip (a step of more rows than a strip has) that are
      // under way: their stacks move on from carry_in as they are.
      std::vector<LatticeLine> passing;
      std::vector<cl_int4> passing_states;
      std::vector<cl_int> offsets;
      for (std::size_t j = 0; j < d.lines.size(); ++j) {
        if (!waiting[j] || next_waiting[j]) continue;
        const auto [first, end] = receiversInRows(d.lines[j], b, s0, s1);
        if (first != end) continue;  // it ended in this strip
        passing.push_back({0, 0, 0, resume[j].s[2]});
        passing_states.push_back(resume[j]);
        offsets.push_back(static_cast<cl_int>(carried));
        resume[j].s[2] = offsets.back();
        next_waiting[j] = 1;
        carried += resume[j].s[1];
      }
      if (!passing.empty()) {
        const cl::Buffer passing_lines(st_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                                       passing.size() * sizeof(LatticeLine), passing.data());
        const cl::Buffer states_buffer(st_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                                       passing_states.size() * sizeof(cl_int4), passing_states.data());
        carryOut(passing_lines, states_buffer, offsets, carry_in, 1);
      }
      waiting.swap(next_waiting);
      const std::size_t plane = field_.pixelCount();
      if (outputs_.horizon_angles) readRows(angles_, result_.angles, s0, s1, k * plane);
      if (outputs_.horizon_distances) readRows(distances_, result_.distances, s0, s1, k * plane);
      readSkySumRows(s0, s1);
      copyEnvironmentRows(s0, s1);
      if (!receiver_positions_.empty()) {  // the strip's receivers' positions, for the strips after
        const std::size_t width = field_.width;
        st_.queue.enqueueReadBuffer(receiver_base_, CL_TRUE, (s0 - row0) * width * sizeof(float),
                                    (s1 - s0) * width * sizeof(float), &receiver_positions_[s0 * width]);
      }
      carry_in = carried ? carry_out : placeholder_;
      carried_in = carried;
      if (horizon_.strip_progress) horizon_.strip_progress(step + 1, strips);
    }
  }

  // Stack entries the device's largest single buffer holds.
  std::size_t maxAllocationEntries() const {
    return (st_.info.max_allocation_bytes ? st_.info.max_allocation_bytes : plan_.budget) / kStackEntryBytes;
  }

  // Stacks of `entries` do not fit beside the strips, which would need to leave `rest` bytes: the
  // strips to try instead (at most half as tall, leaving 1.25 times that), 0 when none would do.
  [[noreturn]] void failCarry(const std::string& what, std::size_t entries, std::size_t rest) const {
    const std::size_t room = rest / 4 * 5;
    const std::size_t fitting =
        plan_.budget > plan_.halo_bytes + room ? (plan_.budget - plan_.halo_bytes - room) / plan_.per_row : 0;
    throw StacksBeyondStrips(what + " needs " + mebibytes(entries * kStackEntryBytes) +
                                 " of device memory, more than the budget leaves beside strips of " +
                                 std::to_string(plan_.strip_rows) + " rows; raise the memory budget",
                             static_cast<int>(std::min<std::size_t>(plan_.strip_rows / 2, fitting)));
  }

  void launchNaive(const RunDirection& d, cl_uint plane_offset) {
    NamedKernel kernel(st_, program_, "horizon_naive");
    kernel.set("heights", heights_);
    kernel.set("width", field_.width);
    kernel.set("height", field_.height);
    kernel.set("dir_x", d.ray.dir_x);
    kernel.set("dir_y", d.ray.dir_y);
    kernel.set("step_length", d.ray.step_length);
    kernel.set("ground_per_pixel", d.ray.ground_per_pixel);
    kernel.set("drop", curvatureDrop(rayUnit(d.ray.ground_per_pixel)));
    kernel.set("max_steps", d.max_steps);
    kernel.set("max_reach", !hasRowSpacing(field_) && horizon_.max_distance > 0.0
                                ? static_cast<float>(horizon_.max_distance / d.ray.ground_per_pixel)
                                : std::numeric_limits<float>::infinity());
    kernel.set("max_ground", hasRowSpacing(field_) && horizon_.max_distance > 0.0
                                 ? static_cast<float>(horizon_.max_distance)
                                 : std::numeric_limits<float>::infinity());
    const auto row_tables = setRowTables(kernel, d, false);
    setOutputs(kernel, d, plane_offset);
    st_.launch(kernel, cl::NDRange(roundUp(field_.width, kTileX), roundUp(field_.height, kTileY)),
               cl::NDRange(kTileX, kTileY));
  }

  const HorizonOptions& horizon_;  // options_ as the horizon operation's
  const HorizonOutputs& outputs_;
  int lanes_ = 1;  // HFVIS_LANES of the program
  std::vector<RunDirection> directions_;
  RunPlan plan_;
  HorizonResult result_;
  std::vector<float> receiver_positions_;  // strips, per-row spacing and a maximum distance: receiver_base's
  // With the error estimate: the odd directions' sums (device, and the host's in strips).
  cl::Buffer svf_odd_, ao_odd_;
  std::vector<float> svf_odd_host_, ao_odd_host_;
  cl::Buffer angles_, distances_, svf_, ao_, normals_, stacks_, window_far_, receiver_base_, row_cells_,
      placeholder_, env_sum_, env_tables_;
};

// The field's tiles of side x side pixels (HorizonOptions::error_tile; 0: the whole field in
// one), row-major; a tile's pixels are found from its rectangle, not kept in lists (those took 8
// bytes a pixel, even with one tile for the whole field).
struct ErrorTiles {
  ErrorTiles(const HeightField& field, int error_tile)
      : width(field.width),
        height(field.height),
        // (a tile past the field is the whole field: kept within it, so that the sums below stay
        // within int, which error_tile near INT_MAX overflowed)
        side(std::min(error_tile > 0 ? error_tile : INT_MAX, std::max(field.width, field.height))),
        across((width + side - 1) / side),
        count(across * ((height + side - 1) / side)) {}
  int of(std::size_t p) const {
    return static_cast<int>(p / width) / side * across + static_cast<int>(p % width) / side;
  }
  // visit(p) for the pixels of tile t, row by row.
  template <class Visit>
  void forEachPixel(int t, Visit&& visit) const {
    const int r0 = t / across * side, c0 = t % across * side;
    for (int r = r0; r < std::min(height, r0 + side); ++r)
      for (int c = c0; c < std::min(width, c0 + side); ++c) visit(static_cast<std::size_t>(r) * width + c);
  }
  // The values of `plane` at the pixels of tile t.
  std::vector<float> values(const std::vector<float>& plane, int t) const {
    std::vector<float> out;
    forEachPixel(t, [&](std::size_t p) { out.push_back(plane[p]); });
    return out;
  }
  int width, height, side, across, count;
};

// HorizonOptions::max_error: the whole field at kFirstAutoDirections, then, while the error
// estimate's 99th percentile over the field exceeds max_error, tiles again at the K
// nextDirectionsForError asks for after their own runs, those of one K in one run over the lines
// that reach them: the tiles with the most pixels above max_error first, until those left hold at
// most half the pixels the field's percentile lets above it (error_tile 0: one tile, K not rounded
// to the ladder). Each pixel's estimate is its run's raw one (splitErrorHalves) divided by
// richardsonDivisor at the order its tile's runs measure (estimateOrder). `run(K, wanted)`: a run
// at K with the raw error estimate over the lines that reach the pixels of `wanted` (null: the
// whole field).
HorizonResult runToError(const HeightField& field, const HorizonOptions& options,
                         const std::function<HorizonResult(int, const std::vector<char>*)>& run) {
  const ErrorTiles grid(field, options.error_tile);
  const int tiles = grid.count;
  const std::size_t pixels = field.pixelCount();
  std::vector<std::vector<EstimateRun>> history(tiles);  // per tile, the runs its pixels took
  std::vector<double> divisor(tiles, 1.0);
  // A run at K over the tiles of `chosen`: their raw estimates' percentiles recorded, and the
  // divisor of their order.
  const auto record = [&](const std::vector<float>& raw, int directions, const std::vector<char>& chosen) {
    for (int t = 0; t < tiles; ++t) {
      if (!chosen[t]) continue;
      history[t].push_back({directions, estimatedError(grid.values(raw, t))});
      divisor[t] = richardsonDivisor(estimateOrder(history[t]));
    }
  };
  HorizonResult result = run(kFirstAutoDirections, nullptr);
  result.runs = {kFirstAutoDirections};
  result.pixel_directions.assign(pixels, kFirstAutoDirections);
  record(result.error_estimate, kFirstAutoDirections, std::vector<char>(tiles, 1));
  for (std::size_t p = 0; p < pixels; ++p)
    result.error_estimate[p] = static_cast<float>(result.error_estimate[p] / divisor[grid.of(p)]);
  double work = result.samples_per_receiver;
  const std::vector<int> ladder = directionLadder();
  // Pixels with data the 99th percentile (estimatedError) lets lie above it.
  const std::size_t with_data = static_cast<std::size_t>(std::count_if(
      result.error_estimate.begin(), result.error_estimate.end(), [](float e) { return !std::isnan(e); }));
  const std::size_t allowed =
      with_data ? with_data - 1 - std::min(with_data - 1, static_cast<std::size_t>(0.99 * with_data)) : 0;
  for (;;) {
    std::vector<std::size_t> above(tiles, 0);
    for (std::size_t p = 0; p < pixels; ++p)
      above[grid.of(p)] += result.error_estimate[p] > options.max_error;  // (NaN: not above)
    std::size_t left = std::accumulate(above.begin(), above.end(), std::size_t{0});
    if (left <= allowed) break;
    std::vector<int> order(tiles);
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int x, int y) { return above[x] > above[y]; });
    std::map<int, std::vector<char>> next;  // K -> the tiles to run at it
    for (int t : order) {
      if (left <= allowed / 2 || above[t] == 0) break;
      left -= above[t];
      const NextErrorRun asked = nextDirectionsForError(history[t], options.max_error);
      if (asked.predicted > kMaxAutoDirections)
        throw beyondAutoDirections(options.max_error, asked.predicted, history[t].back().directions,
                                   estimatedError(grid.values(result.error_estimate, t)),
                                   tiles > 1 ? " in the tile of pixels from column " +
                                                   std::to_string(t % grid.across * grid.side) + ", row " +
                                                   std::to_string(t / grid.across * grid.side)
                                             : std::string());
      int directions = asked.directions;
      if (options.error_tile > 0) directions = *std::lower_bound(ladder.begin(), ladder.end(), directions);
      std::vector<char>& chosen = next[directions];
      chosen.resize(tiles, 0);
      chosen[t] = 1;
    }
    for (const auto& run_tiles : next) {
      // (not a structured binding: the lambdas below capture it, which C++17 does not allow)
      const int directions = run_tiles.first;
      const auto& chosen = run_tiles.second;
      const bool all = std::count(chosen.begin(), chosen.end(), 1) == tiles;
      std::vector<char> wanted;
      if (!all) {
        wanted.assign(pixels, 0);
        for (int t = 0; t < tiles; ++t)
          if (chosen[t]) grid.forEachPixel(t, [&](std::size_t p) { wanted[p] = 1; });
      }
      HorizonResult part = run(directions, all ? nullptr : &wanted);
      result.runs.push_back(directions);
      work += part.samples_per_receiver;
      record(part.error_estimate, directions, chosen);
      for (int t = 0; t < tiles; ++t) {
        if (!chosen[t]) continue;
        grid.forEachPixel(t, [&](std::size_t p) {
          if (!result.sky_view_factor.empty()) result.sky_view_factor[p] = part.sky_view_factor[p];
          if (!result.ambient_occlusion.empty()) result.ambient_occlusion[p] = part.ambient_occlusion[p];
          result.error_estimate[p] = static_cast<float>(part.error_estimate[p] / divisor[t]);
          result.pixel_directions[p] = directions;
        });
      }
      if (directions > result.directions) {
        result.directions = directions;
        result.azimuths = std::move(part.azimuths);
      }
    }
  }
  const auto [least, most] = std::minmax_element(divisor.begin(), divisor.end());
  result.richardson_divisor_least = *least;
  result.richardson_divisor_most = *most;
  result.estimated_error = estimatedError(result.error_estimate);
  result.samples_per_receiver = work;
  return result;
}

// One run of the routine (its hull stacks retried in thinner strips).
HorizonResult runHorizonRoutine(ContextState& st, const HeightField& field, HorizonOptions& attempt,
                                const HorizonOutputs& outputs, const std::vector<char>* pixels,
                                const DirectionSubset* subset) {
  // Hull stacks too deep for the room strips leave: again from the start with thinner strips
  // (StacksBeyondStrips::rows), as the sums of the strips done cannot be taken back.
  for (;;) {
    try {
      HorizonRoutine routine(st, field, attempt, outputs, pixels, subset);
      routine.run();
      return routine.take();
    } catch (const StacksBeyondStrips& error) {
      if (error.rows < 1) throw MemoryBudgetError(error.what());
      attempt.strip_rows = error.rows;
    }
  }
}

}  // namespace

HorizonResult computeHorizonDirections(const ComputeContext& context, const HeightField& field,
                                       const HorizonOptions& options, const HorizonOutputs& outputs,
                                       const DirectionSubset& subset) {
  validate(field);
  HorizonOptions attempt = options;
  attempt.directions = static_cast<int>(subset.indices.size());
  validate(attempt, outputs);
  checkPixelIndexing(field, 1);
  return translateOpenClErrors(
      [&] { return runHorizonRoutine(stateOf(context), field, attempt, outputs, nullptr, &subset); });
}

}  // namespace detail

HorizonResult computeHorizons(const ComputeContext& context, const HeightField& field,
                              const HorizonOptions& options, const HorizonOutputs& outputs) {
  validate(field);
  validate(options, outputs);
  // The environment's sums: a plane per channel, indexed in 32 bits in the kernels.
  detail::checkPixelIndexing(field, outputs.environment ? outputs.environment->channels : 1);
  if (outputs.environment && detail::hasRowSpacing(field))
    throw InvalidArgument(
        "environment lighting takes a field of one cell size: this latitude / longitude grid's spacing "
        "differs "
        "by row (reproject it, or give the cell size)");
  return detail::translateOpenClErrors([&] {
    HorizonOptions attempt = options;
    const auto run = [&](const HorizonOutputs& wanted, const std::vector<char>* pixels,
                         const detail::DirectionSubset* subset = nullptr) {
      return detail::runHorizonRoutine(detail::stateOf(context), field, attempt, wanted, pixels, subset);
    };
    if (outputs.horizon_angles && (options.max_error != 0.0 || outputs.error_estimate)) {
      // The horizon angles' own error, from their planes on the host (core/horizon_angle_error.hpp).
      HorizonOutputs planes = outputs;
      planes.error_estimate = false;
      const auto estimated = [&](int directions, HorizonResult* from) {
        HorizonResult result;
        if (!from) {
          attempt.directions = directions;
          result = run(planes, nullptr);
        } else {
          result = detail::extendHorizonRun(std::move(*from), directions, [&](const std::vector<int>& indices) {
            const detail::DirectionSubset subset{directions, indices};
            attempt.directions = static_cast<int>(indices.size());
            return run(planes, nullptr, &subset);
          });
        }
        detail::estimateHorizonAngleError(result);
        return result;
      };
      if (options.max_error == 0.0) return estimated(options.directions, nullptr);
      // (a run extends only with the sweep: a subset of directions is the sweep's, whose lattice
      // steps a direction's azimuth alone chooses)
      return detail::runHorizonAnglesToError(
          options.max_error, estimated,
          [&](int directions) { return detail::horizonWork(field, options, planes, directions); },
          options.method == HorizonMethod::Sweep);
    }
    if (options.max_error == 0.0) return run(outputs, nullptr);
    // Ask for an error: runs at growing K until the estimate meets it (HorizonOptions::max_error).
    HorizonOutputs estimated = outputs;
    estimated.error_estimate = true;
    return detail::runToError(field, options, [&](int directions, const std::vector<char>* wanted) {
      attempt.directions = directions;
      return run(estimated, wanted);
    });
  });
}

}  // namespace hfvis
