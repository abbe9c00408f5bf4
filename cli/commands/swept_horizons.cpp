// cli/commands/swept_horizons.cpp: see swept_horizons.hpp.
#include "swept_horizons.hpp"

#include <cmath>

namespace hfvis::cli {

HorizonResult computeSweptHorizons(Job& job, const HorizonOutputs& wanted) {
  HorizonOptions options = horizonOptions(job.run);
  job.progress.attach(options);
  HorizonResult result =
      job.progress.run([&] { return computeHorizons(*job.context, job.input, options, wanted); });
  requireResultSize(result.width, result.height, job.input);
  return result;
}

Attributes sweptAttributes(const Job& job, const HorizonResult& result) {
  Attributes attributes = job.attributes(job.input);
  std::string used;
  for (double azimuth : result.azimuths)
    used += (used.empty() ? "" : ",") + formatNumber(azimuth * 180.0 / M_PI);
  attributes.emplace_back("hfvis:azimuths_deg", used);
  return attributes;
}

void HorizonQuantityComputation::compute(Job& job) {
  HorizonOutputs wanted;
  wanted.*quantity_.wanted = true;
  result_ = computeSweptHorizons(job, wanted);
}

Summary HorizonQuantityComputation::write(Job& job, OutputFiles& outputs) {
  const HeightField& field = job.input;
  const std::vector<float>& plane = result_.*quantity_.plane;
  requireSize(plane, field.pixelCount(), quantity_.what);
  requireFiniteResult(plane, field, quantity_.what);
  outputs.image(run_.output, job.image(field, {quantity_.channel}, {plane}, sweptAttributes(job, result_),
                                       quantity_.quantity, quantity_.units));
  Summary summary{run_.directions};
  summary.note = "; mean " + std::string(quantity_.channel) + " " + formatFixed(finiteMean(plane), 4);
  if (!run_.preview.empty()) {
    // Stretched over the 1st to 99th percentile: most of a DEM's svf lies within 0.85 .. 1.
    const auto [lo, hi] = quantileRange(plane);
    outputs.previewPng(run_.preview, field.width, field.height, plane, lo, hi);
    summary.note += "; preview black at " + formatFixed(lo, 3) + ", white at " + formatFixed(hi, 3);
  }
  return summary;
}

}  // namespace hfvis::cli
