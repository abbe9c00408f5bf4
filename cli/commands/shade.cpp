// cli/commands/shade.cpp: "hfvis shade": the surface lit by an HDR environment
// (environment_light.cpp) and / or the sun (sun_shading.cpp) in one pass and one output, and with
// --albedo the radiance a Lambertian surface sends out.
#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "core/number_text.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/sun.hpp"
#include "io/gdal_io.hpp"
#include "light_parts.hpp"

namespace hfvis::cli {
namespace {

// --albedo: a number in [0, 1], or an image of the field's size (one channel, or R, G, B), as
// planes (one value for a number).
std::vector<std::vector<float>> readAlbedo(const RunArguments& run, const HeightField& field) {
  // A whole string strtod reads is a number, never a file name: a decimal one in 0 .. 1, or refused
  // ("nan", "inf", "1e999", "0x1").
  char* end = nullptr;
  std::strtod(run.albedo.c_str(), &end);
  if (!run.albedo.empty() && end == run.albedo.c_str() + run.albedo.size()) {
    double number = 0.0;
    if (!detail::decimalNumber(run.albedo, number))
      throw UsageError("--albedo: a number must be a decimal number in 0 .. 1, got '" + run.albedo + "'");
    if (!(number >= 0.0 && number <= 1.0))
      throw UsageError("--albedo: a number must be in 0 .. 1, got '" + run.albedo + "'");
    return {std::vector<float>(field.pixelCount(), static_cast<float>(number))};
  }
  ImageChannels image = readImage(run.albedo);
  // (a south-up albedo beside a north-up field lay mirrored, one of another place was taken, exit 0)
  detail::requireSameGrid(run.albedo, image.georeference, run.input, field.georeference);
  if (image.width != field.width || image.height != field.height)
    throw IoError(run.albedo, "the albedo is " + std::to_string(image.width) + "x" +
                                  std::to_string(image.height) + ", the height field " +
                                  std::to_string(field.width) + "x" + std::to_string(field.height));
  std::vector<std::vector<float>> planes;
  for (const char* name : {"R", "G", "B"})
    for (std::size_t i = 0; i < image.names.size(); ++i)
      if (image.names[i] == name) planes.push_back(image.planes[i]);
  if (planes.size() != 3) {
    if (image.planes.size() != 1) throw IoError(run.albedo, "an albedo image needs one channel or R, G, B");
    planes = {image.planes[0]};
  }
  // NaN (an albedo raster's nodata) only where the height is nodata too: where it is valid, a NaN
  // made that pixel's radiance NaN, exit 0.
  for (const auto& plane : planes)
    for (std::size_t p = 0; p < plane.size(); ++p) {
      const float v = plane[p];
      if (std::isnan(v) && !std::isfinite(field.heights[p])) continue;
      if (std::isnan(v))
        throw IoError(run.albedo, "the albedo is NaN (nodata) at column " + std::to_string(p % field.width) +
                                      ", row " + std::to_string(p / field.width) +
                                      ", where the height is valid: give an albedo there");
      if (!(v >= 0.0f && v <= 1.0f))
        throw IoError(run.albedo, "albedo values must be in 0 .. 1 (found " + formatNumber(v) + ")");
    }
  return planes;
}

class Shade : public Computation {
 public:
  explicit Shade(const RunArguments& run) : Computation(run), environment_(run), sun_(run) {}

  std::vector<std::string> otherInputs() const override { return {run_.environment, run_.albedo}; }

  // Row 0 is taken as north: a south-up or west-up field is lit flipped (and only the input's size
  // is read from here on).
  // The albedo stays in the input's order, as the irradiance comes back in it; its NaN are checked
  // against the input's heights, before a flipped field lets them go.
  void prepare(HeightField& field) override {
    if (!run_.albedo.empty()) albedo_ = readAlbedo(run_, field);
    lit_ = northUp(field);
    if (lit_.flipped()) field.heights = {};
    if (environment_.given()) environment_.read();
  }

  void compute(Job& job) override {
    HorizonOptions options = horizonOptions(run_);
    job.progress.attach(options);
    if (environment_.given()) environment_.compute(job, lit_, options);
    options.max_error = 0.0;  // (the environment's alone)
    if (sun_.given()) sun_.compute(job, lit_, options);
  }

