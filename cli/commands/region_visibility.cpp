// cli/commands/region_visibility.cpp: "hfvis arealight" (the fraction of an area light's samples
// every pixel sees, and their bitmasks) and "hfvis region" (visibility between two rectangles, as
// JSON), the command line of hfvis/region_visibility.hpp.
#include "hfvis/region_visibility.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <limits>
#include <sstream>

#include "../image_outputs.hpp"
#include "../observer_files.hpp"
#include "../pipeline.hpp"
#include "core/number_text.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/image_io.hpp"

namespace hfvis::cli {
namespace {

// Bits per --masks channel: float32 holds every whole number up to 2^24 exactly, so 16 bits a
// channel keep the masks lossless in any float reader (the EXR writer has no UINT channels).
constexpr int kMaskBitsPerChannel = 16;


std::string rectangleText(const PixelRectangle& r) {
  return std::to_string(r.col0) + "," + std::to_string(r.row0) + "," + std::to_string(r.col1) + "," +
         std::to_string(r.row1);
}

// The library's checks of a region against the field: a usage error naming the option and the
// input, as the viewshed's observers.
void validateRegion(const HeightField& field, const RegionSampling& sampling, const std::string& what,
                    const std::string& input) {
  try {
    validate(field, sampling);
  } catch (const InvalidArgument& error) {
    throw UsageError(what + ": " + error.what() + " (" + input + ")");
  }
}

// The attributes of a run without directions or sampling density (as the viewshed's).
Attributes regionAttributes(const Job& job) {
  Attributes attributes = job.attributes(job.input, /*swept=*/false);
  attributes.emplace_back("hfvis:seed", std::to_string(job.run.seed));
  return attributes;
}

class AreaLight : public Computation {
 public:
  using Computation::Computation;

  std::vector<std::string> outputs() const override {
    std::vector<std::string> paths{run_.output};
    if (!run_.masks_output.empty()) paths.push_back(run_.masks_output);
    if (!run_.preview.empty()) paths.push_back(run_.preview);
    return paths;
  }
  std::vector<std::string> otherInputs() const override { return {run_.sources_file, run_.light_image}; }
  std::string method() const override { return regionVisibilityMethodName(run_.region_method); }

  // The light: --light's rectangle, or the --sources file's points, checked against the field.
  void prepare(HeightField& field) override {
    sources_.height = run_.light_height;
    sources_.absolute = run_.absolute;
    sources_.samples = run_.region_samples;
    if (run_.light) {
      sources_.rectangle = *run_.light;
    } else {
      sources_.points = readRegionPointFile(run_.sources_file, run_.light_height, run_.absolute);
      if (sources_.points.size() > static_cast<std::size_t>(kMaxRegionSamples))
        throw UsageError("--sources: " + run_.sources_file + " lists " +
                         std::to_string(sources_.points.size()) + " points, more than the " +
                         std::to_string(kMaxRegionSamples) + " samples a bitmask holds");
      sources_.samples = static_cast<int>(sources_.points.size());
      // (what checkAreaLight cannot see before the file is read: the bitmask method's light is planar)
      if (run_.region_method == RegionVisibilityMethod::Bitmask) {
        if (sources_.points.size() > static_cast<std::size_t>(kMaxBitmaskSamples))
          throw UsageError("--method bitmask takes at most " + std::to_string(kMaxBitmaskSamples) +
                           " samples; " + run_.sources_file + " lists " + std::to_string(sources_.points.size()) +
                           "; or --method exact or culled");
        for (const RegionPoint& p : sources_.points)
          if (p.height != sources_.points[0].height)
            throw UsageError("--method bitmask needs a planar light: the points of " + run_.sources_file +
                             " lie at different heights; or --method exact or culled");
      }
      // (the viewsheds method stands one viewshed's eye on each; the library would refuse later)
      if (run_.region_method == RegionVisibilityMethod::Viewsheds)
        for (const RegionPoint& p : sources_.points)
          if (p.col != std::floor(p.col) || p.row != std::floor(p.row))
            throw UsageError("--method viewsheds: the source " + formatNumber(p.col) + "," +
                             formatNumber(p.row) + " of " + run_.sources_file +
                             " lies between grid points; the viewsheds method needs whole columns and rows "
                             "(or --method exact)");
    }
    validateRegion(field, sources_, run_.light ? "--light " + rectangleText(*run_.light) : "--sources",
                   run_.input);
    if (!run_.light_image.empty()) readLightImage();
  }

