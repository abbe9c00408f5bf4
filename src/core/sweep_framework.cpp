// sweep_framework.cpp: scratch layout, memory budgets, buffers and the chunked launch of the
// lattice sweeps.
#include "core/sweep_framework.hpp"

#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <sstream>

namespace hfvis::detail {

std::string mebibytes(std::size_t bytes) {
  std::ostringstream s;
  s.precision(1);
  // (a budget under a tenth of a MiB in KiB or bytes: "0.0 MiB" would say nothing)
  if (bytes >= 1024 * 1024 / 10)
    s << std::fixed << bytes / (1024.0 * 1024.0) << " MiB";
  else if (bytes >= 1024)
    s << std::fixed << bytes / 1024.0 << " KiB";
  else
    s << bytes << " bytes";
  return s.str();
}

int simdLanes(const ContextState& st) { return lineMajorLayout(st) && st.info.type == "CPU" ? 8 : 1; }

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

std::size_t memoryBudget(std::size_t budget_bytes, const DeviceInfo& device) {
  if (budget_bytes) return budget_bytes;
  // A CPU device's memory is the host's: PoCL reports a fraction of it as its global memory
  // (4.8 to 6.2 GiB on the 24 GB test machine) and allocates from the host beyond that, so the
  // budget is half the host's physical memory (its largest single buffer still applies).
  // Within a container the memory the process may use is its cgroup's limit, where that is lower.
  // (Other CPU runtimes may refuse to allocate beyond their reported global memory: then the
  // budget is an error they report, not a crash.)
  if (device.type == "CPU") {
    if (const std::size_t host = hostMemoryBudget()) return host;
  }
  return device.global_memory_bytes / 2;
}

std::size_t hostMemoryBudget() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page <= 0) return 0;
  std::size_t host = static_cast<std::size_t>(pages) * static_cast<std::size_t>(page);
  std::ifstream limit("/sys/fs/cgroup/memory.max");
  std::size_t bytes = 0;
  if (limit >> bytes && bytes > 0) host = std::min(host, bytes);  // "max" (no limit) fails to parse
  return host / 2;
}

cl::Buffer deviceBuffer(ContextState& st, std::size_t bytes) {
  return cl::Buffer(st.context, CL_MEM_READ_WRITE, std::max<std::size_t>(bytes, sizeof(float)));
}

cl::Buffer uploadDirections(ContextState& st, const std::vector<SweepDirection>& directions) {
  return cl::Buffer(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                    directions.size() * sizeof(SweepDirection),
                    const_cast<SweepDirection*>(directions.data()));
}

void launchLineChunks(ContextState& st, NamedKernel& kernel, std::vector<LatticeLine> lines,
                      std::size_t samples_per_period, std::size_t scratch_entries, int lanes,
                      std::size_t group, bool lanes_together) {
  if (lines.empty()) return;
  const bool first_line = kernel.has("first_line");
  for (const LineChunk& chunk : chunkLines(lines, samples_per_period, scratch_entries, lineMajorLayout(st),
                                           lanes_together ? static_cast<std::size_t>(lanes) : 1)) {
    const cl::Buffer chunk_lines(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                                 chunk.count * sizeof(LatticeLine), lines.data() + chunk.first);
    kernel.set("lines", chunk_lines);
    kernel.set("n_lines", static_cast<int>(chunk.count));
    kernel.set("stride", static_cast<cl_uint>(chunk.stride));
    if (first_line) kernel.set("first_line", static_cast<int>(chunk.first));
    const std::size_t items = (chunk.count + lanes - 1) / lanes;
    st.launch(kernel, cl::NDRange(roundUp(items, group)), cl::NDRange(group));
  }
}

}  // namespace hfvis::detail
