// cli/commands/viewshed.cpp: "hfvis viewshed": what one observer sees, or how many of several see
// each point (hfvis/viewshed.hpp).
#include "hfvis/viewshed.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "../image_outputs.hpp"
#include "../observer_files.hpp"
#include "../pipeline.hpp"
#include "hfvis/errors.hpp"

namespace hfvis::cli {
namespace {

class Viewshed : public Computation {
 public:
  using Computation::Computation;

  std::string method() const override { return run_.culled ? "culled" : "exact"; }
  // The observers file is an input too: no output (-o, --preview, through a link or not) may
  // replace it.
  std::vector<std::string> otherInputs() const override { return {run_.observers_file}; }

  // The observers: --observer's, then the --observers file's, each checked against the field.
  void prepare(HeightField& field) override {
    for (const ReceiverPixel& p : run_.observers) observers_.push_back({p.col, p.row, run_.observer_height});
    if (!run_.observers_file.empty()) {
      const std::vector<Observer> listed =
          readObserverFile(run_.observers_file, run_.observer_height, run_.absolute);
      observers_.insert(observers_.end(), listed.begin(), listed.end());
    }
    for (const Observer& o : observers_) {
      try {
        validate(field, o);
      } catch (const InvalidArgument& error) {
        throw UsageError(std::string(error.what()) + " (" + run_.input + ")");
      }
    }
  }

  void compute(Job& job) override {
    // Compass azimuths (--fov) take row 0 as north and column 0 as west: a south-up or west-up
    // GeoTIFF is computed flipped, its observers with it, and its results flipped back.
    lit_ = northUp(job.input);
    const HeightField& field = lit_.field();
    std::vector<Observer> placed = observers_;
    for (Observer& o : placed) lit_.place(o);
    ViewshedOptions options = viewshedOptions(run_);
    // --method culled: the pyramid first, for this field, target height and curvature.
    std::optional<ViewshedPyramid> pyramid;
    std::string cull_note;
    if (run_.culled) {
      ViewshedPyramidOptions p;
      p.target_height = options.target_height;
      p.curvature = options.curvature;
      p.finest_level = run_.cull_level;
      p.memory_budget_bytes = run_.memory_budget_bytes;
      Progress building(run_.quiet);
      p.progress = building.callback(p.sectors * p.directions_per_sector, "pyramid directions");
      pyramid = building.run([&] { return buildViewshedPyramid(*job.context, field, p); });
      options.pyramid = &*pyramid;
      cull_note = "; culling pyramid " + formatFixed(pyramid->build_seconds, 2) + " s, " +
                  formatFixed(pyramid->bytes() / (1024.0 * 1024.0), 1) + " MiB";
    }
    if (observers_.size() == 1) {
      ViewshedOutputs outputs;
      outputs.angle = run_.with_angle;
      outputs.needed_height = run_.with_needed_height;
      ViewshedResult r = computeViewshed(*job.context, field, placed[0], options, outputs);
      requireResultSize(r.width, r.height, field);
      lit_.restore(r.visible);
      lit_.restore(r.angle);
      lit_.restore(r.needed_height);
      if (run_.with_angle) {
        for (float& a : r.angle) a = static_cast<float>(a * (180.0 / M_PI));
        names_.push_back("angle");
        planes_.push_back(std::move(r.angle));
      }
      if (run_.with_needed_height) {  // sorts between "angle" and "visible"
        names_.push_back("needed_height");
        planes_.push_back(std::move(r.needed_height));
      }
      std::size_t seen = 0, targets = 0;
      for (float v : r.visible) seen += v == 1.0f, targets += !std::isnan(v);
      note_ = "; " + formatFixed(100.0 * seen / std::max<std::size_t>(targets, 1), 2) +
              " % of the points visible";
      if (pyramid)
        note_ += cull_note + "; " + formatFixed(100.0 * r.culled / std::max<std::size_t>(targets, 1), 2) +
                 " % of the points culled";
      names_.push_back("visible");
      planes_.push_back(std::move(r.visible));
      quantity_ =
          "visible: 1 where a target on the point is seen from the observer's eye, 0 where hidden or out of "
          "range" +
          std::string(run_.with_angle ? "; angle: the target's elevation angle from the eye" : "") +
          (run_.with_needed_height ? "; needed_height: the height above the surface a target there needs to "
                                     "be seen (NaN out of range)"
                                   : "");
      units_ = std::string("visible: 1") + (run_.with_angle ? "; angle: degrees" : "") +
               (run_.with_needed_height ? "; needed_height: height units" : "");
    } else {
      options.progress = job.progress.callback(static_cast<int>(observers_.size()), "observers");
      CumulativeViewshed c =
          job.progress.run([&] { return computeCumulativeViewshed(*job.context, field, placed, options); });
      requireResultSize(c.width, c.height, field);
      lit_.restore(c.count);
      float most = 0.0f;
      for (float v : c.count)
        if (v > most) most = v;
      note_ = "; " + std::to_string(observers_.size()) + " observers, at most " + formatNumber(most) +
              " see one point" + cull_note;
      names_.push_back("count");
      planes_.push_back(std::move(c.count));
      quantity_ = "count: how many of the observers see a target on the point (a cumulative viewshed)";
      units_ = "observers";
    }
  }

