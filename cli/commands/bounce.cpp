// cli/commands/bounce.cpp: "hfvis bounce": the irradiance of one diffuse bounce of a given exit
// radiance (hfvis/bounce.hpp).
#include "hfvis/bounce.hpp"

#include <algorithm>
#include <iomanip>
#include <iostream>

#include "../pipeline.hpp"
#include "hfvis/errors.hpp"
#include "io/gdal_io.hpp"
#include "io/image_reading.hpp"

namespace hfvis::cli {
namespace {

class Bounce : public Computation {
 public:
  using Computation::Computation;

  std::vector<std::string> otherInputs() const override { return {run_.radiance}; }
  std::string method() const override { return "tree"; }

  void prepare(HeightField& field) override {
    // A latitude / longitude grid has a spacing per row, which every operation follows but the
    // bounce: it takes the centre latitude's for the whole field, and says so.
    if (!field.row_cell_size_x.empty()) {
      const auto [narrowest, widest] =
          std::minmax_element(field.row_cell_size_x.begin(), field.row_cell_size_x.end());
      std::cerr
          << std::setprecision(6) << "hfvis: warning: bounce takes the centre latitude's cell size ("
          << field.cell_size_x << " x " << field.cell_size_y << ") for the whole field; its rows range from "
          << *narrowest << " to " << *widest
          << " along columns (per-row spacing of latitude / longitude grids is followed by horizon, svf, "
             "ao, viewcount and horizons; not by bounce)\n";
    }
    radiance_image_ = readImage(run_.radiance);
    detail::requireSameGrid(run_.radiance, radiance_image_.georeference, run_.input, field.georeference);
    detail::requireFloatRadiance(radiance_image_.integers, run_.radiance, "the exit radiance");
    if (radiance_image_.width != field.width || radiance_image_.height != field.height) {
      throw IoError(run_.radiance, "is " + std::to_string(radiance_image_.width) + "x" +
                                       std::to_string(radiance_image_.height) + ", the height field " +
                                       run_.input + " is " + std::to_string(field.width) + "x" +
                                       std::to_string(field.height) +
                                       ": the exit radiance needs one value per height");
    }
    if (radiance_image_.planes.size() > static_cast<std::size_t>(kMaxBounceChannels)) {
      throw IoError(run_.radiance, "has " + std::to_string(radiance_image_.planes.size()) +
                                       " channels; at most " + std::to_string(kMaxBounceChannels) +
                                       " are gathered in one run (split the channels into several files)");
    }
    radiance_.width = radiance_image_.width;
    radiance_.height = radiance_image_.height;
    radiance_.channels = radiance_image_.planes;
    try {
      validate(field, radiance_);
    } catch (const InvalidArgument& error) {
      throw Error(run_.radiance + ": " + error.what());
    }
  }

  void compute(Job& job) override {
    BounceOptions options = bounceOptions(run_);
    job.progress.attach(options);
    result_ = job.progress.run([&] { return computeBounce(*job.context, job.input, radiance_, options); });
  }

  Summary write(Job& job, OutputFiles& outputs) override {
    const HeightField& field = job.input;
    requireResultSize(result_.width, result_.height, field);
    if (result_.irradiance.size() != radiance_.channels.size()) {
      throw Error("internal error: the bounce returned " + std::to_string(result_.irradiance.size()) +
                  " channels for " + std::to_string(radiance_.channels.size()));
    }
    for (const auto& plane : result_.irradiance) {
      requireSize(plane, field.pixelCount(), "irradiance");
      requireFiniteResult(plane, field, "irradiance");
    }
    Attributes attributes = job.attributes(field);
    attributes.emplace_back("hfvis:radiance", run_.radiance);
    // The radiance's channel names, so that R, G, B stay R, G, B.
    outputs.image(
        run_.output,
        job.image(field, radiance_image_.names, result_.irradiance, attributes,
                  "incident indirect irradiance of one diffuse bounce of the exit radiance "
                  "(hfvis:radiance), per channel: sum over directions and visible samples of radiance "
                  "times projected solid angle",
                  "radiance units times steradians (W/m^2 for W m^-2 sr^-1); a Lambertian surface of "
                  "albedo rho re-emits rho * E / pi"));
    if (!run_.preview.empty()) {
      std::vector<float> mean(field.pixelCount(), 0.0f);
      for (const auto& plane : result_.irradiance)
        for (std::size_t p = 0; p < mean.size(); ++p)
          mean[p] += plane[p] / static_cast<float>(result_.irradiance.size());
      outputs.previewPng(run_.preview, field.width, field.height, mean);  // stretched min..max
    }
    Summary summary{run_.directions};
    summary.note = "; mean irradiance";
    for (std::size_t c = 0; c < result_.irradiance.size(); ++c)
      summary.note +=
          (c ? ", " : " ") + radiance_image_.names[c] + " " + formatNumber(finiteMean(result_.irradiance[c]));
    return summary;
  }

 private:
  ImageChannels radiance_image_;
  ExitRadiance radiance_;
  BounceResult result_;
};

void checkBounce(const std::string&, const RunArguments& run) {
  if (run.radiance.empty())
    throw UsageError("missing --radiance RAD.exr (the exit radiance to bounce, same size as the input)");
  if (samePath(run.output, run.radiance))
    throw UsageError("--radiance must differ from -o, both are " + inQuotes(run.output));
  if (!run.preview.empty() && samePath(run.preview, run.radiance))
    throw UsageError("--preview must differ from --radiance, both are " + inQuotes(run.preview));
  asUsageError([&] { validate(bounceOptions(run)); });
}

}  // namespace

const CommandSpec kBounceCommand{
    Command::Bounce,
    "bounce",
    nullptr,
    "incident indirect irradiance of one diffuse bounce of a given exit radiance",
    "IN --radiance RAD.exr -o OUT.exr [-k K] [options]",
    "Writes the incident indirect irradiance of one diffuse bounce of the exit radiance RAD,\n"
    "one float32 channel per radiance channel (same names). NaN at nodata pixels.\n",
    "For every pixel, direction and visible sample along its sweep line, the sample's radiance\n"
    "times the projected solid angle of its elevation band (from the visible segments: bands\n"
    "split at mean elevations between adjacent visible samples; across hidden samples the band\n"
    "goes to the farther sample), for a Lambertian receiver whose normal comes from the four\n"
    "quads around it, each direction standing for its wedge of azimuth (the quadrature weight of\n"
    "its lattice step times 2*pi, about 2*pi/K); surface behind the receiver's tangent plane adds\n"
    "nothing. The sum is the incident indirect irradiance, in radiance units times steradians\n"
    "(W/m^2 for W m^-2 sr^-1); a surface of albedo rho re-emits rho * E / pi, the next bounce's\n"
    "radiance. A flat plane receives 0. The preview stretches the mean over the channels from\n"
    "its minimum to its maximum.\n",
    kImageCommandGroups | kSweepGroup | kSamplingGroup | kHullTreeGroup | kBounceGroup,
    checkBounce,
    nullptr,
    pipelined<Bounce>,
};

}  // namespace hfvis::cli
