// viewshed.cpp: from-point visibility (see hfvis/viewshed.hpp): the field goes to the device
// once per call; per observer the rays' bounds and the targets (kernels/viewshed.cl).
#include "hfvis/viewshed.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/horizon_common.hpp"
#include "core/number_text.hpp"
#include "core/opencl_context.hpp"
#include "core/sweep_framework.hpp"
#include "core/sweep_geometry.hpp"
#include "core/sweep_routine.hpp"
#include "hfvis/errors.hpp"

namespace hfvis {
namespace {

constexpr double kDegree = M_PI / 180.0;
// Boxes whose farthest point is nearer than this many pixels march every target: their rays
// would be as long as the sight lines.
constexpr double kLeastRayPixels = 24.0;

// The kernels' Field struct.
struct DeviceField {
  cl_int width, height;
  cl_float cell_x, cell_y;
  cl_float curvature;
};

bool finiteIn(double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; }

// The grid points analysed: the field clipped to the maximum distance around the observer.
cl_int4 targetBox(const HeightField& field, const Observer& o, double max_distance) {
  cl_int4 box{{0, 0, field.width - 1, field.height - 1}};
  if (max_distance > 0.0) {
    const double rx = std::floor(max_distance / field.cell_size_x), ry = std::floor(max_distance / field.cell_size_y);
    box.s[0] = static_cast<int>(std::max(0.0, o.col - rx));
    box.s[1] = static_cast<int>(std::max(0.0, o.row - ry));
    box.s[2] = static_cast<int>(std::min(field.width - 1.0, o.col + rx));
    box.s[3] = static_cast<int>(std::min(field.height - 1.0, o.row + ry));
  }
  return box;
}

// The viewsheds of a call, one routine item per observer, over one field whose device side
// (the heights, the rays' slope bounds, the maximum pyramid, the culling pyramid) is set up
// once: one observer's outputs, or (counting) per point the number of observers that see it.
class ViewshedRoutine : public detail::DeviceRoutine {
 public:
  // `outputs` null: count (the cumulative viewshed, which reports progress per observer).
  ViewshedRoutine(detail::ContextState& st, const HeightField& field, const ViewshedOptions& options,
                  const std::vector<Observer>& observers, const ViewshedOutputs* outputs)
      : DeviceRoutine(st, field, outputs ? nullptr : options.progress, options.memory_budget_bytes),
        options_(options),
        observers_(observers),
        outputs_(outputs),
        lanes_(detail::simdLanes(st)) {}

  // After run(): the outputs asked for (visible holds the counts when counting) and the
  // statistics.
  ViewshedResult take() { return std::move(result_); }

 private:
  bool counting() const { return outputs_ == nullptr; }

  // Heights as the observers' and targets' heights are given: scaled, not moved to the lowest.
  detail::PreparedHeights prepare() override {
    return detail::prepareHeights(field_, detail::HeightOrigin::Zero);
  }
  std::string programFile() const override { return "viewshed.cl"; }
  std::string programOptions() const override { return "-DHFVIS_LANES=" + std::to_string(lanes_); }

  // The plan (whether the rays' bounds fit the budget), the per-field bounds and pyramids,
  // the per-observer scratch and the outputs.
  void allocate() override {
    device_ = {field_.width, field_.height, static_cast<float>(field_.cell_size_x),
               static_cast<float>(field_.cell_size_y), static_cast<float>(options_.curvature)};
    const std::size_t pixels = field_.pixelCount();
    // The rays' upper bounds, a float per point, where the budget leaves room for them (else
    // every target is marched).
    ray_hi_budgeted_ = pixels * sizeof(float) <= memoryBudget() / 2;
    boundSlopes();
    buildPyramid();
    if (options_.pyramid) uploadCulling(*options_.pyramid);
    ray_hi_ = detail::deviceBuffer(st_, ray_hi_budgeted_ ? pixels * sizeof(float) : sizeof(float));
    pending_ = detail::deviceBuffer(st_, pixels);
    pending_list_ = detail::deviceBuffer(st_, pixels * sizeof(cl_uint));
    row_counts_ = detail::deviceBuffer(st_, static_cast<std::size_t>(field_.height) * sizeof(cl_uint));
    visible_ = counting() ? zeros(pixels) : output();
    if (!counting() && outputs_->angle) angle_ = output();
    if (!counting() && outputs_->needed_height) needed_ = output();
  }