  void compute(Job& job) override {
    RegionVisibilityOptions options = regionVisibilityOptions(run_);
    options.light_image = std::move(light_image_);
    result_ = computeRegionVisibility(*job.context, job.input, sources_, options);
    job.method = regionVisibilityMethodName(result_.method);  // the one that ran (auto picks bitmask or culled)
  }

  Summary write(Job& job, OutputFiles& outputs) override {
    const HeightField& input = job.input;
    requireResultSize(result_.width, result_.height, input);
    const std::size_t pixels = input.pixelCount();
    requireSize(result_.fraction, pixels, "visible fractions");
    if (result_.bits.size() != pixels * static_cast<std::size_t>(result_.words))
      throw Error("internal error: the computed bitmasks hold " + std::to_string(result_.bits.size()) +
                  " words, expected " + std::to_string(pixels * result_.words));
    Attributes attributes = regionAttributes(job);
    const std::string light =
        run_.light ? "rectangle " + rectangleText(*run_.light) + " (inclusive pixel corners)"
                   : std::to_string(sources_.points.size()) + " points from " + run_.sources_file;
    attributes.emplace_back("hfvis:light", light);
    attributes.emplace_back("hfvis:light_samples", std::to_string(result_.samples));
    if (run_.light)
      attributes.emplace_back(
          "hfvis:light_height",
          formatNumber(run_.light_height) + (run_.absolute ? " absolute (z-scaled)" : " above the surface"));
    attributes.emplace_back("hfvis:target_height", formatNumber(run_.target_height));
    attributes.emplace_back("hfvis:decorrelate", run_.decorrelate ? "1" : "0");
    const bool coloured = !run_.light_image.empty();
    if (coloured) {
      for (const auto* plane : {&result_.red, &result_.green, &result_.blue})
        requireSize(*plane, pixels, "colours");
      attributes.emplace_back("hfvis:light_image", run_.light_image);
    }
    std::vector<std::string> names{"visible"};
    std::vector<std::vector<float>> planes{result_.fraction};
    if (coloured) {
      names.insert(names.end(), {"R", "G", "B"});
      planes.insert(planes.end(), {result_.red, result_.green, result_.blue});
    }
    outputs.image(
        run_.output,
        job.image(
            input, names, std::move(planes), attributes,
            std::string("visible: the fraction of the light's samples seen from a receiver standing "
                        "the target height above each grid point") +
                (coloured ? "; R, G, B: the sum over the samples it sees of the light image's "
                            "bilinear colour at each sample, over the samples' count"
                          : ""),
            coloured ? "visible: 1 (0 .. 1); R, G, B: the light image's values" : "visible: 1 (0 .. 1)"));
    if (!run_.masks_output.empty()) {
      // Channel k: samples 16k .. 16k+15, bit b (2^b) for sample 16k+b; NaN at nodata.
      const int channels = (result_.samples + kMaskBitsPerChannel - 1) / kMaskBitsPerChannel;
      std::vector<std::vector<float>> planes(channels, std::vector<float>(pixels));
      for (std::size_t p = 0; p < pixels; ++p)
        for (int k = 0; k < channels; ++k) {
          const std::uint32_t word = result_.bits[p * result_.words + k / 2];
          planes[k][p] = std::isnan(result_.fraction[p])
                             ? NAN
                             : static_cast<float>((word >> (kMaskBitsPerChannel * (k % 2))) & 0xFFFFu);
        }
      Attributes mask_attributes = attributes;
      mask_attributes.emplace_back("hfvis:mask_bits_per_channel", std::to_string(kMaskBitsPerChannel));
      outputs.image(run_.masks_output,
                    job.image(input, directionChannelNames("m", channels), std::move(planes), mask_attributes,
                              "mNNN: the light's samples 16*NNN .. 16*NNN+15 a receiver sees, as the whole "
                              "number sum of 2^b over each visible sample 16*NNN+b",
                              "bit patterns (whole numbers 0 .. 65535)"));
    }
    if (!run_.preview.empty()) {
      // The fraction, bright, over a dimmed hillshade: a soft shadow over the relief, or a source
      // area's visual impact read against the terrain; nodata dark.
      const std::vector<float> shade = hillshade(input);
      std::vector<float> picture(result_.fraction.size());
      for (std::size_t p = 0; p < picture.size(); ++p)
        picture[p] = std::isfinite(result_.fraction[p]) ? 0.3f * shade[p] + 0.7f * result_.fraction[p] : NAN;
      outputs.previewPng(run_.preview, input.width, input.height, picture, 0.0f, 1.0f);
    }
    return {result_.samples, "; mean visible fraction " + formatFixed(finiteMean(result_.fraction), 4),
            "light sample"};
  }