  Summary write(Job& job, OutputFiles& outputs) override {
    const HeightField& input = job.input;
    Attributes attributes = job.attributes(input, /*swept=*/false);
    std::string where;
    for (const Observer& o : observers_) {
      if (where.size() > 4000) {
        where += " ...";
        break;
      }
      where += (where.empty() ? "" : "; ") + std::to_string(o.col) + "," + std::to_string(o.row) + " at " +
               formatNumber(o.height);
    }
    attributes.emplace_back("hfvis:observers", where);
    attributes.emplace_back("hfvis:observer_height", run_.absolute ? "absolute" : "above the surface");
    attributes.emplace_back("hfvis:target_height", formatNumber(viewshedOptions(run_).target_height));
    if (run_.field_of_view)
      attributes.emplace_back("hfvis:field_of_view_deg", formatNumber(run_.field_of_view->first) + " .. " +
                                                             formatNumber(run_.field_of_view->second));
    if (run_.elevation_range)
      attributes.emplace_back(
          "hfvis:elevation_range_deg",
          formatNumber(run_.elevation_range->first) + " .. " + formatNumber(run_.elevation_range->second));
    const ImageChannels image = job.image(input, names_, std::move(planes_), attributes, quantity_, units_);
    outputs.image(run_.output, image);
    if (!run_.preview.empty()) {
      // Visible points (or the count) bright over a dimmed hillshade; nodata black.
      const std::vector<float>& seen = image.planes.back();
      float most = 0.0f;
      for (float v : seen)
        if (v > most) most = v;
      const std::vector<float> shade = hillshade(input);
      std::vector<float> picture(seen.size());
      for (std::size_t p = 0; p < seen.size(); ++p)
        picture[p] =
            std::isnan(seen[p])
                ? NAN
                : 0.3f * shade[p] + (seen[p] > 0.0f ? 0.35f + 0.35f * seen[p] / std::max(most, 1.0f) : 0.0f);
      outputs.previewPng(run_.preview, input.width, input.height, picture, 0.0f, 1.0f);
    }
    return {static_cast<int>(observers_.size()), note_ + (lit_.flipped() ? " (computed north-up)" : ""),
            "observer"};
  }