  int itemCount() const override { return static_cast<int>(observers_.size()); }
  void runItem(int item, int) override { observe(observers_[item]); }

  void finish() override {
    result_.width = field_.width;
    result_.height = field_.height;
    result_.marched = pending_targets_;
    result_.culled = culled_targets_;
    if (counting() || outputs_->visible) result_.visible = read(visible_);
    if (counting()) return;
    if (outputs_->angle) result_.angle = read(angle_);
    if (outputs_->needed_height) result_.needed_height = read(needed_);
    if (outputs_->culled_mask) result_.culled_mask = culledMask();
  }

  // One observer: what needs no sight line settled, the rays, the march of what they leave, and
  // the needed heights.
  void observe(const Observer& o) {
    const float ze = static_cast<float>(
        options_.absolute
            ? o.height
            : prepared_.heights[static_cast<std::size_t>(o.row) * field_.width + o.col] + o.height);
    const cl_int4 box = targetBox(field_, o, options_.max_distance);
    forgiven_ = forgivenRise(ze);
    const cl_int4 cull_leaf = cull(o, ze);
    const int w1 = box.s[2] - box.s[0], h1 = box.s[3] - box.s[1];
    const double far_pixels = std::max({o.col - box.s[0], box.s[2] - o.col, o.row - box.s[1], box.s[3] - o.row});
    const bool use_rays = ray_hi_budgeted_ && !options_.march_every_target && w1 >= 1 && h1 >= 1 &&
                          far_pixels >= kLeastRayPixels;
    classify(o, ze, box, cull_leaf, use_rays);
    // The rays settle most pending targets, or leave them an upper bound for the march.
    if (use_rays) castRays(o, ze, box, cull_leaf);
    marchPending(o, ze, use_rays);
    if (!counting() && outputs_->needed_height) markNeeded(o, ze);
    st_.queue.finish();  // before this observer's ray buffers go
  }

  // The field's largest |height| as the kernels see it (0 when none is finite): what bounds the
  // rounding a sight line forgives and the culling pyramid's margins.
  double largestHeight() const {
    const double top = std::max(std::fabs(double(prepared_.lowest)), std::fabs(double(prepared_.highest)));
    return std::isfinite(top) ? top : 0.0;
  }

  // The most that a sight line from an eye at height ze to any target forgives (forgiven_rise in
  // kernels/viewshed.cl: 2^-21 of |ze| + the target's |height| + the curvature's drop, bounded
  // by the field's largest |height| plus the target height and the drop across the field): the
  // rays hide a target only where the surface rises above its sight line by more.
  float forgivenRise(float ze) const {
    const double across = std::hypot(field_.width * field_.cell_size_x, field_.height * field_.cell_size_y);
    const double drop = std::fabs(options_.curvature) * across * across;
    return static_cast<float>(
        std::ldexp(std::fabs(double(ze)) + largestHeight() + options_.target_height + 2.0 * drop, -21) *
        (1.0 + 1e-5));
  }

  // The arguments of the kernels that follow sight lines from eye o at height ze: the field,
  // the eye and the targets' height above the ground.
  void setEye(detail::NamedKernel& k, const Observer& o, float ze) const {
    k.set("h", heights_);
    k.set("f", device_);
    k.set("ex_i", o.col);
    k.set("ey_i", o.row);
    k.set("ze", ze);
    k.set("target_height", static_cast<float>(options_.target_height));
  }

  // The field of view's arguments: the maximum distance, the azimuths (their span clockwise in
  // degrees; 360, equal azimuths or 0 and 360, is the whole circle) and the elevations.
  void setFieldOfView(detail::NamedKernel& k) const {
    double az_span = std::fmod(options_.azimuth_to_deg - options_.azimuth_from_deg, 360.0);
    if (az_span < 0.0) az_span += 360.0;
    if (az_span == 0.0) az_span = 360.0;
    k.set("max_distance", static_cast<float>(options_.max_distance));
    k.set("az_on", az_span < 360.0 ? 1 : 0);
    k.set("az_from", static_cast<float>(options_.azimuth_from_deg));
    k.set("az_span", static_cast<float>(az_span));
    k.set("el_lo", static_cast<float>(options_.elevation_min_deg * kDegree));
    k.set("el_hi", static_cast<float>(options_.elevation_max_deg * kDegree));
  }

