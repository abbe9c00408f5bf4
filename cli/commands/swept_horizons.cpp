// cli/commands/swept_horizons.cpp: see swept_horizons.hpp.
#include "swept_horizons.hpp"

#include <algorithm>
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
  // The K run, which --max-error chooses, and the error estimate when there is one.
  for (auto& [name, value] : attributes)
    if (name == "hfvis:directions") value = std::to_string(result.directions);
  if (job.run.max_error > 0.0) attributes.emplace_back("hfvis:max_error", formatNumber(job.run.max_error));
  if (job.run.error_tile > 0 && !result.pixel_directions.empty()) {  // refined by tile: least K to most
    int least = std::numeric_limits<int>::max(), most = 0;           // over the pixels with data
    for (std::size_t p = 0; p < result.pixel_directions.size(); ++p)
      if (std::isfinite(job.input.heights[p]))
        least = std::min(least, result.pixel_directions[p]),
        most = std::max(most, result.pixel_directions[p]);
    if (most > 0)
      attributes.emplace_back("hfvis:directions_range", std::to_string(least) + ".." + std::to_string(most));
  }
  if (!result.error_estimate.empty())
    attributes.emplace_back("hfvis:estimated_error", formatNumber(result.estimated_error));
  if (job.run.max_error > 0.0 && result.richardson_divisor_most > 0.0) {
    // What the raw estimate (the halves' difference) was divided by: 2^p - 1, p as the runs
    // measured it (per tile: the least and most), and each run's K, so that the whole cost is
    // known (HorizonOptions::max_error).
    attributes.emplace_back("hfvis:richardson_divisor",
                            result.richardson_divisor_least == result.richardson_divisor_most
                                ? formatNumber(result.richardson_divisor_most)
                                : formatNumber(result.richardson_divisor_least) + ".." +
                                      formatNumber(result.richardson_divisor_most));
    attributes.emplace_back("hfvis:runs", runList(result));
  }
  return attributes;
}

std::string runList(const HorizonResult& result) {
  std::string list;
  for (int K : result.runs) list += (list.empty() ? "" : ",") + std::to_string(K);
  return list;
}

void HorizonQuantityComputation::compute(Job& job) {
  HorizonOutputs wanted;
  wanted.*quantity_.wanted = true;
  // --error-out with -k: the estimate at the K given (--max-error asks the library for it anyway).
  wanted.error_estimate = !run_.error_output.empty();
  result_ = computeSweptHorizons(job, wanted);
}

Summary HorizonQuantityComputation::write(Job& job, OutputFiles& outputs) {
  const HeightField& field = job.input;
  const std::vector<float>& plane = result_.*quantity_.plane;
  requireSize(plane, field.pixelCount(), quantity_.what);
  requireFiniteResult(plane, field, quantity_.what);
  const Attributes attributes = sweptAttributes(job, result_);
  outputs.image(run_.output, job.image(field, {quantity_.channel}, {plane}, attributes, quantity_.quantity,
                                       quantity_.units));
  if (!run_.error_output.empty()) {
    requireSize(result_.error_estimate, field.pixelCount(), "error estimate");
    std::vector<std::string> names{"error"};
    std::vector<std::vector<float>> planes{result_.error_estimate};
    if (run_.error_tile > 0 && !result_.pixel_directions.empty()) {  // --error-tile: each pixel's K
      names.push_back("directions");                                 // NaN at nodata, as the error is
      std::vector<float>& k =
          planes.emplace_back(result_.pixel_directions.begin(), result_.pixel_directions.end());
      for (std::size_t p = 0; p < k.size(); ++p)
        if (!std::isfinite(field.heights[p])) k[p] = std::numeric_limits<float>::quiet_NaN();
    }
    outputs.image(
        run_.error_output,
        job.image(field, names, planes, attributes, std::string("estimated error of the ") + quantity_.what,
                  "absolute, in the output's unit; NaN at nodata (channel directions: the K of the "
                  "pixel's run)"));
  }
  Summary summary{result_.directions};
  summary.note = "; mean " + std::string(quantity_.channel) + " " + formatFixed(finiteMean(plane), 4);
  if (!result_.error_estimate.empty())
    summary.note += "; estimated error (99th percentile) " + formatFixed(result_.estimated_error, 4) +
                    (run_.max_error > 0.0 ? " for --max-error " + formatNumber(run_.max_error) : "");
  if (!run_.preview.empty()) {
    // Stretched over the 1st to 99th percentile: most of a DEM's svf lies within 0.85 .. 1.
    const auto [lo, hi] = quantileRange(plane);
    outputs.previewPng(run_.preview, field.width, field.height, plane, lo, hi);
    summary.note += "; preview black at " + formatFixed(lo, 3) + ", white at " + formatFixed(hi, 3);
  }
  return summary;
}

}  // namespace hfvis::cli
