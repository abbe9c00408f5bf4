// cli/commands/horizon.cpp: "hfvis horizon": the horizon elevation angle (and distance) per
// direction, K channels (hfvis/horizon.hpp).
#include "hfvis/horizon.hpp"

#include <unistd.h>

#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "../pipeline.hpp"
#include "hfvis/errors.hpp"
#include "swept_horizons.hpp"

namespace hfvis::cli {
namespace {

// The host memory a run may use: what the kernel says is available (free memory plus what it
// can reclaim), else the physical memory.
double availableHostBytes() {
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  double kib = 0.0;
  std::string unit;
  while (meminfo >> key >> kib >> unit) {
    if (key == "MemAvailable:") return kib * 1024.0;
  }
  return static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGE_SIZE));
}

// The horizon preview: per pixel, the mean elevation over the directions whose ray stays
// in the field (-pi/2 marks a ray that leaves it at once; averaging those in would make the
// border dominate the stretch). NaN where every direction is NaN (nodata) or leaves at once.
std::vector<float> meanInFieldElevation(const std::vector<float>& planes, std::size_t pixels,
                                        int directions) {
  constexpr float kLeavesAtOnce = -1.57079632679489661923f;
  std::vector<double> sum(pixels, 0.0);
  std::vector<int> count(pixels, 0);
  for (int k = 0; k < directions; ++k) {
    const float* plane = planes.data() + static_cast<std::size_t>(k) * pixels;
    for (std::size_t i = 0; i < pixels; ++i) {
      if (std::isfinite(plane[i]) && plane[i] > kLeavesAtOnce) {
        sum[i] += plane[i];
        ++count[i];
      }
    }
  }
  std::vector<float> mean(pixels);
  for (std::size_t i = 0; i < pixels; ++i) {
    mean[i] = count[i] ? static_cast<float>(sum[i] / count[i]) : std::nanf("");
  }
  return mean;
}

class Horizon : public Computation {
 public:
  using Computation::Computation;

  // K-channel horizon maps of a huge field outgrow the host before anything is computed: the
  // planes are held about three times (the result, its channels, the writer's buffer). Refused
  // then, saying what to ask for instead.
  void prepare(HeightField& field) override {
    const double plane = static_cast<double>(field.pixelCount()) * sizeof(float);
    // (--max-error: K is chosen as the runs go, so checked at the second run's, 16; a later K
    // that outgrows the host is not refused before it runs: docs/COMMAND_LINE.md says so)
    const int directions = run_.horizon_max_error_deg > 0.0 ? 16 : run_.directions;
    const double planes = plane * directions * (run_.distance_output.empty() ? 1 : 2);
    const double need = 3.0 * planes, available = availableHostBytes();
    if (need <= available) return;
    std::ostringstream message;
    message
        << std::fixed << std::setprecision(1) << "the " << directions << "-channel horizon map"
        << (run_.distance_output.empty() ? "" : " and its distances") << " of this " << field.width << " x "
        << field.height << " field need about " << need / 1073741824.0 << " GiB of host memory ("
        << planes / 1073741824.0 << " GiB of planes, held about three times while written) but "
        << available / 1073741824.0
        << " GiB is available: ask for svf or ao (one channel each), fewer directions (-k), or a crop of the "
           "field";
    throw Error(message.str());
  }

  void compute(Job& job) override {
    HorizonOutputs wanted;
    wanted.horizon_angles = true;
    wanted.horizon_distances = !run_.distance_output.empty();
    // --error-out with -k: the estimate at the K given (--max-error asks the library for it anyway).
    wanted.error_estimate = !run_.error_output.empty();
    result_ = computeSweptHorizons(job, wanted);
  }

