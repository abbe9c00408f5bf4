// sweep_framework.cpp: batching, geometry upload and presampling for sweep kernels.
#include "sweep_framework.hpp"

#include <algorithm>
#include <sstream>

namespace hfvis::detail {

int SweepBatch::maxLines() const {
  int n = 0;
  for (const auto& d : directions) n = std::max(n, d.n_lines);
  return n;
}

int SweepBatch::maxSteps() const {
  int n = 0;
  for (const auto& d : directions) n = std::max(n, d.n_steps);
  return n;
}

std::string mebibytes(std::size_t bytes) {
  std::ostringstream s;
  s.precision(1);
  s << std::fixed << bytes / (1024.0 * 1024.0) << " MiB";
  return s.str();
}

bool lineMajorLayout(const ContextState& st) {
  switch (st.options.line_layout) {
    case LineLayout::LineMajor:
      return true;
    case LineLayout::StepMajor:
      return false;
    case LineLayout::Automatic:
      break;
  }
  return st.info.type == "CPU";
}

std::string layoutProgramOption(const ContextState& st) {
  return std::string("-DHFVIS_LINE_MAJOR=") + (lineMajorLayout(st) ? "1" : "0");
}

std::size_t defaultMemoryBudget(const DeviceInfo& device) {
  return std::min<std::size_t>(std::size_t(1) << 30, device.global_memory_bytes / 2);
}

std::vector<SweepBatch> planSweepBatches(const std::vector<SweepDirection>& all, const SweepMemory& memory,
                                         std::size_t budget_bytes, const DeviceInfo& device) {
  const std::size_t budget = budget_bytes ? budget_bytes : defaultMemoryBudget(device);
  const std::size_t max_alloc = device.max_allocation_bytes ? device.max_allocation_bytes : budget;
  std::vector<SweepBatch> batches;
  SweepBatch batch;
  std::size_t used = memory.fixed_bytes;
  for (std::size_t k = 0; k < all.size(); ++k) {
    const std::size_t entries = memory.bytes_per_entry ? all[k].entries() : 0;
    const std::size_t need =
        entries * memory.bytes_per_entry + memory.bytes_per_direction + sizeof(SweepDirection);
    const std::size_t count = batch.directions.size() + 1;
    const bool fits =
        used + need <= budget && (batch.entries + entries) * memory.largest_entry_bytes <= max_alloc &&
        batch.entries + entries < (std::size_t(1) << 31) && count * memory.bytes_per_direction <= max_alloc;
    if (!fits && batch.directions.empty()) {
      throw MemoryBudgetError("one direction needs " + mebibytes(memory.fixed_bytes + need) +
                              " of device memory but the budget is " + mebibytes(budget) +
                              " (largest single buffer " + mebibytes(max_alloc) +
                              "); raise the memory budget or use a smaller field");
    }
    if (!fits || static_cast<int>(batch.directions.size()) == kMaxDirectionsPerBatch) {
      batches.push_back(batch);
      batch = SweepBatch{static_cast<int>(k), {}, 0};
      used = memory.fixed_bytes;
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
  return cl::Buffer(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                    directions.size() * sizeof(SweepDirection),
                    const_cast<SweepDirection*>(directions.data()));
}

void enqueuePresample(ContextState& st, cl::Program& program, const cl::Buffer& heights, int width,
                      int height, const cl::Buffer& directions, const SweepBatch& batch,
                      const cl::Buffer& lines) {
  cl::Kernel presample(program, "presample_lines");
  presample.setArg(0, heights);
  presample.setArg(1, width);
  presample.setArg(2, height);
  presample.setArg(3, directions);
  presample.setArg(4, lines);
  const std::size_t lines_count = batch.maxLines(), steps = batch.maxSteps();
  const bool line_major = lineMajorLayout(st);
  // Work-groups of kLineGroup x kPresampleRows: PoCL pays about a microsecond per
  // work-group, which one row per group made the larger part of this pass.
  st.launch(presample,
            cl::NDRange(roundUp(line_major ? steps : lines_count, kLineGroup),
                        roundUp(line_major ? lines_count : steps, kPresampleRows), batch.directions.size()),
            cl::NDRange(kLineGroup, kPresampleRows, 1));
}

}  // namespace hfvis::detail
