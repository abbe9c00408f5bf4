// sweep_framework.cpp: batching, geometry upload and presampling for sweep kernels.
#include "sweep_framework.hpp"

#include <algorithm>
#include <sstream>

namespace hfvis::detail {

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


std::size_t defaultMemoryBudget(const DeviceInfo& device) {
  return std::min<std::size_t>(std::size_t(1) << 30, device.global_memory_bytes / 2);
}

cl::Buffer deviceBuffer(ContextState& st, std::size_t bytes) {
  return cl::Buffer(st.context, CL_MEM_READ_WRITE, std::max<std::size_t>(bytes, sizeof(float)));
}

cl::Buffer uploadDirections(ContextState& st, const std::vector<SweepDirection>& directions) {
  return cl::Buffer(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                    directions.size() * sizeof(SweepDirection),
                    const_cast<SweepDirection*>(directions.data()));
}

}  // namespace hfvis::detail
