// viewshed.cpp: from-point visibility (see hfvis/viewshed.hpp): the field goes to the device
// once per call; per observer the rays' bounds and the targets (kernels/viewshed.cl).
#include "hfvis/viewshed.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "hfvis/errors.hpp"
#include "core/horizon_common.hpp"
#include "core/opencl_context.hpp"
#include "core/sweep_framework.hpp"

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

// The device side of one field, kept for every observer of a call.
class ViewshedRun {
 public:
  ViewshedRun(detail::ContextState& st, const HeightField& field, const ViewshedOptions& options)
      : st_(st),
        field_(field),
        options_(options),
        lanes_(detail::simdLanes(st)),
        program_(st.program("viewshed.cl", "-DHFVIS_LANES=" + std::to_string(lanes_))) {
    const std::size_t pixels = field.pixelCount();
    heights_.resize(pixels);
    for (std::size_t p = 0; p < pixels; ++p)
      heights_[p] = std::isfinite(field.heights[p]) ? static_cast<float>(field.heights[p] * field.z_scale)
                                                    : std::numeric_limits<float>::quiet_NaN();
    device_ = {field.width, field.height, static_cast<float>(field.cell_size_x), static_cast<float>(field.cell_size_y),
               static_cast<float>(options.curvature)};
    heights_buffer_ = cl::Buffer(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, pixels * sizeof(float),
                                 heights_.data());
    const int cells_x = std::max(field.width - 1, 1), cells_y = std::max(field.height - 1, 1);
    const std::size_t cells = static_cast<std::size_t>(cells_x) * cells_y;
    const cl::NDRange cell_range(detail::roundUp(cells_x, detail::kTileX), detail::roundUp(cells_y, detail::kTileY));
    const cl::Buffer slopes = detail::deviceBuffer(st, cells * sizeof(float));
    lipschitz_ = detail::deviceBuffer(st, cells * sizeof(float));
    detail::NamedKernel slope(st, program_, "viewshed_slopes");
    slope.set("h", heights_buffer_);
    slope.set("f", device_);
    slope.set("slopes", slopes);
    st.launch(slope, cell_range, cl::NDRange(detail::kTileX, detail::kTileY));
    detail::NamedKernel k(st, program_, "viewshed_lipschitz");
    k.set("slopes", slopes);
    k.set("f", device_);
    k.set("lipschitz", lipschitz_);
    st.launch(k, cell_range, cl::NDRange(detail::kTileX, detail::kTileY));
    buildPyramid(cells_x, cells_y);
    if (options.pyramid) uploadCulling(*options.pyramid);
    // The rays' upper bounds, a float per point, where the budget leaves room for them (else
    // every target is marched).
    const std::size_t budget =
        options.memory_budget_bytes ? options.memory_budget_bytes : detail::defaultMemoryBudget(st.info);
    ray_hi_budgeted_ = pixels * sizeof(float) <= budget / 2;
    ray_hi_ = detail::deviceBuffer(st, ray_hi_budgeted_ ? pixels * sizeof(float) : sizeof(float));
    pending_ = detail::deviceBuffer(st, pixels);
    pending_list_ = detail::deviceBuffer(st, pixels * sizeof(cl_uint));
    row_counts_ = detail::deviceBuffer(st, static_cast<std::size_t>(field.height) * sizeof(cl_uint));
  }