  Summary write(Job& job, OutputFiles& outputs) override {
    const HeightField& field = lit_.field();
    const std::size_t pixels = field.pixelCount();
    LitOutput lit;
    // The sun alone sweeps its own azimuth (hfvis:swept_azimuth_deg), no K directions: it wrote
    // the default K of 64 (a probe's find).
    lit.attributes = job.attributes(field, environment_.given());
    if (!environment_.given())
      lit.attributes.emplace_back("hfvis:samples_per_unit", formatNumber(job.run.samples_per_unit));
    if (environment_.given()) environment_.describe(lit, pixels);
    if (sun_.given()) sun_.describe(lit);
    // --albedo: the radiance a Lambertian surface of that albedo sends out, albedo / pi times the
    // irradiance (the environment's and the sun's at --sun-irradiance).
    std::vector<std::vector<float>> radiance;
    if (!albedo_.empty()) {
      const std::size_t channels =
          std::max<std::size_t>(albedo_.size(), environment_.given() ? environment_.channels() : 1);
      for (std::size_t c = 0; c < channels; ++c) {
        std::vector<float> out(pixels);
        const std::vector<float>& a = albedo_[std::min(c, albedo_.size() - 1)];
        for (std::size_t p = 0; p < pixels; ++p) {
          double e = 0.0;
          if (environment_.given())
            e +=
                environment_.irradiance()[std::min<std::size_t>(c, environment_.channels() - 1) * pixels + p];
          if (sun_.given()) e += run_.sun_irradiance * sun_.direct()[p];
          out[p] = static_cast<float>(a[p] / M_PI * e);
        }
        radiance.push_back(std::move(out));
      }
      const bool grey = channels == 1;
      for (const char* name : {"R", "G", "B"}) {
        lit.names.push_back(grey ? std::string("radiance") : std::string("radiance.") + name);
        if (grey) break;
      }
      lit.planes.insert(lit.planes.end(), radiance.begin(), radiance.end());
      lit.attributes.emplace_back("hfvis:albedo", run_.albedo);
      lit.attributes.emplace_back("hfvis:sun_irradiance", formatNumber(run_.sun_irradiance));
      lit.quantity +=
          "radiance: albedo / pi times the irradiance (the environment's, and the sun's times its normal "
          "irradiance)";
      lit.units += "radiance: per steradian";
    }
    outputs.image(run_.output,
                  job.image(field, lit.names, lit.planes, lit.attributes, lit.quantity, lit.units));
    if (!run_.error_output.empty()) {
      requireSize(environment_.errorEstimate(), pixels, "error estimate");
      outputs.image(
          run_.error_output,
          job.image(field, {"error"}, {environment_.errorEstimate()}, lit.attributes,
                    "estimated error of the environment's irradiance: |at K - at K / 2|, the larger of "
                    "K / 2 on K's even and on its odd directions, the largest over the channels",
                    "relative (a fraction of the field's mean irradiance); NaN at nodata"));
    }
    if (!run_.preview.empty()) {
      if (!radiance.empty()) {
        outputs.toneMappedPng(run_.preview, field.width, field.height, radiance);
      } else if (environment_.given()) {
        outputs.toneMappedPng(run_.preview, field.width, field.height,
                              splitPlanes(environment_.irradiance(), pixels, environment_.channels()));
      } else {  // a hillshade with cast shadows: the direct light, 0 .. its largest value
        outputs.previewPng(run_.preview, field.width, field.height, sun_.direct(), 0.0f,
                           std::max(1e-6f, quantileRange(sun_.direct(), 0.0, 1.0).second));
      }
    }
    return {environment_.given() ? environment_.directions() : 1,
            lit.note + (lit_.flipped() ? " (lit north-up)" : "")};
  }