  // Settles what needs no sight line; the rest is pending, for the rays and then the march.
  void classify(const Observer& o, float ze, const cl_int4& box, const cl_int4& cull_leaf, bool use_rays) {
    const bool angle = !counting() && outputs_->angle;
    detail::NamedKernel k = kernel("viewshed_classify");
    setEye(k, o, ze);
    k.set("box", box);
    setFieldOfView(k);
    k.set("culled", cull_levels_.empty() ? pending_ : culled_);
    k.set("cull_level", cull_leaf);
    k.set("out_visible", visible_);
    k.set("accumulate", counting() ? 1 : 0);
    k.set("want_angle", angle ? 1 : 0);
    k.set("out_angle", angle ? angle_ : visible_);
    k.set("pending", pending_);
    k.set("rays_on", use_rays ? 1 : 0);
    k.set("ray_hi", ray_hi_);
    st_.launch(k, pixelRange(), pixelGroup());
  }

  void castRays(const Observer& o, float ze, const cl_int4& box, const cl_int4& cull_leaf) {
    const int rays = 2 * (box.s[2] - box.s[0]) + 2 * (box.s[3] - box.s[1]);
    const float unit = static_cast<float>(std::min(field_.cell_size_x, field_.cell_size_y));
    // With the culling pyramid: how far each ray must go to serve the kept nodes' targets.
    cl::Buffer need = detail::deviceBuffer(st_, sizeof(cl_int));
    if (cull_leaf.s[0] > 0) {
      need = detail::deviceBuffer(st_, rays * sizeof(cl_int));
      st_.queue.enqueueFillBuffer(need, cl_int(-1), 0, rays * sizeof(cl_int));
      detail::NamedKernel n = kernel("viewshed_ray_need");
      n.set("culled", culled_);
      n.set("leaf", cull_leaf);
      n.set("f", device_);
      n.set("ex_i", o.col);
      n.set("ey_i", o.row);
      n.set("box", box);
      n.set("rays", rays);
      n.set("unit", unit);
      n.set("need", need);
      st_.launch(n,
                 cl::NDRange(detail::roundUp(cull_leaf.s[0], detail::kTileX),
                             detail::roundUp(cull_leaf.s[1], detail::kTileY)),
                 pixelGroup());
    }
    detail::NamedKernel r = kernel("viewshed_rays");
    setEye(r, o, ze);
    r.set("lipschitz", lipschitz_);
    r.set("forgiven", forgiven_);
    r.set("box", box);
    r.set("rays", rays);
    r.set("need", need);
    r.set("use_need", cull_leaf.s[0] > 0 ? 1 : 0);
    r.set("unit", unit);
    r.set("pending", pending_);
    r.set("ray_hi", ray_hi_);
    r.set("out_visible", visible_);
    r.set("accumulate", counting() ? 1 : 0);
    const std::size_t items = (static_cast<std::size_t>(rays) + lanes_ - 1) / lanes_;  // lanes_ rays each
    st_.launch(r, cl::NDRange(detail::roundUp(items, detail::kLineGroup)), cl::NDRange(detail::kLineGroup));
  }

  // Marches the pending targets, listed row by row.
  void marchPending(const Observer& o, float ze, bool use_rays) {
    const cl::NDRange row_range(detail::roundUp(field_.height, detail::kLineGroup));
    detail::NamedKernel count = kernel("viewshed_pending_count");
    count.set("pending", pending_);
    count.set("width", field_.width);
    count.set("height", field_.height);
    count.set("counts", row_counts_);
    st_.launch(count, row_range, cl::NDRange(detail::kLineGroup));
    std::vector<cl_uint>& rows = row_offsets_;
    rows.resize(field_.height);
    st_.queue.enqueueReadBuffer(row_counts_, CL_TRUE, 0, rows.size() * sizeof(cl_uint), rows.data());
    cl_uint total = 0;
    for (cl_uint& r : rows) {
      const cl_uint n = r;
      r = total;
      total += n;
    }
    pending_targets_ += total;
    if (total == 0) return;
    st_.queue.enqueueWriteBuffer(row_counts_, CL_FALSE, 0, rows.size() * sizeof(cl_uint), rows.data());
    detail::NamedKernel list = kernel("viewshed_pending_list");
    list.set("pending", pending_);
    list.set("width", field_.width);
    list.set("height", field_.height);
    list.set("offsets", row_counts_);
    list.set("list", pending_list_);
    st_.launch(list, row_range, cl::NDRange(detail::kLineGroup));
    detail::NamedKernel m = kernel("viewshed_march");
    setEye(m, o, ze);
    m.set("rays_on", use_rays ? 1 : 0);
    m.set("ray_hi", ray_hi_);
    m.set("pyramid", pyramid_);
    m.set("levels", levels_);
    m.set("top_level", top_);
    m.set("list", pending_list_);
    m.set("count", total);
    m.set("out_visible", visible_);
    m.set("accumulate", counting() ? 1 : 0);
    st_.launch(m, cl::NDRange(detail::roundUp(total, detail::kLineGroup)), cl::NDRange(detail::kLineGroup));
  }

