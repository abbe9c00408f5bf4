// sweep_routine.hpp: the frame every device operation runs in (after CLBlast's routines): a
// routine prepares the heights, builds its program, plans device memory within its budget and
// allocates, then runs its items (a sweep's directions, a viewshed's observers, insolation's
// azimuth buckets) in batches, reporting progress after each batch, and collects its outputs.
// The operations derive from it and state only their kernels, buffers and outputs.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "hfvis/height_field.hpp"
#include "hfvis/sweep_options.hpp"
#include "core/opencl_context.hpp"
#include "core/sweep_framework.hpp"
#include "core/sweep_geometry.hpp"

namespace hfvis::detail {

class DeviceRoutine {
 public:
  virtual ~DeviceRoutine() = default;
  DeviceRoutine(const DeviceRoutine&) = delete;
  DeviceRoutine& operator=(const DeviceRoutine&) = delete;

  // The whole run: prepare, build, allocate, run every batch, finish.
  void run();

 protected:
  // `progress` (may be empty) hears (items done, items) after each batch; `memory_budget_bytes`
  // is the caller's budget, 0 for the default (memoryBudget()).
  DeviceRoutine(ContextState& st, const HeightField& field, std::function<void(int, int)> progress,
                std::size_t memory_budget_bytes)
      : st_(st), field_(field), progress_(std::move(progress)), memory_budget_bytes_(memory_budget_bytes) {}

  // The heights the kernels read (prepareHeights unless the operation prepares more).
  virtual PreparedHeights prepare() { return prepareHeights(field_); }
  // The program: its kernel file and -D options (after prepare()).
  virtual std::string programFile() const = 0;
  virtual std::string programOptions() const { return ""; }
  // Whether run() uploads the whole field into heights_ before allocate() (an operation
  // that runs a field in strips loads the heights strip by strip itself; one that reads no
  // heights on the device needs none).
  virtual bool heightsResident() const { return true; }
  // Plans device memory (throws MemoryBudgetError when one item does not fit) and allocates
  // every buffer the items need; heights_ and program_ are ready.
  virtual void allocate() = 0;
  // The items run and how many form a batch (outputs downloaded per batch).
  virtual int itemCount() const = 0;
  virtual int batchSize() const { return 1; }
  // Runs item `item`, the `slot`-th of its batch.
  virtual void runItem(int item, int slot) = 0;
  // After the batch [first, first + count) is enqueued: what it hands back to the host.
  virtual void endBatch(int first, int count) {
    (void)first;
    (void)count;
  }
  // After the last batch: the outputs.
  virtual void finish() = 0;

  // The device memory the routine may plan with: the caller's budget, else the default.
  std::size_t memoryBudget() const { return detail::memoryBudget(memory_budget_bytes_, st_.info); }
  // Kernel `name` of the routine's program.
  NamedKernel kernel(const std::string& name) { return NamedKernel(st_, program_, name); }
  // A read-only device copy of host values, and a zero-filled float buffer.
  template <typename T>
  cl::Buffer upload(const std::vector<T>& values) {
    if (values.empty()) return deviceBuffer(st_, 0);
    return cl::Buffer(st_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, values.size() * sizeof(T),
                      const_cast<T*>(values.data()));
  }
  cl::Buffer zeros(std::size_t floats);

  ContextState& st_;
  const HeightField& field_;
  PreparedHeights prepared_;
  cl::Program program_;
  cl::Buffer heights_;  // prepared_.heights on the device

 private:
  std::function<void(int, int)> progress_;
  std::size_t memory_budget_bytes_;
};

// A sweep operation (horizons, intervisibility, the bounce): its items are its directions.
class SweepRoutine : public DeviceRoutine {
 protected:
  SweepRoutine(ContextState& st, const HeightField& field, const SweepOptions& options)
      : DeviceRoutine(st, field, options.progress, options.memory_budget_bytes), options_(options) {}

  // The directions swept, and the sweep of direction `direction`, the `slot`-th of its batch.
  virtual int directionCount() const = 0;
  virtual void sweep(int direction, int slot) = 0;

  const SweepOptions& options_;

 private:
  int itemCount() const final { return directionCount(); }
  void runItem(int item, int slot) final { sweep(item, slot); }
};

}  // namespace hfvis::detail