  Summary write(Job& job, OutputFiles& outputs) override {
    const HeightField& field = job.input;
    const std::size_t pixels = field.pixelCount();
    const int directions = result_.directions;  // --max-error: the K it chose
    const Attributes attributes = horizonAttributes(job);
    // K channels, one per direction, named `prefix` and the direction's number.
    const auto stage = [&](const std::string& path, const std::vector<float>& planes, const char* prefix,
                           const std::string& what, const char* quantity, const char* units) {
      requireSize(planes, pixels * static_cast<std::size_t>(directions), (what + "s").c_str());
      requireFiniteResult(planes, field, what.c_str());
      outputs.image(path, job.image(field, directionChannelNames(prefix, directions),
                                    splitPlanes(planes, pixels, directions), attributes, quantity, units));
    };
    stage(run_.output, result_.angles, "h", "horizon angle",
          "horizon elevation angle per direction (channel k = direction k)",
          "radians above the horizontal; -pi/2 where the ray leaves the field at once");
    if (!run_.distance_output.empty()) {
      stage(run_.distance_output, result_.distances, "d", "horizon distance",
            "ground distance to the point casting the horizon, per direction",
            "ground units (pixels times cell size); 0 where no point casts a horizon or the surface's own "
            "slope "
            "at the receiver is the horizon");
    }
    Summary summary{directions};
    if (!result_.error_estimate.empty()) {
      // Degrees, as --max-error takes them.
      requireSize(result_.error_estimate, pixels, "error estimate");
      std::vector<float> degrees = result_.error_estimate;
      for (float& e : degrees) e = static_cast<float>(e * (180.0 / M_PI));
      if (!run_.error_output.empty())
        outputs.image(run_.error_output,
                      job.image(field, {"error"}, {degrees}, attributes,
                                "estimated error of the horizon angles: mean over azimuth of the K channels' "
                                "linear interpolation's error",
                                "degrees; NaN at nodata"));
      summary.note = "; estimated mean error " + formatFixed(result_.estimated_error * 180.0 / M_PI, 4) + " deg" +
                     (run_.horizon_max_error_deg > 0.0
                          ? " for --max-error " + formatNumber(run_.horizon_max_error_deg) + " (runs at K = " +
                                runList(result_) + ")"
                          : "");
    }
    if (!run_.preview.empty()) {
      const std::vector<float> mean = meanInFieldElevation(result_.angles, pixels, directions);
      outputs.previewPng(run_.preview, field.width, field.height, mean);  // stretched min..max
    }
    return summary;
  }

 private:
  // The run's attributes; with an error estimate it and --max-error in degrees (the library's are
  // radians).
  Attributes horizonAttributes(const Job& job) const {
    Attributes attributes = sweptAttributes(job, result_);
    for (auto& [name, value] : attributes)
      if (name == "hfvis:estimated_error") value = formatNumber(result_.estimated_error * 180.0 / M_PI);
    if (run_.horizon_max_error_deg > 0.0) {
      attributes.emplace_back("hfvis:max_error", formatNumber(run_.horizon_max_error_deg));
      attributes.emplace_back("hfvis:runs", runList(result_));
    }
    if (!result_.error_estimate.empty())
      attributes.emplace_back("hfvis:error_unit", "degrees, the mean over pixels and azimuths");
    return attributes;
  }

  HorizonResult result_;
};

void checkHorizon(const std::string& name, const RunArguments& run) {
  if (run.horizon_max_error_deg > 0.0 && run.directions_given)
    throw UsageError(name + ": --max-error chooses K itself; give either it or -k");
  if (!run.error_output.empty() && run.horizon_max_error_deg == 0.0 && run.directions < 5)
    throw UsageError(name + ": --error-out interpolates each direction from its neighbours: it needs -k 5 or more");
  asUsageError([&] { validate(horizonOptions(run), horizonOutputs(Command::Horizon, run)); });
}

// Horizon angles reach down to -pi/2, a ray that leaves the field at once.
double lowestAngle(const RunArguments&) { return -M_PI / 2.0; }

}  // namespace

const CommandSpec kHorizonCommand{
    Command::Horizon,
    "horizon",
    nullptr,
    "K float32 channels h000..h(K-1): horizon elevation angle per direction, radians",
    "IN -o OUT.exr [-k K | --max-error DEG] [--distance-out DIST.exr] [--error-out ERR.exr] [options]",
    "Writes K float32 channels h000..h(K-1) (zero-padded, so sorted order = direction order;\n"
    "select channels by name): channel k = horizon elevation angle in direction k, radians.\n",
    "Its preview shows the mean horizon elevation over the directions whose ray stays in\n"
    "the field (low = dark, high = bright), stretched from its minimum to its maximum; the\n"
    "sky-view-factor and ambient-occlusion previews stretch their 1st to 99th percentile over\n"
    "black..white (the summary line prints both ends). Nodata is black in every preview.\n",
    kSweptFieldGroups | kSweepMethodGroup | kHorizonGroup,
    checkHorizon,
    lowestAngle,
    pipelined<Horizon>,
};

}  // namespace hfvis::cli