  void markNeeded(const Observer& o, float ze) {
    detail::NamedKernel n = kernel("viewshed_needed");
    setEye(n, o, ze);
    setFieldOfView(n);
    n.set("pyramid", pyramid_);
    n.set("levels", levels_);
    n.set("top_level", top_);
    n.set("out_needed", needed_);
    st_.launch(n, pixelRange(), pixelGroup());
  }

  // The last observer's culled points: 1 / 0, NaN at nodata.
  std::vector<float> culledMask() const {
    std::vector<float> mask(field_.pixelCount(), 0.0f);
    const int k = cull_levels_.empty() ? 0 : cull_levels_.back().s[3], nx = cull_levels_.empty() ? 0 : cull_levels_.back().s[0];
    for (int y = 0; y < field_.height; ++y)
      for (int x = 0; x < field_.width; ++x) {
        const std::size_t p = static_cast<std::size_t>(y) * field_.width + x;
        if (std::isnan(prepared_.heights[p]))
          mask[p] = std::numeric_limits<float>::quiet_NaN();
        else if (!leaf_flags_.empty() && leaf_flags_[static_cast<std::size_t>(y >> k) * nx + (x >> k)])
          mask[p] = 1.0f;
      }
    return mask;
  }

  // The culling pyramid on the device: every level's regions (coarsest first), their table, the
  // sectors and the breakpoints; one flag per node for the query.
  void uploadCulling(const ViewshedPyramid& pyramid) {
    std::vector<float> regions;
    std::size_t nodes = 0;
    for (auto level = pyramid.levels.rbegin(); level != pyramid.levels.rend(); ++level) {
      cull_levels_.push_back(cl_int4{{level->nodes_x, level->nodes_y, static_cast<int>(nodes), level->k}});
      nodes += static_cast<std::size_t>(level->nodes_x) * level->nodes_y;
      regions.insert(regions.end(), level->regions.begin(), level->regions.end());
    }
    cull_regions_ = upload(regions);
    std::vector<cl_float2> spans(pyramid.sectors);
    for (int s = 0; s < pyramid.sectors; ++s) spans[s] = cl_float2{{pyramid.sector_start[s], pyramid.sector_width[s]}};
    cull_spans_ = upload(spans);
    std::vector<float> breaks(ViewshedPyramid::kBreakpoints);
    for (int i = 0; i < ViewshedPyramid::kBreakpoints; ++i)
      breaks[i] = static_cast<float>(pyramid.reach * ViewshedPyramid::breakFraction(i));
    cull_breaks_ = upload(breaks);
    culled_ = detail::deviceBuffer(st_, nodes);
    cull_sectors_ = pyramid.sectors;
    valid_points_ = &pyramid.valid_points;
  }

