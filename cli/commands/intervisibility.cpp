// cli/commands/intervisibility.cpp: "hfvis intervisibility" (also "viewcount"): the visible
// samples and ground area of every pixel (hfvis/intervisibility.hpp).
#include "hfvis/intervisibility.hpp"

#include "../pipeline.hpp"

namespace hfvis::cli {
namespace {

class Intervisibility : public Computation {
 public:
  using Computation::Computation;

  std::string method() const override {
    return run_.visibility_method == IntervisibilityMethod::Naive ? "naive" : "tree";
  }

  void compute(Job& job) override {
    IntervisibilityOptions options = intervisibilityOptions(run_);
    job.progress.attach(options);
    result_ = job.progress.run([&] {
      return computeIntervisibility(*job.context, job.input, options, intervisibilityOutputs(run_));
    });
  }

  Summary write(Job& job, OutputFiles& outputs) override {
    const HeightField& field = job.input;
    requireResultSize(result_.width, result_.height, field);
    const std::size_t pixels = field.pixelCount();
    requireSize(result_.visible_count, pixels, "visible counts");
    requireSize(result_.visible_area, pixels, "visible areas");
    requireFiniteResult(result_.visible_count, field, "visible count");
    requireFiniteResult(result_.visible_area, field, "visible area");

    Attributes attributes = job.attributes(field);
    attributes.emplace_back(
        "hfvis:tie_rule",
        "a sample is visible when its slope from the receiver is >= the slope of every "
        "sample between them (grazing samples are visible), or when the steepest of them "
        "hides it only within the heights' rounding (2^-22 of the sum of the heights compared, "
        "counted from the field's base height, and of the highest one's absolute value), as it does every "
        "hidden sample between them; each decision an exact sign");
    // The K run, which --max-error chooses, and the error estimate when there is one.
    for (auto& [name, value] : attributes)
      if (name == "hfvis:directions") value = std::to_string(result_.directions);
    if (run_.max_error > 0.0) attributes.emplace_back("hfvis:max_error", formatNumber(run_.max_error));
    if (!result_.error_estimate.empty())
      attributes.emplace_back("hfvis:estimated_error", formatNumber(result_.estimated_error));
    Summary summary{result_.directions};
    if (run_.statistics) {
      const IntervisibilityStatistics& stats = result_.statistics;
      // Timonen (2013), Table 2: per receiver (line sample) and direction.
      attributes.emplace_back("hfvis:stats_m_a", formatNumber(stats.meanHorizons()));
      attributes.emplace_back("hfvis:stats_t_a", formatNumber(stats.meanIterations()));
      attributes.emplace_back("hfvis:stats_visible_per_point", formatNumber(stats.meanVisible()));
      attributes.emplace_back("hfvis:stats_naive_iterations_per_point",
                              formatNumber(stats.meanNaiveIterations()));
      attributes.emplace_back("hfvis:stats_receivers", std::to_string(stats.receivers));
      // Asked for explicitly: printed even with --quiet.
      summary.always =
          "statistics per point and direction (Timonen 2013, Table 2): m_a " +
          formatFixed(stats.meanHorizons(), 3) + ", t_a " + formatFixed(stats.meanIterations(), 3) +
          " (--hull-tree " + (run_.hull_tree_name.empty() ? "default" : run_.hull_tree_name) + ")" +
          ", visible " + formatFixed(stats.meanVisible(), 3) + ", naive iterations " +
          formatFixed(stats.meanNaiveIterations(), 3) + " (" + std::to_string(stats.receivers) +
          " line samples, " + std::to_string(stats.lines_over_bound) + " lines over t <= 2m + n)";
    }
    // "count" sorts before "visible_area", so the count is channel 0 in the EXR, whose
    // channels are stored sorted by name.
    outputs.image(
        run_.output,
        job.image(
            field, {"count", "visible_area"}, {result_.visible_count, result_.visible_area}, attributes,
            "count: visible surface samples summed over the K directions; visible_area: the visible ground "
            "area (total viewshed), each visible sample at ground distance rho standing for (2*pi/K) * rho * "
            "drho",
            "count: samples (one per 1/S pixel lengths along each direction, S = samples per unit); "
            "visible_area: ground units squared"));
    if (!run_.error_output.empty()) {
      requireSize(result_.error_estimate, pixels, "error estimate");
      outputs.image(run_.error_output,
                    job.image(field, {"error"}, {result_.error_estimate}, attributes,
                              "estimated error of the visible count (not the area), relative to the "
                              "field's mean count",
                              "relative (a fraction of the mean count); NaN at nodata"));
    }
    if (!run_.preview.empty())
      outputs.previewPng(run_.preview, field.width, field.height,
                         result_.visible_count);  // stretched min..max
    summary.note = "; mean count " + formatFixed(finiteMean(result_.visible_count), 2);
    if (!result_.error_estimate.empty())
      summary.note += "; estimated error (99th percentile, relative to the mean count) " +
                      formatFixed(result_.estimated_error, 4) +
                      (run_.max_error > 0.0 ? " for --max-error " + formatNumber(run_.max_error) : "");
    return summary;
  }

