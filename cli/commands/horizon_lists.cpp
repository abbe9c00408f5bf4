// cli/commands/horizon_lists.cpp: "hfvis horizon-lists" (also "horizons"): the visibility
// horizons of chosen receivers, as JSON or CSV (hfvis/horizon_lists.hpp).
#include "hfvis/horizon_lists.hpp"

#include <cctype>
#include <filesystem>

#include "../horizon_list_files.hpp"
#include "../pipeline.hpp"

namespace hfvis::cli {
namespace {

// Computed on the host, one ray per receiver and direction, and written as text.
class HorizonLists : public Computation {
 public:
  using Computation::Computation;

  std::vector<std::string> outputs() const override { return {run_.output}; }
  bool writesImages() const override { return false; }
  std::string method() const override { return "tree on the receivers' rays"; }

  // A receiver outside the field is a usage error, found once the field's size is known.
  void prepare(HeightField& field) override {
    for (const ReceiverPixel& p : run_.receivers) {
      if (p.col >= field.width || p.row >= field.height) {
        throw UsageError("--at " + std::to_string(p.col) + "," + std::to_string(p.row) +
                         ": outside the field " + run_.input + ", which is " + std::to_string(field.width) +
                         "x" + std::to_string(field.height) + " (columns 0.." +
                         std::to_string(field.width - 1) + ", rows 0.." + std::to_string(field.height - 1) +
                         ")");
      }
    }
  }

  void compute(Job& job) override {
    lists_ = computeHorizonLists(job.input, horizonListOptions(run_), run_.receivers);
  }

  Summary write(Job& job, OutputFiles& outputs) override {
    std::size_t horizons = 0;
    for (const auto& receiver : lists_)
      for (const auto& direction : receiver.directions) horizons += direction.horizons.size();
    std::string ext = std::filesystem::path(run_.output).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    outputs.text(run_.output,
                 ext == ".csv" ? horizonListsCsv(lists_) : horizonListsJson(run_, job.input, lists_));
    Summary summary{run_.directions};
    summary.note = "; " + std::to_string(lists_.size()) +
                   (lists_.size() == 1 ? " receiver, " : " receivers, ") + std::to_string(horizons) +
                   " horizons";
    return summary;
  }

 private:
  std::vector<ReceiverHorizons> lists_;
};

void checkHorizonLists(const std::string&, const RunArguments& run) {
  if (!hasExtension(run.output, ".json") && !hasExtension(run.output, ".csv")) {
    throw UsageError(
        "-o: the horizon lists are written as JSON or CSV; the name must end in .json or .csv, got " +
        namedAs(run.output));
  }
  if (run.receivers.empty()) throw UsageError("missing --at COL,ROW (the receivers whose horizons to list)");
  asUsageError([&] { validate(horizonListOptions(run)); });
}

}  // namespace

const CommandSpec kHorizonListsCommand{
    Command::HorizonLists,
    "horizon-lists",
    "horizons",
    "the visibility horizons of chosen receivers per direction, as JSON or CSV",
    "IN --at COL,ROW [--at COL,ROW ...] -o OUT.json|OUT.csv [-k K] [options]",
    "Writes, for each receiver and direction, the visibility horizons along the receiver's ray\n"
    "and the visible segments they bound, as JSON or CSV (by the extension of -o). It runs on\n"
    "the host, one ray per receiver and direction.\n",
    "-o OUT.json|OUT.csv  JSON: every receiver, direction and horizon, with the conventions\n"
    "           spelled out; CSV: one row per horizon with the columns\n"
    "           col,row,direction,azimuth_rad,horizon,sample,distance,elevation_rad,\n"
    "           segment_begin,segment_end,near_distance,visible_samples,nodata\n"
    "           (a direction without horizons: one row with the horizon fields empty;\n"
    "           nodata 1 where the receiver's height is nodata).\n"
    "Along direction k the receiver's own ray is sampled at i = 1, 2, ... (i/S pixel lengths,\n"
    "the naive method's samples; tie rule as intervisibility); between two samples the surface's\n"
    "highest point above their chord, where it rises above it, hides what lies behind it.\n"
    "Horizons are listed nearest first:\n"
    "each is the farthest visible sample of its segment (distance in ground units, elevation in\n"
    "radians); its visible segment is the samples [segment_begin, segment_end) toward the\n"
    "receiver, from near_distance up to distance. The segments hold every visible sample once.\n",
    kOutputGroup | kInputGroup | kSweepGroup | kSamplingGroup | kEarthGroup | kHorizonListsGroup,
    checkHorizonLists,
    nullptr,
    pipelined<HorizonLists>,
};

}  // namespace hfvis::cli