 private:
  std::vector<Observer> observers_;
  NorthUp lit_;
  std::vector<std::string> names_;
  std::vector<std::vector<float>> planes_;
  std::string quantity_, units_, note_;
};

void checkViewshed(const std::string&, const RunArguments& run) {
  if (!run.absolute && run.observer_height < 0.0)
    throw UsageError(
        "--observer-height: an eye below the surface sees nothing; give a height >= 0 (or --absolute)");
  if (run.observers.empty() && run.observers_file.empty())
    throw UsageError("missing --observer COL,ROW or --observers FILE.csv (who looks)");
  if ((run.with_angle || run.with_needed_height) && (run.observers.size() > 1 || !run.observers_file.empty()))
    throw UsageError(std::string(run.with_angle ? "--angle" : "--needed-height") +
                     " is for one observer given by --observer (several, or a file of them, give a count)");
  if (run.cull_level_given && !run.culled) throw UsageError("--cull-level is for --method culled");
  if (!run.observers_file.empty() && samePath(run.output, run.observers_file))
    throw UsageError("--observers must differ from -o, both are " + inQuotes(run.output));
  asUsageError([&] { validate(viewshedOptions(run)); });
}

// The angle channel (--angle) reaches down to -90 degrees; "visible" and "count" start at 0.
double lowestValue(const RunArguments& run) { return run.with_angle ? -90.0 : 0.0; }

}  // namespace

const CommandSpec kViewshedCommand{
    Command::Viewshed,
    "viewshed",
    nullptr,
    "\"visible\" (1 / 0): what one observer sees; with several observers \"count\"",
    "IN -o OUT.exr --observer COL,ROW [--observer COL,ROW ...] [--observers FILE.csv]\n"
    "[--observer-height H] [--target-height T] [--absolute] [--max-distance D]\n"
    "[--curvature] [--refraction K] [--fov FROM,TO] [--elevation-range LO,HI]\n"
    "[--angle] [--needed-height] [--method exact|culled] [--cull-level K] [options]",
    "What an observer standing on grid point COL,ROW (zero-based) sees: channel \"visible\" is 1\n"
    "where a target standing T (default 0) above the surface is seen from the eye H (default 2)\n"
    "above the surface (--absolute: at height H), 0 where it is hidden or out of range, NaN at\n"
    "nodata. Seen means no point of the bilinear surface strictly between eye and target rises\n"
    "above the straight sight line (grazing sees); cells with a nodata corner hide nothing.\n"
    "Decided exactly for every target, up to single-precision rounding of sight lines that\n"
    "graze. --max-distance D: targets within D ground units; --fov FROM,TO: targets whose\n"
    "compass azimuth lies clockwise from FROM to TO; --elevation-range LO,HI: targets seen\n"
    "between LO and HI degrees above the eye's horizontal; --curvature and --refraction lower\n"
    "every point, targets too, by the Earth's drop. --angle adds channel \"angle\", the target's\n"
    "elevation angle from the eye in degrees; --needed-height channel \"needed_height\", the height\n"
    "above the surface a target there needs to be seen (0 where one on the surface is; NaN out of\n"
    "range; every sight line is marched in full, much slower).\n"
    "Several observers (--observer repeated, and / or --observers FILE.csv with columns\n"
    "col,row[,height], a header line allowed): channel \"count\", how many of them see each\n"
    "point (a cumulative viewshed); a row's height replaces --observer-height. An observer\n"
    "outside the field or on nodata is an error.\n"
    "--method culled first builds Stewart's culling pyramid (horizons swept in 128 directions,\n"
    "occlusion regions per point and sector combined up a quadtree, nodes of 2^K x 2^K points\n"
    "from --cull-level K, default 2) and skips the targets of every node it shows hidden: the\n"
    "same result as --method exact; worth it for many observers, where one pyramid serves all.\n"
    "The preview shows the visible points (or the count) bright over a dimmed hillshade.\n",
    nullptr,
    kImageCommandGroups | kEarthGroup | kReachGroup | kViewshedGroup,
    checkViewshed,
    lowestValue,
    pipelined<Viewshed>,
};

}  // namespace hfvis::cli
