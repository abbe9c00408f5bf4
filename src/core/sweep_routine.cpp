// sweep_routine.cpp: the common frame of the device operations (see sweep_routine.hpp).
#include "core/sweep_routine.hpp"

#include <algorithm>

namespace hfvis::detail {

void DeviceRoutine::run() {
  prepared_ = prepare();
  program_ = st_.program(programFile(), programOptions());
  if (heightsResident()) heights_ = upload(prepared_.heights);
  allocate();
  const int items = itemCount(), batch = std::max(1, batchSize());
  for (int first = 0; first < items; first += batch) {
    const int count = std::min(batch, items - first);
    for (int slot = 0; slot < count; ++slot) runItem(first + slot, slot);
    endBatch(first, count);
    st_.queue.finish();
    if (progress_) progress_(first + count, items);
  }
  finish();
}

cl::Buffer DeviceRoutine::zeros(std::size_t floats) {
  cl::Buffer buffer = deviceBuffer(st_, floats * sizeof(float));
  const float zero = 0.0f;
  if (floats) st_.queue.enqueueFillBuffer(buffer, zero, 0, floats * sizeof(float));
  return buffer;
}

}  // namespace hfvis::detail
