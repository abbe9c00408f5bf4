// cli/commands/insolation.cpp: "hfvis insolation": sunshine hours and direct irradiation over a
// span of time (hfvis/insolation.hpp).
#include "hfvis/insolation.hpp"

#include <algorithm>
#include <iostream>

#include "../pipeline.hpp"

namespace hfvis::cli {
namespace {

constexpr double kMostUnaliasedStep = 60.0;  // minutes (--step): past it, a warning

class Insolation : public Computation {
 public:
  using Computation::Computation;

  std::string method() const override { return "sweep"; }

  // Row 0 is taken as north: a south-up or west-up field is computed flipped (and only the
  // input's size is read from here on).
  void prepare(HeightField& field) override {
    // Each step takes the sun at its middle: steps of hours alias the day's course (a step of 1440
    // minutes counted every hour of a day as sunny, exit 0 without a word). A span shorter than
    // the step is one step of the span's length: it aliases as much where that is past the limit
    // (a day in one step of 1440 was the worst case and had no warning, a probe's find).
    const InsolationOptions options = insolationOptions(run_);
    const double longest_step = std::min(60.0 * options.step_minutes, options.to_utc - options.from_utc);
    if (longest_step > 60.0 * kMostUnaliasedStep)
      std::cerr << "hfvis: warning: --step " << formatNumber(options.step_minutes)
                << " minutes takes the sun once per step, at its middle: steps past " << kMostUnaliasedStep
                << " minutes alias its course over the day (sun hours and irradiation may be far off; the "
                   "default is 10)\n";
    lit_ = northUp(field);
    if (lit_.flipped()) field.heights = {};
  }

  void compute(Job& job) override {
    const HeightField& field = lit_.field();
    HorizonOptions sweep = horizonOptions(run_);
    job.progress.attach(sweep);
    result_ = job.progress.run(
        [&] { return computeInsolation(*job.context, field, insolationOptions(run_), sweep); });
  }

  Summary write(Job& job, OutputFiles& outputs) override {
    const HeightField& field = lit_.field();
    requireResultSize(result_.width, result_.height, field);
    requireSize(result_.sun_hours, field.pixelCount(), "sun hours");
    requireSize(result_.direct, field.pixelCount(), "direct irradiations");
    requireFiniteResult(result_.direct, field, "direct irradiation");
    lit_.restore(result_.sun_hours);
    lit_.restore(result_.direct);
    const InsolationOptions options = insolationOptions(run_);
    // One sweep per azimuth bucket the sun passes (hfvis:sweeps), no K directions.
    Attributes attributes = job.attributes(field, false);
    attributes.emplace_back("hfvis:samples_per_unit", formatNumber(job.run.samples_per_unit));
    attributes.emplace_back("hfvis:latitude_deg", formatNumber(options.latitude_deg));
    attributes.emplace_back("hfvis:longitude_deg", formatNumber(options.longitude_deg));
    attributes.emplace_back("hfvis:from_utc_s", formatNumber(options.from_utc));
    attributes.emplace_back("hfvis:to_utc_s", formatNumber(options.to_utc));
    attributes.emplace_back("hfvis:step_minutes", formatNumber(options.step_minutes));
    attributes.emplace_back("hfvis:sun_size_deg", formatNumber(options.size_deg));
    attributes.emplace_back("hfvis:azimuth_bucket_deg", formatNumber(options.azimuth_bucket_deg));
    attributes.emplace_back("hfvis:refraction",
                            options.apparent ? "apparent (refracted) elevations" : "geometric");
    attributes.emplace_back("hfvis:steps_with_sun", std::to_string(result_.steps));
    attributes.emplace_back("hfvis:sweeps", std::to_string(result_.sweeps));
    // "direct" sorts before "sun_hours": channel 0 in the EXR.
    outputs.image(
        run_.output,
        job.image(
            field, {"direct", "sun_hours"}, {result_.direct, result_.sun_hours}, attributes,
            "sun_hours: hours with the sun's centre above the pixel's horizon (and elevation 0); direct: the "
            "sum over steps of hours * the disc's part seen * max(0, n . s), the irradiation from a sun of "
            "normal irradiance 1",
            "sun_hours: hours; direct: hours times the sun's normal irradiance (W/m^2 gives Wh/m^2)"));
    if (!run_.preview.empty()) {
      const auto [lo, hi] = quantileRange(result_.direct);
      outputs.previewPng(run_.preview, field.width, field.height, result_.direct, lo, hi);
    }
    Summary summary{result_.sweeps};
    summary.note = "; " + std::to_string(result_.steps) + " steps with the sun up, mean sun " +
                   formatFixed(finiteMean(result_.sun_hours), 2) + " h" +
                   (lit_.flipped() ? " (lit north-up)" : "");
    return summary;
  }

 private:
  NorthUp lit_;
  InsolationResult result_;
};

void checkInsolation(const std::string&, const RunArguments& run) {
  if (!run.latitude || !run.longitude || !run.from_time || !run.to_time)
    throw UsageError("missing the place or the span: --lat LAT --lon LON --from TIME --to TIME");
  if (!(*run.from_time < *run.to_time)) throw UsageError("--from must come before --to");
  asUsageError([&] {
    validate(insolationOptions(run));
    validate(static_cast<const SweepOptions&>(horizonOptions(run)));
  });
}

}  // namespace

const CommandSpec kInsolationCommand{
    Command::Insolation,
    "insolation",
    nullptr,
    "\"sun_hours\" (hours of sun) and \"direct\" (irradiation of a unit sun, hours) over a span",
    "IN -o OUT.exr --lat LAT --lon LON --from TIME --to TIME [--step MINUTES]\n"
    "[--sun-size DEG] [--azimuth-bucket DEG] [--apparent] [options]",
    "Sunlight from TIME to TIME (ISO 8601 with a zone) at latitude LAT, longitude LON, in steps\n"
    "of MINUTES (default 10; the last one shorter), each taken at its middle. Channel\n"
    "\"sun_hours\": hours with the sun's centre above the pixel's horizon and above elevation 0\n"
    "(terrain beyond the field taken as level); \"direct\": the sum over the steps of hours *\n"
    "the disc's part seen * max(0, n . s), the irradiation from a sun of normal irradiance 1 in\n"
    "hours (times a normal irradiance in W/m^2 it is Wh/m^2). Steps whose sun azimuths fall in\n"
    "one bucket of DEG (default 0.25) share one horizon sweep, so a year costs a few hundred\n"
    "sweeps. --apparent lifts the sun by the atmosphere's refraction. Row 0 is taken as north (a\n"
    "south-up GeoTIFF is lit flipped north-up). The preview stretches direct over its 1st to\n"
    "99th percentile. NaN at nodata pixels.\n",
    nullptr,
    kImageCommandGroups | kSamplingGroup | kEarthGroup | kSunPlaceGroup | kInsolationGroup,
    checkInsolation,
    nullptr,
    pipelined<Insolation>,
};

}  // namespace hfvis::cli