 private:
  // --light-image: R, G, B (one grey channel: in all three), checked before any work.
  void readLightImage() {
    ImageChannels image = readColourImage(run_.light_image, "--light-image");
    light_image_.width = image.width;
    light_image_.height = image.height;
    for (int c = 0; c < 3; ++c) {
      const std::vector<float>& plane = image.planes[image.planes.size() == 1 ? 0 : c];
      light_image_.rgb.insert(light_image_.rgb.end(), plane.begin(), plane.end());
    }
    RegionVisibilityOptions options;
    options.light_image = light_image_;
    try {
      validate(options);
    } catch (const InvalidArgument& error) {
      throw IoError(run_.light_image, std::string("--light-image: ") + error.what());
    }
  }

  RegionSampling sources_;
  LightImage light_image_;
  RegionVisibilityResult result_;
};

// A number for JSON: 10 significant digits (as the other outputs' numbers: enough for a float32's
// pixel position, height or fraction), NaN as null.
std::string jsonNumber(double value) { return std::isfinite(value) ? formatNumber(value) : "null"; }

// A map coordinate or an echoed option: the fewest digits that read back as the same double (10
// digits left northings of 4.6e6 a millimetre apart, half a cell of 1 mm, and 1e15 the same x
// for every sample).
std::string jsonExact(double value) { return std::isfinite(value) ? detail::exactNumber(value) : "null"; }

// A ratio in full: a reader recomputing clear_pairs / pairs gets the same double.
std::string exactNumber(double value) {
  std::ostringstream out;
  out << std::setprecision(std::numeric_limits<double>::max_digits10) << value;
  return out.str();
}

// Map coordinates of a pixel position (grid points are pixel centres: column c lies at c + 0.5 in
// the geotransform of pixel corners).
std::pair<double, double> mapPosition(const std::array<double, 6>& t, double col, double row) {
  return {t[0] + (col + 0.5) * t[1] + (row + 0.5) * t[2], t[3] + (col + 0.5) * t[4] + (row + 0.5) * t[5]};
}

class Region : public Computation {
 public:
  using Computation::Computation;

  std::vector<std::string> outputs() const override {
    std::vector<std::string> paths{run_.output};
    if (!run_.rays_output.empty()) paths.push_back(run_.rays_output);
    return paths;
  }
  // Text outputs, computed on the device.
  bool writesImages() const override { return false; }
  bool usesDevice() const override { return true; }
  std::string method() const override {  // auto: the culled march (the bitmask method takes no pair)
    return regionVisibilityMethodName(run_.region_method == RegionVisibilityMethod::Auto ? RegionVisibilityMethod::Culled
                                                                         : run_.region_method);
  }