  // The culling pyramid's query for eye o at height ze, level by level from the coarsest: the
  // finest level's table entry (nodes across 0: no pyramid), its flags at its first node.
  // None where the rounding a sight line forgives (forgiven_) passes a quarter of the least margin
  // by which the pyramid's blockers rise above the sight lines they cut (buildViewshedPyramid: 1e-5
  // of 1 + the field's largest |height| + the target height, and 2e-3 of the larger cell side):
  // an eye far above or below the field's heights.
  cl_int4 cull(const Observer& o, float ze) {
    leaf_flags_.clear();
    if (cull_levels_.empty()) return cl_int4{{0, 0, 0, 0}};
    const double least_margin = 1e-5 * (1.0 + largestHeight() + options_.target_height) +
                                2e-3 * std::max(field_.cell_size_x, field_.cell_size_y);
    if (forgiven_ > 0.25 * least_margin) return cl_int4{{0, 0, 0, 0}};
    for (std::size_t l = 0; l < cull_levels_.size(); ++l) {
      const cl_int4 level = cull_levels_[l];
      detail::NamedKernel k = kernel("viewshed_cull");
      k.set("regions", cull_regions_);
      k.set("level", level);
      k.set("parent", l > 0 ? cull_levels_[l - 1] : level);
      k.set("has_parent", l > 0 ? 1 : 0);
      k.set("sectors", cull_sectors_);
      k.set("spans", cull_spans_);
      k.set("breaks", cull_breaks_);
      k.set("f", device_);
      k.set("ex", static_cast<float>(o.col));
      k.set("ey", static_cast<float>(o.row));
      k.set("ze", ze);
      k.set("culled", culled_);
      st_.launch(k,
                 cl::NDRange(detail::roundUp(level.s[0], detail::kTileX),
                             detail::roundUp(level.s[1], detail::kTileY)),
                 pixelGroup());
    }
    const cl_int4 leaf = cull_levels_.back();
    std::vector<unsigned char> flags(static_cast<std::size_t>(leaf.s[0]) * leaf.s[1]);
    st_.queue.enqueueReadBuffer(culled_, CL_TRUE, static_cast<std::size_t>(leaf.s[2]), flags.size(), flags.data());
    for (std::size_t i = 0; i < flags.size(); ++i) culled_targets_ += flags[i] ? (*valid_points_)[i] : 0;
    leaf_flags_ = std::move(flags);
    return leaf;
  }

  // The rays' slope bounds: each cell's steepest slope, and its Lipschitz bound (kernels/viewshed.cl).
  void boundSlopes() {
    const std::size_t cells = static_cast<std::size_t>(cellsX()) * cellsY();
    const cl::NDRange cell_range(detail::roundUp(cellsX(), detail::kTileX),
                                 detail::roundUp(cellsY(), detail::kTileY));
    const cl::Buffer slopes = detail::deviceBuffer(st_, cells * sizeof(float));
    lipschitz_ = detail::deviceBuffer(st_, cells * sizeof(float));
    detail::NamedKernel slope = kernel("viewshed_slopes");
    slope.set("h", heights_);
    slope.set("f", device_);
    slope.set("slopes", slopes);
    st_.launch(slope, cell_range, pixelGroup());
    detail::NamedKernel k = kernel("viewshed_lipschitz");
    k.set("slopes", slopes);
    k.set("f", device_);
    k.set("lipschitz", lipschitz_);
    st_.launch(k, cell_range, pixelGroup());
  }

  // The maximum pyramid's levels 1 .. top_ (kernels/viewshed.cl), up to blocks of 4096 cells or one
  // block over the field.
  void buildPyramid() {
    std::vector<cl_int4> levels(1, cl_int4{{0, 0, 0, 0}});
    std::size_t total = 0;
    for (int k = 1; k <= 12; ++k) {
      const int bx = (cellsX() + (1 << k) - 1) >> k, by = (cellsY() + (1 << k) - 1) >> k;
      levels.push_back(cl_int4{{bx, by, static_cast<int>(total), 0}});
      total += static_cast<std::size_t>(bx) * by;
      if (bx == 1 && by == 1) break;
    }
    top_ = static_cast<int>(levels.size()) - 1;
    levels_ = upload(levels);
    pyramid_ = detail::deviceBuffer(st_, total * sizeof(float));
    for (int k = 1; k <= top_; ++k) {
      const cl_int4 level = levels[k];
      detail::NamedKernel next = kernel(k == 1 ? "viewshed_pyramid_first" : "viewshed_pyramid_next");
      if (k == 1) {
        next.set("h", heights_);
        next.set("f", device_);
      } else {
        next.set("below", levels[k - 1]);
      }
      next.set("level", level);
      next.set("pyramid", pyramid_);
      st_.launch(next,
                 cl::NDRange(detail::roundUp(level.s[0], detail::kTileX),
                             detail::roundUp(level.s[1], detail::kTileY)),
                 pixelGroup());
    }
  }

