// horizon.cpp: the horizon operation on the device: batching directions under a memory
// budget, launching presample -> hull-stack sweep -> reduction (or the naive march), and
// downloading only the requested outputs.
#include "hfvis/horizon.hpp"

#include <algorithm>
#include <sstream>

#include "hfvis/errors.hpp"
#include "horizon_common.hpp"
#include "horizon_device.hpp"
#include "opencl_context.hpp"

namespace hfvis {
namespace detail {
namespace {

constexpr int kMaxBatch = 32;  // directions per batch: bounds kernel time, gives progress
constexpr std::size_t kLineGroup = 64;
constexpr std::size_t kTileX = 16, kTileY = 4;

std::size_t roundUp(std::size_t n, std::size_t m) { return (n + m - 1) / m * m; }

std::string mib(std::size_t bytes) {
  std::ostringstream s;
  s.precision(1);
  s << std::fixed << bytes / (1024.0 * 1024.0) << " MiB";
  return s.str();
}

std::string programOptions(const HorizonOptions& options, const HorizonOutputs& outputs, bool has_nodata) {
  std::ostringstream s;
  s << "-DHFVIS_HAS_NODATA=" << has_nodata << " -DHFVIS_WANT_ANGLES=" << outputs.horizon_angles
    << " -DHFVIS_WANT_DISTANCES=" << outputs.horizon_distances << " -DHFVIS_WANT_SVF=" << outputs.sky_view_factor
    << " -DHFVIS_WANT_AO=" << outputs.ambient_occlusion << " -DHFVIS_DIRECTIONS=" << options.directions;
  return s.str();
}

// A batch: directions [first, first + count) with their buffer offsets set.
struct Batch {
  int first = 0;
  std::vector<SweepDirection> directions;
  std::size_t entries = 0;  // line-buffer entries of the whole batch
};

// Splits the run into batches whose device memory stays within the budget.
std::vector<Batch> planBatches(const std::vector<SweepDirection>& all, const HorizonOptions& options,
                               const HorizonOutputs& outputs, const DeviceInfo& device, std::size_t plane,
                               bool needs_line_buffers) {
  std::size_t budget = options.memory_budget_bytes;
  if (budget == 0) budget = std::min<std::size_t>(std::size_t(1) << 30, device.global_memory_bytes / 2);
  const std::size_t max_alloc = device.max_allocation_bytes ? device.max_allocation_bytes : budget;
  const std::size_t fixed = plane * sizeof(float) * (1 + outputs.sky_view_factor + outputs.ambient_occlusion);
  const std::size_t per_plane = plane * sizeof(float) * (outputs.horizon_angles + outputs.horizon_distances);
  // Line buffer and hull stacks, two floats per entry each.
  const std::size_t per_entry = needs_line_buffers ? 2 * 2 * sizeof(float) : 0;
  std::vector<Batch> batches;
  Batch batch;
  std::size_t used = fixed;
  for (std::size_t k = 0; k < all.size(); ++k) {
    const std::size_t entries = needs_line_buffers ? all[k].entries() : 0;
    const std::size_t need = entries * per_entry + per_plane + sizeof(SweepDirection);
    const bool fits = used + need <= budget && (batch.entries + entries) * 2 * sizeof(float) <= max_alloc &&
                      batch.entries + entries < (std::size_t(1) << 31) &&
                      (batch.directions.size() + 1) * per_plane <= max_alloc;
    if (!fits && batch.directions.empty()) {
      throw MemoryBudgetError("one direction needs " + mib(fixed + need) + " of device memory but the budget is " +
                              mib(budget) + " (largest single buffer " + mib(max_alloc) +
                              "); raise the memory budget or use a smaller field");
    }
    if (!fits || static_cast<int>(batch.directions.size()) == kMaxBatch) {
      batches.push_back(batch);
      batch = Batch{static_cast<int>(k), {}, 0};
      used = fixed;
    }
    SweepDirection d = all[k];
    d.buffer_offset = static_cast<std::uint32_t>(batch.entries);
    batch.directions.push_back(d);
    batch.entries += entries;
    used += need;
  }
  batches.push_back(batch);
  return batches;
}

cl::Buffer deviceBuffer(ContextState& st, std::size_t bytes) {
  return cl::Buffer(st.context, CL_MEM_READ_WRITE, std::max<std::size_t>(bytes, sizeof(float)));
}

cl::Buffer uploadDirections(ContextState& st, const std::vector<SweepDirection>& directions) {
  return cl::Buffer(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, directions.size() * sizeof(SweepDirection),
                    const_cast<SweepDirection*>(directions.data()));
}

int maxLines(const std::vector<SweepDirection>& ds) {
  int n = 0;
  for (const auto& d : ds) n = std::max(n, d.n_lines);
  return n;
}

int maxSteps(const std::vector<SweepDirection>& ds) {
  int n = 0;
  for (const auto& d : ds) n = std::max(n, d.n_steps);
  return n;
}

// Launches presample_lines and, when `sweep`, horizon_sweep over one batch.
void enqueueSweep(ContextState& st, cl::Program& program, const cl::Buffer& heights, const HeightField& field,
                  const cl::Buffer& directions, const std::vector<SweepDirection>& batch, const cl::Buffer& lines,
                  const cl::Buffer& stacks, bool sweep) {
  const std::size_t lines_global = roundUp(maxLines(batch), kLineGroup);
  cl::Kernel presample(program, "presample_lines");
  presample.setArg(0, heights);
  presample.setArg(1, field.width);
  presample.setArg(2, field.height);
  presample.setArg(3, directions);
  presample.setArg(4, lines);
  st.queue.enqueueNDRangeKernel(presample, cl::NullRange,
                                cl::NDRange(lines_global, maxSteps(batch), batch.size()),
                                cl::NDRange(kLineGroup, 1, 1));
  if (!sweep) return;
  cl::Kernel hull(program, "horizon_sweep");
  hull.setArg(0, directions);
  hull.setArg(1, lines);
  hull.setArg(2, stacks);
  st.queue.enqueueNDRangeKernel(hull, cl::NullRange, cl::NDRange(lines_global, batch.size()),
                                cl::NDRange(kLineGroup, 1));
}

HorizonResult run(const ComputeContext& context, const HeightField& field, const HorizonOptions& options,
                  const HorizonOutputs& outputs) {
  ContextState& st = context.state();
  const PreparedHeights prepared = prepareHeights(field);
  const bool sweep = options.method == HorizonMethod::Sweep;
  cl::Program program = st.program("horizon.cl", programOptions(options, outputs, prepared.has_nodata));
  const std::size_t plane = field.pixelCount();
  const auto batches =
      planBatches(runDirections(field, options), options, outputs, st.info, plane, sweep);

  HorizonResult result = allocateResult(field, options, outputs);
  cl::Buffer heights(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, plane * sizeof(float),
                     const_cast<float*>(prepared.heights.data()));
  const std::size_t max_batch_entries =
      std::max_element(batches.begin(), batches.end(), [](auto& a, auto& b) { return a.entries < b.entries; })->entries;
  const std::size_t max_batch_size =
      std::max_element(batches.begin(), batches.end(), [](auto& a, auto& b) {
        return a.directions.size() < b.directions.size();
      })->directions.size();
  cl::Buffer lines, stacks;
  if (sweep) {
    lines = deviceBuffer(st, max_batch_entries * 2 * sizeof(float));
    stacks = deviceBuffer(st, max_batch_entries * 2 * sizeof(float));
  }
  cl::Buffer angles = deviceBuffer(st, outputs.horizon_angles ? max_batch_size * plane * sizeof(float) : 0);
  cl::Buffer distances = deviceBuffer(st, outputs.horizon_distances ? max_batch_size * plane * sizeof(float) : 0);
  cl::Buffer svf = deviceBuffer(st, outputs.sky_view_factor ? plane * sizeof(float) : 0);
  cl::Buffer ao = deviceBuffer(st, outputs.ambient_occlusion ? plane * sizeof(float) : 0);
  const float zero = 0.0f;
  if (outputs.sky_view_factor) st.queue.enqueueFillBuffer(svf, zero, 0, plane * sizeof(float));
  if (outputs.ambient_occlusion) st.queue.enqueueFillBuffer(ao, zero, 0, plane * sizeof(float));

  const cl::NDRange pixels(roundUp(field.width, kTileX), roundUp(field.height, kTileY));
  const cl::NDRange tile(kTileX, kTileY);
  int done = 0;
  for (const Batch& batch : batches) {
    const cl::Buffer directions = uploadDirections(st, batch.directions);
    const int batch_size = static_cast<int>(batch.directions.size());
    cl::Kernel reduce;
    if (sweep) {
      enqueueSweep(st, program, heights, field, directions, batch.directions, lines, stacks, true);
      reduce = cl::Kernel(program, "horizon_reduce");
    } else {
      reduce = cl::Kernel(program, "horizon_naive");
    }
    int arg = 0;
    reduce.setArg(arg++, heights);
    reduce.setArg(arg++, field.width);
    reduce.setArg(arg++, field.height);
    reduce.setArg(arg++, static_cast<float>(field.cell_size_x));
    reduce.setArg(arg++, static_cast<float>(field.cell_size_y));
    reduce.setArg(arg++, directions);
    reduce.setArg(arg++, batch_size);
    if (sweep) reduce.setArg(arg++, lines);
    reduce.setArg(arg++, angles);
    reduce.setArg(arg++, distances);
    reduce.setArg(arg++, svf);
    reduce.setArg(arg++, ao);
    st.queue.enqueueNDRangeKernel(reduce, cl::NullRange, pixels, tile);
    const std::size_t batch_bytes = batch_size * plane * sizeof(float);
    const std::size_t at = batch.first * plane;
    if (outputs.horizon_angles) st.queue.enqueueReadBuffer(angles, CL_TRUE, 0, batch_bytes, &result.angles[at]);
    if (outputs.horizon_distances)
      st.queue.enqueueReadBuffer(distances, CL_TRUE, 0, batch_bytes, &result.distances[at]);
    st.queue.finish();
    done += batch_size;
    if (options.progress) options.progress(done, options.directions);
  }
  if (outputs.sky_view_factor)
    st.queue.enqueueReadBuffer(svf, CL_TRUE, 0, plane * sizeof(float), result.sky_view_factor.data());
  if (outputs.ambient_occlusion)
    st.queue.enqueueReadBuffer(ao, CL_TRUE, 0, plane * sizeof(float), result.ambient_occlusion.data());
  finishReduction(options, result);
  return result;
}

}  // namespace

SweepLineBuffers sweepLinesOnDevice(const ComputeContext& context, const HeightField& field,
                                    const std::vector<float>& prepared_heights, const SweepDirection& direction) {
  return translateOpenClErrors([&] {
    ContextState& st = context.state();
    cl::Program program = st.program("horizon.cl", "");
    SweepLineBuffers out;
    out.geometry = direction;
    out.geometry.buffer_offset = 0;
    const std::vector<SweepDirection> batch{out.geometry};
    const std::size_t entries = out.geometry.entries();
    cl::Buffer heights(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, prepared_heights.size() * sizeof(float),
                       const_cast<float*>(prepared_heights.data()));
    const cl::Buffer directions = uploadDirections(st, batch);
    cl::Buffer lines = deviceBuffer(st, entries * 2 * sizeof(float));
    cl::Buffer stacks = deviceBuffer(st, entries * 2 * sizeof(float));
    std::vector<float> pairs(entries * 2);
    enqueueSweep(st, program, heights, field, directions, batch, lines, stacks, false);
    st.queue.enqueueReadBuffer(lines, CL_TRUE, 0, pairs.size() * sizeof(float), pairs.data());
    for (std::size_t e = 0; e < entries; ++e) out.samples.push_back(pairs[2 * e]);
    enqueueSweep(st, program, heights, field, directions, batch, lines, stacks, true);
    st.queue.enqueueReadBuffer(lines, CL_TRUE, 0, pairs.size() * sizeof(float), pairs.data());
    for (std::size_t e = 0; e < entries; ++e) {
      out.occluder_rises.push_back(pairs[2 * e]);
      out.occluder_steps.push_back(pairs[2 * e + 1]);
    }
    return out;
  });
}

}  // namespace detail

HorizonResult computeHorizons(const ComputeContext& context, const HeightField& field, const HorizonOptions& options,
                              const HorizonOutputs& outputs) {
  validate(field);
  validate(options, outputs);
  return detail::translateOpenClErrors([&] { return detail::run(context, field, options, outputs); });
}

}  // namespace hfvis
