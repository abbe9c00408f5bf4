// sweep_routine.cpp: the common frame of the sweep operations (see sweep_routine.hpp).
#include "core/sweep_routine.hpp"

#include <algorithm>

#include "core/sweep_framework.hpp"

namespace hfvis::detail {

void SweepRoutine::run() {
  prepared_ = prepare();
  program_ = st_.program(programFile(), programOptions());
  if (heightsResident()) heights_ = upload(prepared_.heights);
  allocate();
  const int directions = directionCount(), batch = std::max(1, batchSize());
  for (int first = 0; first < directions; first += batch) {
    const int count = std::min(batch, directions - first);
    for (int slot = 0; slot < count; ++slot) sweep(first + slot, slot);
    endBatch(first, count);
    st_.queue.finish();
    if (options_.progress) options_.progress(first + count, directions);
  }
  finish();
}

cl::Buffer SweepRoutine::upload(const std::vector<float>& values) {
  if (values.empty()) return deviceBuffer(st_, 0);
  return cl::Buffer(st_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, values.size() * sizeof(float),
                    const_cast<float*>(values.data()));
}

cl::Buffer SweepRoutine::zeros(std::size_t floats) {
  cl::Buffer buffer = deviceBuffer(st_, floats * sizeof(float));
  const float zero = 0.0f;
  if (floats) st_.queue.enqueueFillBuffer(buffer, zero, 0, floats * sizeof(float));
  return buffer;
}

}  // namespace hfvis::detail
