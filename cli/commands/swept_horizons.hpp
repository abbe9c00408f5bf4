// cli/commands/swept_horizons.hpp: what horizon, sky-view-factor and ambient-occlusion share: one
// computeHorizons run, the azimuths it swept, and (the latter two) one channel written from it.
#pragma once

#include <string>
#include <vector>

#include "../pipeline.hpp"
#include "hfvis/horizon.hpp"

namespace hfvis::cli {

// computeHorizons for `wanted`, with the run's options and progress.
HorizonResult computeSweptHorizons(Job& job, const HorizonOutputs& wanted);

// The run's attributes and hfvis:azimuths_deg: the sweep's directions are lattice steps near
// phi_k (horizon planes) or quadrature directions (sky-view factor, ambient occlusion).
// With --max-error (sky-view factor, occlusion) also hfvis:richardson_divisor (least..most with
// tiles) and hfvis:runs.
Attributes sweptAttributes(const Job& job, const HorizonResult& result);

// hfvis:runs: each run's K (HorizonResult::runs), comma-separated.
std::string runList(const HorizonResult& result);

// One channel computed from the horizons.
struct HorizonQuantity {
  Command command;
  const char* channel;  // its name, "svf"
  const char* what;     // in messages, "sky-view factor"
  const char* quantity;
  const char* units;
  bool HorizonOutputs::*wanted;
  std::vector<float> HorizonResult::*plane;
};

class HorizonQuantityComputation : public Computation {
 public:
  HorizonQuantityComputation(const RunArguments& run, const HorizonQuantity& quantity)
      : Computation(run), quantity_(quantity) {}
  void compute(Job& job) override;
  Summary write(Job& job, OutputFiles& outputs) override;

 private:
  const HorizonQuantity& quantity_;
  HorizonResult result_;
};

// The CommandSpec::check and ::run of a command that writes `quantity`.
template <const HorizonQuantity& quantity>
void checkHorizonQuantity(const std::string& name, const RunArguments& run) {
  if (run.max_error > 0.0 && run.directions_given)
    throw UsageError(name + ": --max-error chooses K itself; give either it or -k");
  if (run.error_tile > 0 && run.max_error == 0.0)
    throw UsageError(name + ": --error-tile refines toward --max-error; give it with --max-error");
  asUsageError([&] { validate(horizonOptions(run), horizonOutputs(quantity.command, run)); });
}
template <const HorizonQuantity& quantity>
int runHorizonQuantity(const CommandLine& line) {
  HorizonQuantityComputation computation(line.run, quantity);
  return runPipeline(line, computation);
}

}  // namespace hfvis::cli
