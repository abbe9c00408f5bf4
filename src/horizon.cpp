// horizon.cpp: the horizon operation on the device. Per direction, one launch of the
// lattice sweep (receiver-exact hull stacks, reduced straight into the requested outputs)
// or of the naive march; per batch of directions, the requested planes are downloaded.
#include "hfvis/horizon.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "fast_math.hpp"
#include "hfvis/errors.hpp"
#include "horizon_common.hpp"
#include "lattice_geometry.hpp"
#include "opencl_context.hpp"
#include "sweep_framework.hpp"
#include "sweep_routine.hpp"

namespace hfvis {
namespace detail {
namespace {

constexpr std::size_t kStackEntryBytes = 2 * sizeof(float);  // (height, position)

// Lines one work-item of horizon_lattice sweeps side by side (HFVIS_LANES): SIMD lanes
// where a work-item runs on a CPU core in the line-major layout; one line per work-item on
// GPUs (whatever the layout: a lane-wide work-item would run alone in its group there) and in
// the step-major layout, whose neighbouring work-items read neighbouring stack entries.
int sweepLanes(const ContextState& st) { return lineMajorLayout(st) && st.info.type == "CPU" ? 8 : 1; }

std::string programOptions(const HorizonOutputs& outputs, bool has_nodata, int lanes, bool curvature,
                           bool max_distance, bool row_spacing) {
  std::ostringstream s;
  s << "-DHFVIS_LANES=" << lanes << " -DHFVIS_HAS_NODATA=" << has_nodata << " -DHFVIS_CURVATURE=" << curvature
    << " -DHFVIS_MAX_DISTANCE=" << max_distance << " -DHFVIS_ROW_SPACING=" << row_spacing
    << " -DHFVIS_WANT_ANGLES=" << outputs.horizon_angles
    << " -DHFVIS_WANT_DISTANCES=" << outputs.horizon_distances
    << " -DHFVIS_WANT_SVF=" << outputs.sky_view_factor << " -DHFVIS_WANT_AO=" << outputs.ambient_occlusion;
  return s.str();
}

// One direction of a run, whichever method: what the kernels and the outputs need.
struct RunDirection {
  LatticeDirection lattice;  // sweep (azimuth and weight for both methods)
  SweepDirection ray;        // naive march
  std::vector<LatticeSample> samples;
  float cos_azimuth = 1.0f, sin_azimuth = 0.0f;  // as the scalar reference rounds them
  std::vector<LatticeLine> lines;                // sweep: the direction's lines over the field
  LatticeWindow window;                          // sweep: the maximum distance along its lines
  int max_steps = kAllSteps;                     // naive march: the steps within the maximum distance
  // Per-row spacing: ground length and terms by row (latticeRowTables, rayRowTables).
  std::vector<float> row_length, row_terms;
};

// How a run uses its device memory budget: directions per downloaded batch of planes and
// the hull-stack scratch (entries) every launch of the sweep shares.
struct RunPlan {
  int directions_per_batch = 1;
  std::size_t stack_entries = 0;
};

RunPlan planRun(const HeightField& field, const HorizonOptions& options, const HorizonOutputs& outputs,
                const std::vector<RunDirection>& directions, const DeviceInfo& device) {
  const bool sweep = options.method == HorizonMethod::Sweep;
  const std::size_t budget =
      options.memory_budget_bytes ? options.memory_budget_bytes : defaultMemoryBudget(device);
  const std::size_t max_alloc = device.max_allocation_bytes ? device.max_allocation_bytes : budget;
  const std::size_t plane = field.pixelCount() * sizeof(float);
  // Heights, the sums, the normals' two slopes, the window's float2 per pixel.
  const std::size_t fixed = plane * (1 + outputs.sky_view_factor + outputs.ambient_occlusion * 3 +
                                     (sweep && options.max_distance > 0.0) * 2);
  const std::size_t per_direction = plane * (outputs.horizon_angles + outputs.horizon_distances);
  // Scratch: all of a direction's stacks in one launch when it fits; one line at a time at least.
  std::size_t whole = 0, longest = 0;
  if (sweep) {
    for (const RunDirection& d : directions) {
      std::size_t total = 0;
      for (const LatticeLine& line : d.lines) {
        const std::size_t capacity = lineCapacity(line, d.samples.size());
        total += capacity;
        longest = std::max(longest, capacity);
      }
      whole = std::max(whole, total);
    }
  }
  auto fail = [&](std::size_t need) {
    throw MemoryBudgetError("one direction needs " + mebibytes(need) +
                            " of device memory but the budget is " + mebibytes(budget) +
                            " (largest single buffer " + mebibytes(max_alloc) +
                            "); raise the memory budget or use a smaller field");
  };
  const std::size_t least = fixed + per_direction + longest * kStackEntryBytes;
  if (least > budget || per_direction > max_alloc || longest * kStackEntryBytes > max_alloc) fail(least);
  const std::size_t available = budget - fixed;
  RunPlan plan;
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

std::vector<RunDirection> runDirectionsOf(const HeightField& field, const HorizonOptions& options,
                                          const HorizonOutputs& outputs) {
  std::vector<RunDirection> out;
  if (options.method == HorizonMethod::Sweep) {
    const std::vector<LatticeDirection> directions = horizonDirections(field, options, outputs);
    std::vector<RowTable> rows;
    if (hasRowSpacing(field)) rows = latticeRowTables(field, directions, !exactAzimuths(outputs));
    for (std::size_t k = 0; k < directions.size(); ++k) {
      const LatticeDirection& d = directions[k];
      out.push_back({d, SweepDirection{}, latticeSamples(d, options.samples_per_unit),
                     static_cast<float>(std::cos(d.azimuth)), static_cast<float>(std::sin(d.azimuth)),
                     latticeLines(d, field.width, field.height), latticeWindow(field, d, options.max_distance)});
      if (!rows.empty()) {
        out.back().row_length = std::move(rows[k].length);
        out.back().row_terms = std::move(rows[k].terms);
      }
    }
  } else {
    const std::vector<SweepDirection> rays = runDirections(field, options);
    std::vector<RowTable> rows;
    if (hasRowSpacing(field)) rows = rayRowTables(field, rays);
    for (int k = 0; k < options.directions; ++k) {
      const SweepDirection& d = rays[k];
      RunDirection r;
      r.ray = d;
      r.lattice.azimuth = directionAzimuth(k, options);
      r.lattice.weight = 1.0 / options.directions;
      r.cos_azimuth = d.cos_azimuth;
      r.sin_azimuth = d.sin_azimuth;
      r.max_steps = stepsWithin(options.max_distance, double(d.step_length) * d.ground_per_pixel);
      if (!rows.empty()) {
        r.row_length = std::move(rows[k].length);
        r.row_terms = std::move(rows[k].terms);
      }
      out.push_back(r);
    }
  }
  return out;
}

class HorizonRoutine : public SweepRoutine {
 public:
  HorizonRoutine(ContextState& st, const HeightField& field, const HorizonOptions& options,
                 const HorizonOutputs& outputs)
      : SweepRoutine(st, field, options), horizon_(options), outputs_(outputs) {}

  HorizonResult take() { return std::move(result_); }

 private:
  std::string programFile() const override { return "horizon.cl"; }
  std::string programOptions() const override {
    return detail::programOptions(outputs_, prepared_.has_nodata, sweepLanes(st_), horizon_.curvature != 0.0,
                                  horizon_.max_distance > 0.0, hasRowSpacing(field_));
  }

  void allocate() override {
    lanes_ = sweepLanes(st_);
    directions_ = runDirectionsOf(field_, horizon_, outputs_);
    const RunPlan plan = planRun(field_, horizon_, outputs_, directions_, st_.info);
    batch_ = plan.directions_per_batch;
    result_ = allocateResult(field_, horizon_, outputs_);
    for (int k = 0; k < horizon_.directions; ++k) result_.azimuths[k] = directions_[k].lattice.azimuth;
    const std::size_t plane = field_.pixelCount();
    const std::size_t planes_bytes = plan.directions_per_batch * plane * sizeof(float);
    angles_ = st_.reusableBuffer("horizon angles", outputs_.horizon_angles ? planes_bytes : 0);
    distances_ = st_.reusableBuffer("horizon distances", outputs_.horizon_distances ? planes_bytes : 0);
    svf_ = zeros(outputs_.sky_view_factor ? plane : 0);
    ao_ = zeros(outputs_.ambient_occlusion ? plane : 0);
    normals_ = deviceBuffer(st_, outputs_.ambient_occlusion ? 2 * plane * sizeof(float) : 0);
    stacks_ = st_.reusableBuffer("lattice stacks", plan.stack_entries * kStackEntryBytes);
    const bool window = horizon_.method == HorizonMethod::Sweep && horizon_.max_distance > 0.0;
    window_far_ = deviceBuffer(st_, window ? 2 * plane * sizeof(float) : 0);
    stack_entries_ = plan.stack_entries;
    if (outputs_.ambient_occlusion) {
      cl::Kernel normals(program_, "pixel_normals");
      normals.setArg(0, heights_);
      normals.setArg(1, field_.width);
      normals.setArg(2, field_.height);
      normals.setArg(3, static_cast<float>(field_.cell_size_x));
      normals.setArg(4, static_cast<float>(field_.cell_size_y));
      const cl::Buffer row_cells = rowCells();
      normals.setArg(5, row_cells);
      normals.setArg(6, normals_);
      st_.launch(normals, cl::NDRange(roundUp(field_.width, kTileX), roundUp(field_.height, kTileY)),
                 cl::NDRange(kTileX, kTileY));
    }
  }

  int directionCount() const override { return horizon_.directions; }
  int batchSize() const override { return batch_; }

  void sweep(int k, int slot) override {
    const RunDirection& d = directions_[k];
    const bool planes = outputs_.horizon_angles || outputs_.horizon_distances;
    if (d.lattice.weight == 0.0 && !planes) return;  // merged into an equal step (latticeDirections)
    const cl_uint plane_offset = static_cast<cl_uint>(slot * field_.pixelCount());
    if (horizon_.method == HorizonMethod::Sweep) {
      launchSweep(d, plane_offset);
    } else {
      launchNaive(d, plane_offset);
    }
  }

  void endBatch(int first, int count) override {
    const std::size_t plane = field_.pixelCount();
    const std::size_t batch_bytes = count * plane * sizeof(float), at = first * plane;
    if (outputs_.horizon_angles) st_.queue.enqueueReadBuffer(angles_, CL_TRUE, 0, batch_bytes, &result_.angles[at]);
    if (outputs_.horizon_distances)
      st_.queue.enqueueReadBuffer(distances_, CL_TRUE, 0, batch_bytes, &result_.distances[at]);
  }

  void finish() override {
    const std::size_t bytes = field_.pixelCount() * sizeof(float);
    if (outputs_.sky_view_factor)
      st_.queue.enqueueReadBuffer(svf_, CL_TRUE, 0, bytes, result_.sky_view_factor.data());
    if (outputs_.ambient_occlusion) {
      cl::Kernel scale(program_, "occlusion_scale");
      scale.setArg(0, normals_);
      scale.setArg(1, static_cast<cl_uint>(field_.pixelCount()));
      scale.setArg(2, ao_);
      st_.launch(scale, cl::NDRange(roundUp(field_.pixelCount(), kLineGroup)), cl::NDRange(kLineGroup));
      st_.queue.enqueueReadBuffer(ao_, CL_TRUE, 0, bytes, result_.ambient_occlusion.data());
    }
    finishReduction(result_);
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

  // The unit of positions along lines and rays: pixels of that ground length, or (per-row
  // spacing) ground units.
  double positionUnit(double ground_per_pixel) const { return hasRowSpacing(field_) ? 1.0 : ground_per_pixel; }

  // The per-row tables of a direction (placeholders without per-row spacing), set as the
  // kernel's arguments `arg` and `arg + 1`; the caller keeps them until the launch.
  std::array<cl::Buffer, 2> setRowTables(cl::Kernel& kernel, int arg, const RunDirection& d) {
    auto table = [&](const std::vector<float>& values) {
      if (values.empty()) return deviceBuffer(st_, 0);
      return cl::Buffer(st_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, values.size() * sizeof(float),
                        const_cast<float*>(values.data()));
    };
    std::array<cl::Buffer, 2> tables{table(d.row_length), table(d.row_terms)};
    kernel.setArg(arg, tables[0]);
    kernel.setArg(arg + 1, tables[1]);
    return tables;
  }

  // The arguments every direction's kernel ends with: its outputs.
  void setOutputs(cl::Kernel& kernel, int arg, const RunDirection& d, cl_uint plane_offset) {
    kernel.setArg(arg++, d.cos_azimuth);
    kernel.setArg(arg++, d.sin_azimuth);
    kernel.setArg(arg++, static_cast<float>(d.lattice.weight));
    kernel.setArg(arg++, swathFactor(static_cast<float>(d.lattice.weight)));
    kernel.setArg(arg++, plane_offset);
    if (horizon_.method == HorizonMethod::Sweep) {
      kernel.setArg(arg++, stacks_);
      stride_arg_ = arg++;  // set per chunk (launchLineChunks)
      kernel.setArg(arg++, window_far_);
    }
    kernel.setArg(arg++, normals_);
    kernel.setArg(arg++, angles_);
    kernel.setArg(arg++, distances_);
    kernel.setArg(arg++, svf_);
    kernel.setArg(arg++, ao_);
  }

  void launchSweep(const RunDirection& d, cl_uint plane_offset) {
    cl::Buffer samples(st_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                       d.samples.size() * sizeof(LatticeSample),
                       const_cast<LatticeSample*>(d.samples.data()));
    cl::Kernel kernel(program_, "horizon_lattice");
    kernel.setArg(0, heights_);
    kernel.setArg(1, field_.width);
    kernel.setArg(2, field_.height);
    kernel.setArg(5, samples);
    kernel.setArg(6, static_cast<int>(d.samples.size()));
    kernel.setArg(7, d.lattice.a);
    kernel.setArg(8, d.lattice.b);
    kernel.setArg(9, static_cast<float>(d.lattice.period));
    const double unit = positionUnit(d.lattice.ground_per_pixel);
    kernel.setArg(10, static_cast<float>(unit));
    kernel.setArg(11, static_cast<float>(d.lattice.period * d.lattice.ground_per_pixel));
    kernel.setArg(12, curvatureDrop(unit));
    kernel.setArg(13, d.window.window);
    kernel.setArg(14, d.window.inv_window);
    const auto row_tables = setRowTables(kernel, 15, d);
    setOutputs(kernel, 17, d, plane_offset);
    LineChunkArguments chunk;
    chunk.lines = 3;
    chunk.count = 4;
    chunk.stride = stride_arg_;
    // With lanes, groups of one work-item: 64 work-items of 8 lines would put all of a
    // 512-line direction in one group, on one core.
    launchLineChunks(st_, kernel, d.lines, d.samples.size(), stack_entries_, chunk, lanes_,
                     lanes_ > 1 ? 1 : kLineGroup);
  }

  void launchNaive(const RunDirection& d, cl_uint plane_offset) {
    cl::Kernel kernel(program_, "horizon_naive");
    kernel.setArg(0, heights_);
    kernel.setArg(1, field_.width);
    kernel.setArg(2, field_.height);
    kernel.setArg(3, d.ray.dir_x);
    kernel.setArg(4, d.ray.dir_y);
    kernel.setArg(5, d.ray.step_length);
    kernel.setArg(6, d.ray.ground_per_pixel);
    kernel.setArg(7, curvatureDrop(positionUnit(d.ray.ground_per_pixel)));
    kernel.setArg(8, d.max_steps);
    const auto row_tables = setRowTables(kernel, 9, d);
    setOutputs(kernel, 11, d, plane_offset);
    st_.launch(kernel, cl::NDRange(roundUp(field_.width, kTileX), roundUp(field_.height, kTileY)),
               cl::NDRange(kTileX, kTileY));
  }

  const HorizonOptions& horizon_;  // options_ as the horizon operation's
  const HorizonOutputs& outputs_;
  std::vector<RunDirection> directions_;
  HorizonResult result_;
  int batch_ = 1;
  cl::Buffer angles_, distances_, svf_, ao_, normals_, stacks_, window_far_;
  std::size_t stack_entries_ = 0;
  int stride_arg_ = 0;  // horizon_lattice's `stride` argument
  int lanes_ = 1;       // HFVIS_LANES of the program
};

}  // namespace
}  // namespace detail

HorizonResult computeHorizons(const ComputeContext& context, const HeightField& field,
                              const HorizonOptions& options, const HorizonOutputs& outputs) {
  validate(field);
  validate(options, outputs);
  detail::requireSupported(field, options);
  detail::checkPixelIndexing(field, 1);
  return detail::translateOpenClErrors([&] {
    detail::HorizonRoutine routine(detail::stateOf(context), field, options, outputs);
    routine.run();
    return routine.take();
  });
}

}  // namespace hfvis