  void prepare(HeightField& field) override {
    from_ = sampling(*run_.from_region, run_.from_height);
    to_ = sampling(*run_.to_region, run_.to_height);
    validateRegion(field, from_, "--from " + rectangleText(*run_.from_region), run_.input);
    validateRegion(field, to_, "--to " + rectangleText(*run_.to_region), run_.input);
  }

  void compute(Job& job) override {
    result_ = computeRegionPairVisibility(*job.context, job.input, from_, to_, regionVisibilityOptions(run_));
  }

  Summary write(Job& job, OutputFiles& outputs) override {
    const RegionPairVisibilityResult& r = result_;
    if (r.sources.size() != static_cast<std::size_t>(r.source_samples) ||
        r.receivers.size() != static_cast<std::size_t>(r.receiver_samples) ||
        r.bits.size() != static_cast<std::size_t>(r.receiver_samples) * r.words)
      throw Error("internal error: the region pair's samples or bitmasks are not of the sizes asked for");
    const auto& transform = job.input.georeference.geotransform;
    const double fraction = r.pairs ? double(r.clear_pairs) / double(r.pairs) : 0.0;
    std::ostringstream json;
    // A sample: where it lies (pixel and, georeferenced, map), its height and the share it sees.
    const auto samples = [&](const std::vector<RegionPoint>& points, const std::vector<float>& fractions) {
      std::string out = "[";
      for (std::size_t i = 0; i < points.size(); ++i) {
        const RegionPoint& p = points[i];
        out += std::string(i ? "," : "") + "\n    {\"col\": " + jsonNumber(p.col) +
               ", \"row\": " + jsonNumber(p.row) + ", \"height\": " + jsonNumber(p.height);
        if (transform) {
          const auto [x, y] = mapPosition(*transform, p.col, p.row);
          out += ", \"x\": " + jsonExact(x) + ", \"y\": " + jsonExact(y);
        }
        out += ", \"visible_fraction\": " + jsonNumber(fractions[i]) + "}";
      }
      return out + "\n  ]";
    };
    const auto region = [&](const PixelRectangle& rect, double height, int count) {
      return "{\"rectangle\": [" + rectangleText(rect) + "], \"height\": " + jsonExact(height) +
             ", \"height_is\": " + jsonString(run_.absolute ? "absolute (z-scaled)" : "above the surface") +
             ", \"samples\": " + std::to_string(count) + "}";
    };
    json << "{\n"
         << "  \"command\": \"region\",\n"
         << "  \"input\": " << jsonString(run_.input) << ",\n"
         << "  \"method\": " << jsonString(job.method) << ",\n"
         << "  \"seed\": " << run_.seed << ",\n"
         << "  \"max_distance\": " << jsonExact(run_.max_distance) << ",\n"
         << "  \"curvature\": "
         << (run_.curvature ? jsonNumber(regionVisibilityOptions(run_).curvature) : std::string("0")) << ",\n"
         << "  \"from\": " << region(*run_.from_region, run_.from_height, r.source_samples) << ",\n"
         << "  \"to\": " << region(*run_.to_region, run_.to_height, r.receiver_samples) << ",\n"
         << "  \"pairs\": " << r.pairs << ",\n"
         << "  \"clear_pairs\": " << r.clear_pairs << ",\n"
         << "  \"visible_fraction\": " << exactNumber(fraction) << ",\n"
         << "  \"conventions\": "
         << jsonString(
                "col, row: pixel columns and rows (grid points at whole numbers, samples between them); "
                "height: absolute, z-scaled height units; x, y: map coordinates of a georeferenced input; "
                "a from sample's visible_fraction: the to samples it sees / their count, a to sample's: the "
                "from samples it sees / their count; a pair is clear when no point of the bilinear surface "
                "strictly between its ends rises above the segment")
         << ",\n"
         << "  \"from_samples\": " << samples(r.sources, r.source_fraction) << ",\n"
         << "  \"to_samples\": " << samples(r.receivers, r.receiver_fraction) << "\n"
         << "}\n";
    outputs.text(run_.output, json.str());
    if (!run_.rays_output.empty()) {
      std::string csv = "from_col,from_row,from_height,to_col,to_row,to_height";
      if (transform) csv += ",from_x,from_y,to_x,to_y";
      csv += "\n";
      for (int t = 0; t < r.receiver_samples; ++t)
        for (int s = 0; s < r.source_samples; ++s) {
          if (!r.visible(t, s)) continue;
          const RegionPoint &a = r.sources[s], &b = r.receivers[t];
          csv += formatNumber(a.col) + "," + formatNumber(a.row) + "," + formatNumber(a.height) + "," +
                 formatNumber(b.col) + "," + formatNumber(b.row) + "," + formatNumber(b.height);
          if (transform) {
            const auto [ax, ay] = mapPosition(*transform, a.col, a.row);
            const auto [bx, by] = mapPosition(*transform, b.col, b.row);
            csv += "," + detail::exactNumber(ax) + "," + detail::exactNumber(ay) + "," +
                   detail::exactNumber(bx) + "," + detail::exactNumber(by);
          }
          csv += "\n";
        }
      outputs.text(run_.rays_output, csv);
    }
    return {r.source_samples,
            "; " + std::to_string(r.clear_pairs) + " of " + std::to_string(r.pairs) + " pairs clear (" +
                formatFixed(100.0 * fraction, 2) + " %)",
            "sample"};
  }

