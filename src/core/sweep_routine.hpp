// sweep_routine.hpp: the frame every sweep operation runs in (after CLBlast's routines): a
// routine prepares the heights, builds its program, plans device memory and allocates, then
// sweeps its directions in batches, reporting progress after each batch, and collects its
// outputs. The operations (horizons, intervisibility, the bounce) derive from it and state
// only their kernels, buffers and outputs.
#pragma once

#include <string>

#include "hfvis/height_field.hpp"
#include "hfvis/sweep_options.hpp"
#include "core/opencl_context.hpp"
#include "core/sweep_geometry.hpp"

namespace hfvis::detail {

class SweepRoutine {
 public:
  virtual ~SweepRoutine() = default;
  SweepRoutine(const SweepRoutine&) = delete;
  SweepRoutine& operator=(const SweepRoutine&) = delete;

  // The whole run: prepare, build, allocate, sweep every batch, finish.
  void run();

 protected:
  SweepRoutine(ContextState& st, const HeightField& field, const SweepOptions& options)
      : st_(st), field_(field), options_(options) {}

  // The heights the kernels read (prepareHeights unless the operation prepares more).
  virtual PreparedHeights prepare() { return prepareHeights(field_); }
  // The program: its kernel file and -D options (after prepare()).
  virtual std::string programFile() const = 0;
  virtual std::string programOptions() const = 0;
  // Whether run() uploads the whole field into heights_ before allocate() (an operation
  // that runs a field in strips loads the heights strip by strip itself).
  virtual bool heightsResident() const { return true; }
  // Plans device memory (throws MemoryBudgetError when one direction does not fit) and
  // allocates every buffer the sweeps need; heights_ and program_ are ready.
  virtual void allocate() = 0;
  // The directions swept and how many form a batch (outputs downloaded per batch).
  virtual int directionCount() const = 0;
  virtual int batchSize() const { return 1; }
  // Sweeps direction `direction`, the `slot`-th of its batch.
  virtual void sweep(int direction, int slot) = 0;
  // After the batch [first, first + count) is enqueued: what it hands back to the host.
  virtual void endBatch(int first, int count) {
    (void)first;
    (void)count;
  }
  // After the last batch: the outputs.
  virtual void finish() = 0;

  // A device copy of host floats, and a zero-filled float buffer.
  cl::Buffer upload(const std::vector<float>& values);
  cl::Buffer zeros(std::size_t floats);

  ContextState& st_;
  const HeightField& field_;
  const SweepOptions& options_;
  PreparedHeights prepared_;
  cl::Program program_;
  cl::Buffer heights_;  // prepared_.heights on the device
};

}  // namespace hfvis::detail