 private:
  EnvironmentLight environment_;
  SunShading sun_;
  NorthUp lit_;
  std::vector<std::vector<float>> albedo_;
};

// The light, given one way, and the options each light needs given with it.
void checkShade(const std::string&, const RunArguments& run) {
  const bool placed = run.sun_time || run.latitude || run.longitude;
  if (run.sun && placed)
    throw UsageError("--sun AZ,EL or --at TIME --lat LAT --lon LON: give the sun one way, not both");
  const bool sun = run.sun || (run.sun_time && run.latitude && run.longitude);
  if (!sun && placed) {  // a placed sun with a part missing: name it
    std::string missing;
    for (const auto& [given, name] : {std::pair{bool(run.sun_time), "--at TIME"},
                                      {bool(run.latitude), "--lat LAT"},
                                      {bool(run.longitude), "--lon LON"}})
      if (!given) missing += (missing.empty() ? "" : ", ") + std::string(name);
    throw UsageError("missing " + missing +
                     ": the sun at a time and place needs --at TIME --lat LAT --lon LON");
  }
  if (!sun && run.environment.empty())
    throw UsageError(
        "missing the light: --env ENV.exr and / or the sun, --sun AZ,EL (compass azimuth, elevation) or --at "
        "TIME "
        "--lat LAT --lon LON");
  if (run.environment.empty() && run.sweep_options_given)
    throw UsageError("-k, --method and --azimuth-offset need --env (the sun alone sweeps its own azimuth)");
  if (run.environment.empty() && (run.max_error > 0.0 || !run.error_output.empty()))
    throw UsageError("--max-error and --error-out need --env (the sun's shadow has no directions to choose)");
  if (run.max_error > 0.0 && run.directions_given)
    throw UsageError("shade: --max-error chooses K itself; give either it or -k");
  if (run.error_tile > 0)
    throw UsageError("shade: --error-tile refines the sky-view factor and occlusion only; the whole field takes one K here");
  if (!run.error_output.empty() && run.max_error == 0.0)
    throw UsageError("shade: --error-out needs --max-error (the estimate compares the runs at K and K / 2)");
  if (run.environment.empty() && (run.environment_rotation_deg != 0.0 || run.environment_rows != 0))
    throw UsageError("--env-rotate and --env-rows need --env ENV.exr");
  if (!sun && run.sun_irradiance != 1.0) throw UsageError("--sun-irradiance needs the sun");
  if (run.albedo.empty() && run.sun_irradiance != 1.0)
    throw UsageError(
        "--sun-irradiance needs --albedo (it scales the sun's light in the radiance; 'direct' is "
        "for a normal irradiance of 1)");
  if (!sun && run.sun_size_deg != 0.53) throw UsageError("--sun-size needs the sun");
  if (!run.environment.empty() && samePath(run.output, run.environment))
    throw UsageError("--env must differ from -o, both are " + inQuotes(run.output));
  if (!run.albedo.empty() && samePath(run.output, run.albedo))
    throw UsageError("--albedo must differ from -o, both are " + inQuotes(run.output));
  if (run.sun_time) {
    try {  // the solar position's range of years
      sunPosition(*run.sun_time, *run.latitude, *run.longitude);
    } catch (const InvalidArgument& error) {
      throw UsageError(std::string("--at: ") + error.what());
    }
  }
  asUsageError([&] { validate(static_cast<const SweepOptions&>(horizonOptions(run))); });
}

}  // namespace

const CommandSpec kShadeCommand{
    Command::Shade,
    "shade",
    nullptr,
    "--env: \"R\", \"G\", \"B\" (or \"Y\"), the irradiance from an HDR environment through the\n"
    "horizons; the sun: \"sun\", the part of its disc above the horizon (0..1), and\n"
    "\"direct\", sun * max(0, n . s); --albedo: \"radiance[.R/G/B]\", what the surface sends out",
    "IN -o OUT.exr [--env ENV.exr [--env-rotate DEG] [--env-rows N] [-k K | --max-error E\n"
    "[--error-out ERR.exr]]]\n"
    "[--sun AZ,EL | --at TIME --lat LAT --lon LON] [--sun-size DEG]\n"
    "[--albedo A|FILE [--sun-irradiance E]] [options]",
    "Lights the surface; give --env, the sun, or both.\n"
    "--env ENV.exr: an HDR environment, equirectangular (latitude / longitude, 2:1): row 0 at\n"
    "  the zenith, the last row at the nadir; the column at fraction u of the width looks toward\n"
    "  compass azimuth 360 u + DEG (--env-rotate; left edge north, a quarter east, the middle\n"
    "  south). One channel or R, G, B (an alpha channel is ignored). Channels R, G, B (or Y): the\n"
    "  irradiance at each point from the part of the environment above its horizons, for its\n"
    "  normal, in the environment's radiance times steradians (uniform radiance 1 gives pi on\n"
    "  open flat ground, pi times 'hfvis ambient-occlusion' everywhere). -k directions (default\n"
    "  64) and --method as for ambient-occlusion; --env-rows N bands of zenith angle in the tables\n"
    "  (default the map's rows, exact for a map constant over each pixel; fewer are faster to\n"
    "  build, not to light). -k, --method and --azimuth-offset need --env. --max-error E (0 < E\n"
    "  < 1): K chosen so that the 99th percentile of |irradiance at K - at K / 2| (the larger\n"
    "  of K / 2 on K's even and on its odd directions) over the field's mean irradiance is at\n"
    "  most E (every run also twice at K / 2); --error-out writes it.\n"
    "The sun: channel \"sun\" is the fraction of the sun's disc (--sun-size degrees across,\n"
    "  default 0.53; 0 = a point sun, hard shadows) above each pixel's horizon in the sun's\n"
    "  azimuth and above elevation 0 (level ground beyond the field); \"direct\" is sun * max(0,\n"
    "  n . s), the irradiance from a sun of normal irradiance 1. --sun AZ,EL (compass azimuth,\n"
    "  degrees clockwise from north; elevation, degrees), or where it stands at --at TIME seen\n"
    "  from --lat, --lon (as 'hfvis sun-position', geometric). Only the sun's azimuth is swept,\n"
    "  along the cheapest integer step within 0.02 degree of it (near the axes up to 1415 pixels\n"
    "  long, and as slow).\n"
    "--albedo A|FILE (a number in 0..1, or an image of the field's size, 1 or 3 channels): also\n"
    "  \"radiance\" (or radiance.R/G/B), albedo / pi times the irradiance: the environment's plus\n"
    "  the direct light times --sun-irradiance E (default 1; only with --albedo), a Lambertian\n"
    "  surface's radiance. An RGB GeoTIFF's bands (colour interpretation) read as R, G, B.\n"
    "Row 0 is taken as north (a south-up GeoTIFF is lit flipped north-up). The preview is the\n"
    "radiance or the irradiance tonemapped (ACES filmic, sRGB), or with the sun alone a\n"
    "hillshade with cast shadows: direct from 0 (black) to its largest value (white). NaN at\n"
    "nodata pixels.\n",
    nullptr,
    kSweptFieldGroups | kSweepMethodGroup | kSunPlaceGroup | kEnvironmentLightGroup | kSunShadingGroup |
        kErrorTargetGroup,
    checkShade,
    nullptr,
    pipelined<Shade>,
};

}  // namespace hfvis::cli