  // One observer's targets into `visible` (added to it when `accumulate`) and, if given, `angle`.
  void observe(const Observer& o, cl::Buffer& visible, bool accumulate, cl::Buffer* angle,
               cl::Buffer* needed = nullptr) {
    const float ze = static_cast<float>(options_.absolute ? o.height
                                                          : heights_[static_cast<std::size_t>(o.row) * field_.width + o.col] + o.height);
    const cl_int4 box = targetBox(field_, o, options_.max_distance);
    const cl_int4 cull_leaf = cull(o, ze);
    const int w1 = box.s[2] - box.s[0], h1 = box.s[3] - box.s[1];
    const double far_pixels = std::max({o.col - box.s[0], box.s[2] - o.col, o.row - box.s[1], box.s[3] - o.row});
    const bool use_rays = ray_hi_budgeted_ && !options_.march_every_target && w1 >= 1 && h1 >= 1 &&
                          far_pixels >= kLeastRayPixels;
    // The field of view's span clockwise; 0 (equal azimuths, or 0 and 360) is the whole circle.
    double az_span = std::fmod(options_.azimuth_to_deg - options_.azimuth_from_deg, 360.0);
    if (az_span < 0.0) az_span += 360.0;
    if (az_span == 0.0) az_span = 360.0;
    // Settle what needs no sight line; the rest is pending, for the rays and then the march.
    detail::NamedKernel k(st_, program_, "viewshed_classify");
    k.set("h", heights_buffer_);
    k.set("f", device_);
    k.set("ex_i", o.col);
    k.set("ey_i", o.row);
    k.set("ze", ze);
    k.set("target_height", static_cast<float>(options_.target_height));
    k.set("box", box);
    k.set("max_distance", static_cast<float>(options_.max_distance));
    k.set("az_on", az_span < 360.0 ? 1 : 0);
    k.set("az_from", static_cast<float>(options_.azimuth_from_deg));
    k.set("az_span", static_cast<float>(az_span));
    k.set("el_lo", static_cast<float>(options_.elevation_min_deg * kDegree));
    k.set("el_hi", static_cast<float>(options_.elevation_max_deg * kDegree));
    k.set("culled", cull_levels_.empty() ? pending_ : culled_);
    k.set("cull_level", cull_leaf);
    k.set("out_visible", visible);
    k.set("accumulate", accumulate ? 1 : 0);
    k.set("want_angle", angle ? 1 : 0);
    k.set("out_angle", angle ? *angle : visible);
    k.set("pending", pending_);
    k.set("rays_on", use_rays ? 1 : 0);
    k.set("ray_hi", ray_hi_);
    st_.launch(k, cl::NDRange(detail::roundUp(field_.width, detail::kTileX), detail::roundUp(field_.height, detail::kTileY)),
               cl::NDRange(detail::kTileX, detail::kTileY));
    // The rays settle most pending targets, or leave them an upper bound for the march.
    if (use_rays) {
      const int rays = 2 * w1 + 2 * h1;
      const float unit = static_cast<float>(std::min(field_.cell_size_x, field_.cell_size_y));
      // With the culling pyramid: how far each ray must go to serve the kept nodes' targets.
      cl::Buffer need = detail::deviceBuffer(st_, sizeof(cl_int));
      if (cull_leaf.s[0] > 0) {
        need = detail::deviceBuffer(st_, rays * sizeof(cl_int));
        st_.queue.enqueueFillBuffer(need, cl_int(-1), 0, rays * sizeof(cl_int));
        detail::NamedKernel n(st_, program_, "viewshed_ray_need");
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
                   cl::NDRange(detail::kTileX, detail::kTileY));
      }
      detail::NamedKernel r(st_, program_, "viewshed_rays");
      r.set("h", heights_buffer_);
      r.set("f", device_);
      r.set("lipschitz", lipschitz_);
      r.set("ex_i", o.col);
      r.set("ey_i", o.row);
      r.set("ze", ze);
      r.set("target_height", static_cast<float>(options_.target_height));
      r.set("box", box);
      r.set("rays", rays);
      r.set("need", need);
      r.set("use_need", cull_leaf.s[0] > 0 ? 1 : 0);
      r.set("unit", unit);
      r.set("pending", pending_);
      r.set("ray_hi", ray_hi_);
      r.set("out_visible", visible);
      r.set("accumulate", accumulate ? 1 : 0);
      const std::size_t items = (static_cast<std::size_t>(rays) + lanes_ - 1) / lanes_;  // lanes_ rays each
      st_.launch(r, cl::NDRange(detail::roundUp(items, detail::kLineGroup)), cl::NDRange(detail::kLineGroup));
    }
    // March the pending targets, listed row by row.
    const cl::NDRange row_range(detail::roundUp(field_.height, detail::kLineGroup));
    detail::NamedKernel count(st_, program_, "viewshed_pending_count");
    count.set("pending", pending_);
    count.set("width", field_.width);
    count.set("height", field_.height);
    count.set("counts", row_counts_);
    st_.launch(count, row_range, cl::NDRange(detail::kLineGroup));
    std::vector<cl_uint> rows(field_.height);
    st_.queue.enqueueReadBuffer(row_counts_, CL_TRUE, 0, rows.size() * sizeof(cl_uint), rows.data());
    cl_uint total = 0;
    for (cl_uint& r : rows) {
      const cl_uint n = r;
      r = total;
      total += n;
    }
    pending_targets_ += total;
    if (total > 0) {
      st_.queue.enqueueWriteBuffer(row_counts_, CL_FALSE, 0, rows.size() * sizeof(cl_uint), rows.data());
      detail::NamedKernel list(st_, program_, "viewshed_pending_list");
      list.set("pending", pending_);
      list.set("width", field_.width);
      list.set("height", field_.height);
      list.set("offsets", row_counts_);
      list.set("list", pending_list_);
      st_.launch(list, row_range, cl::NDRange(detail::kLineGroup));
      detail::NamedKernel m(st_, program_, "viewshed_march");
      m.set("h", heights_buffer_);
      m.set("f", device_);
      m.set("ex_i", o.col);
      m.set("ey_i", o.row);
      m.set("ze", ze);
      m.set("target_height", static_cast<float>(options_.target_height));
      m.set("rays_on", use_rays ? 1 : 0);
      m.set("ray_hi", ray_hi_);
      m.set("pyramid", pyramid_);
      m.set("levels", levels_);
      m.set("top_level", top_);
      m.set("list", pending_list_);
      m.set("count", total);
      m.set("out_visible", visible);
      m.set("accumulate", accumulate ? 1 : 0);
      st_.launch(m, cl::NDRange(detail::roundUp(total, detail::kLineGroup)), cl::NDRange(detail::kLineGroup));
    }
    if (needed) {
      detail::NamedKernel n(st_, program_, "viewshed_needed");
      n.set("h", heights_buffer_);
      n.set("f", device_);
      n.set("ex_i", o.col);
      n.set("ey_i", o.row);
      n.set("ze", ze);
      n.set("target_height", static_cast<float>(options_.target_height));
      n.set("max_distance", static_cast<float>(options_.max_distance));
      n.set("az_on", az_span < 360.0 ? 1 : 0);
      n.set("az_from", static_cast<float>(options_.azimuth_from_deg));
      n.set("az_span", static_cast<float>(az_span));
      n.set("el_lo", static_cast<float>(options_.elevation_min_deg * kDegree));
      n.set("el_hi", static_cast<float>(options_.elevation_max_deg * kDegree));
      n.set("pyramid", pyramid_);
      n.set("levels", levels_);
      n.set("top_level", top_);
      n.set("out_needed", *needed);
      st_.launch(n, cl::NDRange(detail::roundUp(field_.width, detail::kTileX), detail::roundUp(field_.height, detail::kTileY)),
                 cl::NDRange(detail::kTileX, detail::kTileY));
    }
    st_.queue.finish();  // before this observer's ray buffers go
  }

  // Targets marched so far (the rest were settled by classification), and valid targets culled.
  std::size_t pendingTargets() const { return pending_targets_; }
  std::size_t culledTargets() const { return culled_targets_; }

  // The last observer's culled points: 1 / 0, NaN at nodata.
  std::vector<float> culledMask() const {
    std::vector<float> mask(field_.pixelCount(), 0.0f);
    const int k = cull_levels_.empty() ? 0 : cull_levels_.back().s[3], nx = cull_levels_.empty() ? 0 : cull_levels_.back().s[0];
    for (int y = 0; y < field_.height; ++y)
      for (int x = 0; x < field_.width; ++x) {
        const std::size_t p = static_cast<std::size_t>(y) * field_.width + x;
        if (std::isnan(heights_[p]))
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
    cull_regions_ = cl::Buffer(st_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, regions.size() * sizeof(float),
                               regions.data());
    std::vector<cl_float2> spans(pyramid.sectors);
    for (int s = 0; s < pyramid.sectors; ++s) spans[s] = cl_float2{{pyramid.sector_start[s], pyramid.sector_width[s]}};
    cull_spans_ = cl::Buffer(st_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, spans.size() * sizeof(cl_float2),
                             spans.data());
    std::vector<float> breaks(ViewshedPyramid::kBreakpoints);
    for (int i = 0; i < ViewshedPyramid::kBreakpoints; ++i)
      breaks[i] = static_cast<float>(pyramid.reach * ViewshedPyramid::breakFraction(i));
    cull_breaks_ = cl::Buffer(st_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, breaks.size() * sizeof(float),
                              breaks.data());
    culled_ = detail::deviceBuffer(st_, nodes);
    cull_sectors_ = pyramid.sectors;
    valid_points_ = &pyramid.valid_points;
  }

  // The culling pyramid's query for eye o at height ze, level by level from the coarsest: the
  // finest level's table entry (nodes across 0: no pyramid), its flags at its first node.
  cl_int4 cull(const Observer& o, float ze) {
    if (cull_levels_.empty()) return cl_int4{{0, 0, 0, 0}};
    for (std::size_t l = 0; l < cull_levels_.size(); ++l) {
      const cl_int4 level = cull_levels_[l];
      detail::NamedKernel k(st_, program_, "viewshed_cull");
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
      st_.launch(k, cl::NDRange(detail::roundUp(level.s[0], detail::kTileX), detail::roundUp(level.s[1], detail::kTileY)),
                 cl::NDRange(detail::kTileX, detail::kTileY));
    }
    const cl_int4 leaf = cull_levels_.back();
    std::vector<unsigned char> flags(static_cast<std::size_t>(leaf.s[0]) * leaf.s[1]);
    st_.queue.enqueueReadBuffer(culled_, CL_TRUE, static_cast<std::size_t>(leaf.s[2]), flags.size(), flags.data());
    for (std::size_t i = 0; i < flags.size(); ++i) culled_targets_ += flags[i] ? (*valid_points_)[i] : 0;
    leaf_flags_ = std::move(flags);
    return leaf;
  }

  // The maximum pyramid's levels 1 .. top_ (kernels/viewshed.cl), up to blocks of 4096 cells or one
  // block over the field.
  void buildPyramid(int cells_x, int cells_y) {
    std::vector<cl_int4> levels(1, cl_int4{{0, 0, 0, 0}});
    std::size_t total = 0;
    for (int k = 1; k <= 12; ++k) {
      const int bx = (cells_x + (1 << k) - 1) >> k, by = (cells_y + (1 << k) - 1) >> k;
      levels.push_back(cl_int4{{bx, by, static_cast<int>(total), 0}});
      total += static_cast<std::size_t>(bx) * by;
      if (bx == 1 && by == 1) break;
    }
    top_ = static_cast<int>(levels.size()) - 1;
    levels_ = cl::Buffer(st_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, levels.size() * sizeof(cl_int4),
                         levels.data());
    pyramid_ = detail::deviceBuffer(st_, total * sizeof(float));
    for (int k = 1; k <= top_; ++k) {
      const cl_int4 level = levels[k];
      detail::NamedKernel kernel(st_, program_, k == 1 ? "viewshed_pyramid_first" : "viewshed_pyramid_next");
      if (k == 1) {
        kernel.set("h", heights_buffer_);
        kernel.set("f", device_);
      } else {
        kernel.set("below", levels[k - 1]);
      }
      kernel.set("level", level);
      kernel.set("pyramid", pyramid_);
      st_.launch(kernel, cl::NDRange(detail::roundUp(level.s[0], detail::kTileX), detail::roundUp(level.s[1], detail::kTileY)),
                 cl::NDRange(detail::kTileX, detail::kTileY));
    }
  }

  cl::Buffer output() { return detail::deviceBuffer(st_, field_.pixelCount() * sizeof(float)); }

  std::vector<float> read(const cl::Buffer& b) {
    std::vector<float> out(field_.pixelCount());
    st_.queue.enqueueReadBuffer(b, CL_TRUE, 0, out.size() * sizeof(float), out.data());
    return out;
  }

 private:
  detail::ContextState& st_;
  const HeightField& field_;
  const ViewshedOptions& options_;
  int lanes_;  // rays per work-item (HFVIS_LANES)
  cl::Program program_;
  std::vector<float> heights_;
  DeviceField device_{};
  cl::Buffer heights_buffer_, lipschitz_, pyramid_, levels_;
  cl::Buffer pending_, pending_list_, row_counts_;  // the targets classification leaves to viewshed_march
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
  int top_ = 0;
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
  if (!std::isfinite(o.curvature)) throw InvalidArgument("the curvature coefficient must be finite");
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
  if (!std::isfinite(o.height)) throw InvalidArgument("the observer's height must be finite");
}