  int cellsX() const { return std::max(field_.width - 1, 1); }
  int cellsY() const { return std::max(field_.height - 1, 1); }
  cl::NDRange pixelRange() const {
    return cl::NDRange(detail::roundUp(field_.width, detail::kTileX),
                       detail::roundUp(field_.height, detail::kTileY));
  }
  static cl::NDRange pixelGroup() { return cl::NDRange(detail::kTileX, detail::kTileY); }

  cl::Buffer output() { return detail::deviceBuffer(st_, field_.pixelCount() * sizeof(float)); }

  std::vector<float> read(const cl::Buffer& b) {
    std::vector<float> out(field_.pixelCount());
    st_.queue.enqueueReadBuffer(b, CL_TRUE, 0, out.size() * sizeof(float), out.data());
    return out;
  }

  const ViewshedOptions& options_;
  const std::vector<Observer>& observers_;
  const ViewshedOutputs* outputs_;  // null: counting
  int lanes_;                       // rays per work-item (HFVIS_LANES)
  DeviceField device_{};
  cl::Buffer lipschitz_, pyramid_, levels_;
  cl::Buffer visible_, angle_, needed_;             // the outputs (visible_: the counts when counting)
  cl::Buffer pending_, pending_list_, row_counts_;  // the targets classification leaves to viewshed_march
  std::vector<cl_uint>
      row_offsets_;  // the rows' first entries in pending_list_, read until the observer ends
  cl::Buffer ray_hi_;                               // per target, the rays' upper bound for the march
  bool ray_hi_budgeted_ = false;                    // whether ray_hi_ holds a float per point
  std::size_t pending_targets_ = 0;
  // The culling pyramid (uploadCulling): its levels' table, coarsest first.
  std::vector<cl_int4> cull_levels_;
  cl::Buffer cull_regions_, cull_spans_, cull_breaks_, culled_;
  int cull_sectors_ = 0;
  const std::vector<std::uint32_t>* valid_points_ = nullptr;
  std::size_t culled_targets_ = 0;
  std::vector<unsigned char> leaf_flags_;  // the last query's finest level
  float forgiven_ = 0.0f;                  // forgivenRise of the observer being computed
  int top_ = 0;
  ViewshedResult result_;
};

void validateViewshed(const HeightField& field, const ViewshedOptions& options) {
  validate(field);
  validate(options);
  if (field.pixelCount() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw InvalidArgument("a viewshed takes fields of at most 2^31 - 1 points (got " +
                          std::to_string(field.pixelCount()) + "); crop the DEM to the maximum distance");
  if (detail::hasRowSpacing(field))
    throw InvalidArgument("viewsheds on latitude / longitude grids (per-row spacing) are not supported; "
                          "reproject the DEM to a projected CRS");
  if (const ViewshedPyramid* p = options.pyramid) {
    if (p->width != field.width || p->height != field.height || p->cell_size_x != field.cell_size_x ||
        p->cell_size_y != field.cell_size_y || p->z_scale != field.z_scale ||
        p->heights_fingerprint != heightsFingerprint(field))
      throw InvalidArgument("the culling pyramid was built for another field (size, cell size, z-scale or heights)");
    if (p->target_height != options.target_height)
      throw InvalidArgument("the culling pyramid was built for target height " + std::to_string(p->target_height) +
                            ", the viewshed asks " + std::to_string(options.target_height));
    if (p->curvature != options.curvature)
      throw InvalidArgument("the culling pyramid was built for another curvature coefficient");
    // Its shape, as buildViewshedPyramid makes it (the kernels index by it).
    bool shaped = p->sectors > 0 && p->sector_start.size() == static_cast<std::size_t>(p->sectors) &&
                  p->sector_width.size() == p->sector_start.size() && !p->levels.empty() && p->reach > 0.0;
    for (std::size_t l = 0; shaped && l < p->levels.size(); ++l) {
      const ViewshedPyramid::Level& level = p->levels[l];
      const int k = level.k, side = 1 << std::clamp(k, 0, 30);
      shaped = k >= 1 && k <= 30 && (l == 0 || k == p->levels[l - 1].k + 1) &&
               level.nodes_x == (field.width + side - 1) / side && level.nodes_y == (field.height + side - 1) / side &&
               level.regions.size() == static_cast<std::size_t>(level.nodes_x) * level.nodes_y * p->sectors *
                                           ViewshedPyramid::kRegionFloats;
    }
    // The sectors follow one another around the circle.
    double around = 0.0;
    for (int s = 0; shaped && s < p->sectors; ++s) {
      const double next = p->sector_start[(s + 1) % p->sectors];
      double step = std::fmod(next - p->sector_start[s], 2.0 * M_PI);
      if (step < 0.0) step += 2.0 * M_PI;
      shaped = p->sector_width[s] >= 0.0f && std::fabs(step - p->sector_width[s]) < 1e-5;
      around += p->sector_width[s];
    }
    shaped = shaped && std::fabs(around - 2.0 * M_PI) < 1e-4;
    shaped = shaped && p->levels.back().nodes_x == 1 && p->levels.back().nodes_y == 1 &&
             p->valid_points.size() == static_cast<std::size_t>(p->levels.front().nodes_x) * p->levels.front().nodes_y;
    if (!shaped) throw InvalidArgument("the culling pyramid is malformed (its levels, sectors or regions)");
  }
}

}  // namespace

void validate(const ViewshedOptions& o) {
  if (!(std::isfinite(o.target_height) && o.target_height >= 0.0))
    throw InvalidArgument("the target height must be finite and >= 0 (got " + std::to_string(o.target_height) + ")");
  if (!(std::isfinite(o.max_distance) && o.max_distance >= 0.0))
    throw InvalidArgument("the maximum distance must be finite and >= 0 (got " + std::to_string(o.max_distance) + ")");
  detail::validateCurvature(o.curvature, "the curvature coefficient");
  if (!finiteIn(o.azimuth_from_deg, 0.0, 360.0) || !finiteIn(o.azimuth_to_deg, 0.0, 360.0))
    throw InvalidArgument("field-of-view azimuths must be in [0, 360] degrees");
  if (!finiteIn(o.elevation_min_deg, -90.0, 90.0) || !finiteIn(o.elevation_max_deg, -90.0, 90.0) ||
      o.elevation_min_deg > o.elevation_max_deg)
    throw InvalidArgument("elevation limits must be in [-90, 90] degrees, the lower first");
}

void validate(const HeightField& field, const Observer& o) {
  if (o.col < 0 || o.col >= field.width || o.row < 0 || o.row >= field.height)
    throw InvalidArgument("observer " + std::to_string(o.col) + "," + std::to_string(o.row) + " is outside the " +
                          std::to_string(field.width) + " x " + std::to_string(field.height) + " field");
  if (!std::isfinite(field.at(o.col, o.row)))
    throw InvalidArgument("observer " + std::to_string(o.col) + "," + std::to_string(o.row) + " stands on nodata");
  // (an eye 1e39 below the surface saw every target: the CLI's range, as regions' and PVS's)
  if (!std::isfinite(o.height) || std::fabs(o.height) > kMostGivenHeight)
    throw InvalidArgument(
        "the observer's height must be finite and within +-" + detail::shortNumber(kMostGivenHeight) +
        ", what the kernels' single precision holds (got " + detail::shortNumber(o.height) + ")");
}

ViewshedResult computeViewshed(const ComputeContext& context, const HeightField& field, const Observer& observer,
                               const ViewshedOptions& options, const ViewshedOutputs& outputs) {
  validateViewshed(field, options);
  validate(field, observer);
  if (!outputs.visible && !outputs.angle && !outputs.needed_height && !outputs.culled_mask)
    throw InvalidArgument("no viewshed output requested");
  if (outputs.culled_mask && !options.pyramid) throw InvalidArgument("the culled mask needs a culling pyramid");
  return detail::translateOpenClErrors([&] {
    const std::vector<Observer> observers{observer};
    ViewshedRoutine routine(detail::stateOf(context), field, options, observers, &outputs);
    routine.run();
    return routine.take();
  });
}

CumulativeViewshed computeCumulativeViewshed(const ComputeContext& context, const HeightField& field,
                                             const std::vector<Observer>& observers, const ViewshedOptions& options) {
  validateViewshed(field, options);
  if (observers.empty()) throw InvalidArgument("a cumulative viewshed needs at least one observer");
  for (const Observer& o : observers) validate(field, o);
  return detail::translateOpenClErrors([&] {
    ViewshedRoutine routine(detail::stateOf(context), field, options, observers, nullptr);
    routine.run();
    CumulativeViewshed result;
    result.width = field.width;
    result.height = field.height;
    result.observers = static_cast<int>(observers.size());
    result.count = routine.take().visible;
    return result;
  });
}

}  // namespace hfvis