 private:
  RegionSampling sampling(const PixelRectangle& rectangle, double height) const {
    RegionSampling s;
    s.rectangle = rectangle;
    s.samples = run_.region_samples;
    s.height = height;
    s.absolute = run_.absolute;
    return s;
  }

  RegionSampling from_, to_;
  RegionPairVisibilityResult result_;
};

// A height below the surface is hidden (the surface rises above every segment beside it).
void requireAboveSurface(const RunArguments& run, const char* option, double height) {
  if (!run.absolute && height < 0.0)
    throw UsageError(
        std::string(option) +
        ": a sample below the surface is hidden from everything; give a height >= 0 (or --absolute)");
}

void checkAreaLight(const std::string&, const RunArguments& run) {
  if (run.light && !run.sources_file.empty())
    throw UsageError("--light and --sources both give the light; give one of them");
  if (!run.light && run.sources_file.empty())
    throw UsageError("missing --light C0,R0,C1,R1 or --sources FILE.csv (the area light)");
  if (!run.light_image.empty() && !run.light)
    throw UsageError("--light-image colours a --light rectangle, not --sources points");
  if (!run.sources_file.empty() && run.region_samples_given)
    throw UsageError("--samples is for --light: the --sources file's points are the samples");
  if (!run.sources_file.empty() && (run.seed_given || run.decorrelate))
    throw UsageError(std::string(run.decorrelate ? "--decorrelate" : "--seed") +
                     " jitters a --light's samples; the --sources file's points stand where they are");
  if (run.memory_budget_bytes != 0)
    throw UsageError(
        "--memory-budget is not available with 'hfvis arealight' (its buffers are not budgeted)");
  requireAboveSurface(run, "--light-height", run.light_height);
  if (run.region_method == RegionVisibilityMethod::Viewsheds) {
    if (run.decorrelate)
      throw UsageError(
          "--decorrelate needs --method exact or culled (the viewsheds method shares the samples)");
    if (run.light && (run.light->col0 != run.light->col1 || run.light->row0 != run.light->row1))
      throw UsageError(
          "--method viewsheds needs the light's samples on grid points: a one-pixel --light or --sources "
          "FILE.csv (a larger rectangle's samples are jittered between them); or --method exact or culled");
  }
  if (run.region_method == RegionVisibilityMethod::Bitmask) {
    if (!run.absolute)
      throw UsageError(
          "--method bitmask needs a planar light: --absolute (a --light rectangle at one height, or "
          "--sources "
          "points all at one height); or --method exact or culled");
    if (run.decorrelate)
      throw UsageError(
          "--decorrelate needs --method exact or culled (the bitmask method shares the samples)");
    if (run.curvature)
      throw UsageError(
          "--curvature and --refraction need --method exact or culled (the bitmask method's "
          "back-projections are straight)");
    if (run.region_samples > kMaxBitmaskSamples)
      throw UsageError("--method bitmask takes at most " + std::to_string(kMaxBitmaskSamples) +
                       " samples (got " + std::to_string(run.region_samples) +
                       "); or --method exact or culled");
  }
  if (!run.masks_output.empty() && samePath(run.output, run.masks_output))
    throw UsageError("--masks must differ from -o, both are " + inQuotes(run.output));
  asUsageError([&] { validate(regionVisibilityOptions(run)); });
}

void checkRegion(const std::string&, const RunArguments& run) {
  if (run.memory_budget_bytes != 0)
    throw UsageError("--memory-budget is not available with 'hfvis region' (its buffers are not budgeted)");
  if (!hasExtension(run.output, ".json"))
    throw UsageError("-o: 'hfvis region' writes JSON; the name must end in .json, got " +
                     namedAs(run.output));
  if (!run.from_region || !run.to_region)
    throw UsageError(std::string("missing ") + (run.from_region ? "--to" : "--from") +
                     " C0,R0,C1,R1 (region pairs need --from and --to rectangles)");
  if (!run.rays_output.empty() && !hasExtension(run.rays_output, ".csv"))
    throw UsageError("--rays: the rays are written as CSV; the name must end in .csv, got " +
                     namedAs(run.rays_output));
  if (run.region_method == RegionVisibilityMethod::Viewsheds ||
      run.region_method == RegionVisibilityMethod::Bitmask)
    throw UsageError(std::string("--method ") + regionVisibilityMethodName(run.region_method) +
                     " is for 'hfvis arealight' (every pixel a receiver); region pairs take --method "
                     "exact or culled");
  requireAboveSurface(run, "--from-height", run.from_height);
  requireAboveSurface(run, "--to-height", run.to_height);
  asUsageError([&] { validate(regionVisibilityOptions(run)); });
}

}  // namespace

const CommandSpec kAreaLightCommand{
    Command::AreaLight,
    "arealight",
    nullptr,
    "\"visible\": the fraction (0..1) of an area light's samples each pixel sees",
    "IN -o OUT.exr|OUT.tif (--light C0,R0,C1,R1 [--light-height H] | --sources FILE.csv)\n"
    "[--absolute] [--samples N] [--target-height T] [--decorrelate]\n"
    "[--method auto|exact|culled|viewsheds|bitmask]\n"
    "[--seed N] [--light-image RGB.exr] [--max-distance D] [--curvature] [--refraction K]\n"
    "[--masks MASKS.exr] [--preview P.png] [options]",
    "Region visibility with every pixel a receiver (Eisemann & Decoret 2007's sampled\n"
    "visibility): channel \"visible\" is the fraction (0..1) of the light's samples seen from a\n"
    "receiver T (default 0) above each grid point; NaN at nodata (a GeoTIFF's --nodata value).\n"
    "The light: --light C0,R0,C1,R1, the rectangle of grid points between two corner pixels\n"
    "(zero-based columns and rows, inclusive, in any order), sampled N times (--samples,\n"
    "default 16, at most 4096): about square strata, each sample jittered in its stratum by a\n"
    "hash of (--seed, the rectangle, sample), H (--light-height, default 2) above the bilinear\n"
    "surface under it, or at height H with --absolute (an area light in a horizontal plane); or\n"
    "--sources FILE.csv,\n"
    "the samples themselves, one col,row[,height] a line (a header line, a UTF-8 BOM, CRLF and\n"
    "'#' comments allowed; fractional columns and rows lie between pixel centres; a missing\n"
    "height is --light-height). Every pixel sees the same samples, unless --decorrelate (each\n"
    "its own jitter: noise instead of banding). A pair sees as in the viewshed: no point of the\n"
    "bilinear surface strictly between them rises above the segment (grazing sees; cells with a\n"
    "nodata corner hide nothing); --max-distance D: farther pairs are hidden; --curvature and\n"
    "--refraction lower the surface between them by the Earth's drop.\n"
    "--masks FILE (.exr or .tif) also writes which samples each pixel sees, losslessly: float32\n"
    "channels m000, m001, ..., channel k holding samples 16k .. 16k+15 as the whole number sum\n"
    "of 2^b over each visible sample 16k+b (0 .. 65535, exact in float32; NaN at nodata).\n"
    "--method exact marches one sight line per pixel and sample, culled the same lines\n"
    "leaping over low blocks; --method viewsheds runs one viewshed per sample, for\n"
    "samples on grid points (a one-pixel --light, --sources with whole columns and rows), not\n"
    "with --decorrelate; it may decide grazing lines the other way. --method bitmask (a --light\n"
    "at an --absolute height, at most 1024 samples, no --decorrelate or --curvature) scatters\n"
    "the cells' back-projections onto the light's plane through a table of edge bitmasks and\n"
    "marches only the samples it leaves undecided: the exact bits. --method auto (default)\n"
    "takes bitmask where it takes the light and N is 64 or more (faster there), else culled;\n"
    "the summary and hfvis:method name the one that ran. A light outside the field, or on\n"
    "nodata, is an error.\n"
    "--light-image FILE (an EXR or any image hfvis reads; R, G, B, or one grey channel) colours\n"
    "the --light rectangle (Eisemann & Decoret 2007's textured light): the image stretched over\n"
    "it, row 0 along the lowest row, each sample taking the image's bilinear colour at its own\n"
    "jittered position; channels R, G, B are the colours of the samples a pixel sees, summed,\n"
    "over N (a white image of 1 gives R = G = B = visible; NaN at nodata). A missing image, other\n"
    "channels, or a negative or non-finite value is an error before any work.\n"
    "The preview shows the fraction, bright (1) to dark (0), over a dimmed hillshade.\n",
    nullptr,
    kImageCommandGroups | kEarthGroup | kReachGroup | kRegionSamplingGroup | kAreaLightGroup,
    checkAreaLight,
    nullptr,
    pipelined<AreaLight>,
};

const CommandSpec kRegionCommand{
    Command::Region,
    "region",
    nullptr,
    "visibility between two rectangles: the share of clear sample pairs, as JSON",
    "IN --from C0,R0,C1,R1 --to C0,R0,C1,R1 -o OUT.json [--from-height H] [--to-height H]\n"
    "[--absolute] [--samples N] [--seed N] [--method auto|exact|culled] [--max-distance D] [--curvature]\n"
    "[--refraction K] [--rays RAYS.csv] [options]",
    "Visibility between two regions: N samples of each rectangle (--samples, default 16, at most\n"
    "4096; sampled as arealight's --light), H above the surface (--from-height, --to-height,\n"
    "default 2; --absolute: at height H), every sample of --from against every sample of --to.\n"
    "Writes JSON: pairs (N * N), clear_pairs (the pairs whose segment the surface does not\n"
    "block), visible_fraction = clear_pairs / pairs; the rectangles and options; and each\n"
    "sample (from_samples, to_samples) with its col, row, absolute z-scaled height, map x, y\n"
    "(a georeferenced input) and visible_fraction, the share of the other region's samples it\n"
    "sees. --rays RAYS.csv also lists every clear pair, one a line:\n"
    "from_col,from_row,from_height,to_col,to_row,to_height (and from_x,from_y,to_x,to_y for a\n"
    "georeferenced input; map coordinates of the pixel centres). A rectangle outside the field\n"
    "or holding nodata is an error. Computed on the device: --method exact, or culled (the same\n"
    "bits sooner; auto, the default, takes it).\n",
    nullptr,
    kOutputGroup | kInputGroup | kDeviceGroup | kEarthGroup | kReachGroup | kRegionSamplingGroup |
        kRegionPairGroup,
    checkRegion,
    nullptr,
    pipelined<Region>,
};

}  // namespace hfvis::cli