ViewshedResult computeViewshed(const ComputeContext& context, const HeightField& field, const Observer& observer,
                               const ViewshedOptions& options, const ViewshedOutputs& outputs) {
  validateViewshed(field, options);
  validate(field, observer);
  if (!outputs.visible && !outputs.angle && !outputs.needed_height && !outputs.culled_mask)
    throw InvalidArgument("no viewshed output requested");
  if (outputs.culled_mask && !options.pyramid) throw InvalidArgument("the culled mask needs a culling pyramid");
  return detail::translateOpenClErrors([&] {
    detail::ContextState& st = detail::stateOf(context);
    ViewshedRun run(st, field, options);
    cl::Buffer visible = run.output();
    cl::Buffer angle = outputs.angle ? run.output() : cl::Buffer();
    cl::Buffer needed = outputs.needed_height ? run.output() : cl::Buffer();
    run.observe(observer, visible, false, outputs.angle ? &angle : nullptr, outputs.needed_height ? &needed : nullptr);
    ViewshedResult result;
    result.width = field.width;
    result.height = field.height;
    result.marched = run.pendingTargets();
    result.culled = run.culledTargets();
    if (outputs.visible) result.visible = run.read(visible);
    if (outputs.angle) result.angle = run.read(angle);
    if (outputs.needed_height) result.needed_height = run.read(needed);
    if (outputs.culled_mask) result.culled_mask = run.culledMask();
    return result;
  });
}

CumulativeViewshed computeCumulativeViewshed(const ComputeContext& context, const HeightField& field,
                                             const std::vector<Observer>& observers, const ViewshedOptions& options) {
  validateViewshed(field, options);
  if (observers.empty()) throw InvalidArgument("a cumulative viewshed needs at least one observer");
  for (const Observer& o : observers) validate(field, o);
  return detail::translateOpenClErrors([&] {
    detail::ContextState& st = detail::stateOf(context);
    ViewshedRun run(st, field, options);
    cl::Buffer count = run.output();
    st.queue.enqueueFillBuffer(count, 0.0f, 0, field.pixelCount() * sizeof(float));
    for (std::size_t i = 0; i < observers.size(); ++i) {
      run.observe(observers[i], count, true, nullptr);
      if (options.progress) options.progress(static_cast<int>(i + 1), static_cast<int>(observers.size()));
    }
    CumulativeViewshed result;
    result.width = field.width;
    result.height = field.height;
    result.observers = static_cast<int>(observers.size());
    result.count = run.read(count);
    return result;
  });
}

}  // namespace hfvis