 private:
  IntervisibilityResult result_;
};

void checkIntervisibility(const std::string& name, const RunArguments& run) {
  const bool naive = run.visibility_method != IntervisibilityMethod::HullTree;
  if (naive && !run.hull_tree_name.empty())
    throw UsageError("--hull-tree needs --method tree (the naive method builds no tree)");
  // (the library's "statistics ... only for the hull-tree method", in the CLI's words)
  if (naive && run.statistics)
    throw UsageError("--stats needs --method tree (the naive method has no horizons or iterations to count)");
  if (naive && (run.max_error > 0.0 || !run.error_output.empty()))
    throw UsageError(
        "--max-error and --error-out need --method tree (the naive method's rays are not split in halves)");
  if (run.max_error > 0.0 && run.directions_given)
    throw UsageError(name + ": --max-error chooses K itself; give either it or -k");
  if (run.error_tile > 0)
    throw UsageError(name + ": --error-tile refines the sky-view factor and occlusion only; the whole field takes one K here");
  asUsageError([&] { validate(intervisibilityOptions(run), intervisibilityOutputs(run)); });
}

}  // namespace

const CommandSpec kIntervisibilityCommand{
    Command::Intervisibility,
    "intervisibility",
    "viewcount",
    "channel 0 \"count\": visible surface samples summed over the K directions;\n"
    "channel 1 \"visible_area\": the visible ground area (total viewshed), ground units^2",
    "IN -o OUT.exr [-k K | --max-error E] [--error-out ERR.exr] [--method tree|naive] [--stats] [options]",
    "Writes two float32 channels: channel 0 \"count\" = the number of visible surface samples\n"
    "summed over the K directions (one sample per 1/S pixel lengths along each direction, S =\n"
    "--samples-per-unit, default 1); channel 1 \"visible_area\" = the visible ground area, ground\n"
    "units squared. NaN at nodata pixels.\n",
    "Tie rule   along direction k a pixel sees the samples q_i = p + i/S * d_k (S samples per\n"
    "           unit, bilinear heights, inside the field); q is visible when its slope from p is\n"
    "           >= the slope of every sample between them (grazing samples are visible: on a flat\n"
    "           plane every sample is), or the steepest of them hides it only within the heights'\n"
    "           rounding (a few units in the last place), as it does every hidden sample between\n"
    "           them: on a tilted plane too every sample is. Count: the visible samples summed over\n"
    "           the K directions, each counting its step times S; an N x M flat plane gives\n"
    "           N + M - 2 at K = 4. The tree method runs on lines through the pixel centres along\n"
    "           integer steps (a, b) close to d_k, each pixel the receiver of its own line, its\n"
    "           steps |(a, b)| / ceil(|(a, b)| S); the naive method marches each pixel's own ray.\n"
    "Area       each visible sample at ground distance rho stands for its direction's share of\n"
    "           the circle (2*pi/K for the naive march, the quadrature weight of the tree's\n"
    "           step) times rho * drho, drho the ground step: ground units squared; it tends to\n"
    "           the area seen as K grows.\n"
    "The preview stretches the count from its minimum to its maximum.\n",
    kSweptFieldGroups | kHullTreeGroup | kIntervisibilityGroup | kErrorTargetGroup,
    checkIntervisibility,
    nullptr,
    pipelined<Intervisibility>,
};

}  // namespace hfvis::cli
