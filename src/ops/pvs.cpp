// pvs.cpp: the potentially visible sets' geometry (hfvis/pvs.hpp), the device ray caster
// (kernels/pvs.cl) and the dense reference; the samplers are in pvs_sampling.cpp.
#include "hfvis/pvs.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "core/horizon_common.hpp"
#include "core/number_text.hpp"
#include "core/opencl_context.hpp"
#include "core/sweep_framework.hpp"
#include "core/sweep_geometry.hpp"
#include "core/sweep_routine.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/viewshed.hpp"
#include "ops/pvs_ray.hpp"

namespace hfvis {

int PvsLayout::tileOfCell(int cell) const {
  return (cell / cells_x / tile) * tiles_x + (cell % cells_x) / tile;
}

int PvsLayout::viewOfCell(int cell) const {
  return (cell / cells_x / view_cell) * view_x + (cell % cells_x) / view_cell;
}

PvsLayout pvsLayout(const HeightField& field, const PvsGrid& grid) {
  validate(field);
  if (field.width < 2 || field.height < 2)
    throw InvalidArgument("potentially visible sets need a field of at least 2 x 2 points (got " +
                          std::to_string(field.width) + " x " + std::to_string(field.height) + ")");
  if (field.pixelCount() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw InvalidArgument("potentially visible sets take fields of at most 2^31 - 1 points");
  if (detail::hasRowSpacing(field))
    throw InvalidArgument(
        "potentially visible sets on latitude / longitude grids (per-row spacing) are not supported; "
        "reproject the DEM to a projected CRS");
  PvsLayout l;
  l.cells_x = field.width - 1;
  l.cells_y = field.height - 1;
  const int most = std::max(l.cells_x, l.cells_y);
  if (grid.view_cell < 1 || grid.view_cell > most)
    throw InvalidArgument("the view cell size must be 1 .. " + std::to_string(most) + " cells (got " +
                          std::to_string(grid.view_cell) + ")");
  if (grid.tile < 1 || grid.tile > most)
    throw InvalidArgument("the tile size must be 1 .. " + std::to_string(most) + " cells (got " +
                          std::to_string(grid.tile) + ")");
  // (a band of 1e39, finite in double, is infinite in the kernels' float: the rays' origins were
  // blamed; kMostGivenHeight, as the command line's --view-height)
  if (!std::isfinite(grid.band_low) || !std::isfinite(grid.band_high) || grid.band_low < 0.0 ||
      grid.band_high < grid.band_low || grid.band_high > kMostGivenHeight)
    throw InvalidArgument(
        "the view band needs finite heights 0 <= H0 <= H1 <= " + detail::shortNumber(kMostGivenHeight) +
        " (got " + detail::shortNumber(grid.band_low) + ", " + detail::shortNumber(grid.band_high) + ")");
  l.view_cell = grid.view_cell;
  l.tile = grid.tile;
  l.view_x = (l.cells_x + grid.view_cell - 1) / grid.view_cell;
  l.view_y = (l.cells_y + grid.view_cell - 1) / grid.view_cell;
  l.tiles_x = (l.cells_x + grid.tile - 1) / grid.tile;
  l.tiles_y = (l.cells_y + grid.tile - 1) / grid.tile;
  if (!grid.mask.empty()) {
    if (grid.mask.size() != static_cast<std::size_t>(l.viewCells()))
      throw InvalidArgument("the view-cell mask has " + std::to_string(grid.mask.size()) +
                            " entries, not the " + std::to_string(l.view_x) + " x " +
                            std::to_string(l.view_y) + " view cells");
    if (std::none_of(grid.mask.begin(), grid.mask.end(), [](std::uint8_t m) { return m != 0; }))
      throw InvalidArgument("the view-cell mask selects no view cell");
  }
  return l;
}

std::size_t PvsResult::entries() const {
  std::size_t n = 0;
  for (std::uint32_t w : bits) n += static_cast<std::size_t>(__builtin_popcount(w));
  return n;
}

double pvsRecall(const PvsResult& got, const PvsResult& want) {
  if (got.bits.size() != want.bits.size()) throw InvalidArgument("recall of two PVSs of different grids");
  std::size_t both = 0, wanted = 0;
  for (std::size_t i = 0; i < want.bits.size(); ++i) {
    both += static_cast<std::size_t>(__builtin_popcount(got.bits[i] & want.bits[i]));
    wanted += static_cast<std::size_t>(__builtin_popcount(want.bits[i]));
  }
  return wanted ? double(both) / double(wanted) : 1.0;
}

namespace detail {

std::vector<float> rayHeights(const HeightField& field) {
  return prepareHeights(field, HeightOrigin::Zero).heights;
}

RayPyramid buildRayPyramid(const std::vector<float>& heights, int width, int height) {
  RayPyramid p;
  p.levels.assign(4, 0);
  const int cells_x = width - 1, cells_y = height - 1;
  // fmax-like: NaN (nodata) left out.
  auto larger = [](float a, float b) { return std::isnan(a) ? b : (std::isnan(b) ? a : std::max(a, b)); };
  for (int k = 1; k <= 12; ++k) {
    const int bx = (cells_x + (1 << k) - 1) >> k, by = (cells_y + (1 << k) - 1) >> k;
    const int first = static_cast<int>(p.values.size());
    p.levels.insert(p.levels.end(), {bx, by, first, 0});
    for (int y = 0; y < by; ++y)
      for (int x = 0; x < bx; ++x) {
        float m = NAN;
        if (k == 1) {
          for (int j = 2 * y; j <= std::min(2 * y + 2, height - 1); ++j)
            for (int i = 2 * x; i <= std::min(2 * x + 2, width - 1); ++i)
              m = larger(m, heights[std::size_t(j) * width + i]);
        } else {
          const int* below = &p.levels[4 * (k - 1)];
          for (int j = 2 * y; j <= std::min(2 * y + 1, below[1] - 1); ++j)
            for (int i = 2 * x; i <= std::min(2 * x + 1, below[0] - 1); ++i)
              m = larger(m, p.values[std::size_t(below[2]) + std::size_t(j) * below[0] + i]);
        }
        p.values.push_back(m);
      }
    p.top = k;
    if (bx == 1 && by == 1) break;
  }
  return p;
}

namespace {

// Rays per launch: bounds a launch's time (a GPU's watchdog) and its buffers.
constexpr int kRaysPerLaunch = 1 << 16;

class RayCastRoutine : public DeviceRoutine, public RayCaster {
 public:
  RayCastRoutine(ContextState& st, const HeightField& field, const PvsGrid& grid, double curvature,
                 std::size_t memory_budget_bytes, const std::function<void(RayCaster&)>& body)
      : DeviceRoutine(st, field, nullptr, memory_budget_bytes),
        grid_(grid),
        curvature_(curvature),
        layout_(pvsLayout(field, grid)),
        body_(body) {}

  RayCasts cast(const std::vector<HeightRay>& rays, bool view_cells) override {
    for (const HeightRay& r : rays)
      if (!std::isfinite(r.ox) || !std::isfinite(r.oy) || !std::isfinite(r.oz) || !std::isfinite(r.dx) ||
          !std::isfinite(r.dy) || !std::isfinite(r.dz) || std::isnan(r.t_max))
        throw InvalidArgument("a ray with a non-finite origin or direction, or a NaN length");
    const int n = static_cast<int>(rays.size());
    const int cap = view_cells ? layout_.view_x + layout_.view_y : 0;
    // Per ray on the device: 8 floats in, t, cell and count out, and a list's capacity of
    // (view cell, t) pairs twice (as cast, and packed with its work-group's); twice over, since
    // two launches are in flight (their buffers apart): the host packs the next launch's rays
    // and unpacks the previous one's results while the device casts.
    // The lists are allocated by whole work-groups (the packed read of a launch's last group
    // may reach its end), so a launch with lists takes whole groups: then the budget holds them.
    const std::size_t per_ray = 2 * (8 + 3 + 4 * std::size_t(cap)) * 4;
    const std::size_t granule = cap > 0 ? kLineGroup : 1;
    if (granule * per_ray > memoryBudget())
      throw MemoryBudgetError(std::to_string(granule) + (granule > 1 ? " rays (a work-group)" : " ray") +
                              " and their view-cell lists, in each of two launches in flight, need " +
                              mebibytes(granule * per_ray) + " but the memory budget is " +
                              mebibytes(memoryBudget()));
    const int chunk = static_cast<int>(std::min<std::size_t>(kRaysPerLaunch, memoryBudget() / per_ray) /
                                       granule * granule);
    const std::vector<int> order = originOrder(rays);
    RayCasts out;
    out.t.resize(rays.size());
    out.cell.resize(rays.size());
    if (cap > 0) {
      out.list_first.resize(rays.size());
      out.list_count.resize(rays.size());
      out.view_cells.reserve(rays.size() + rays.size() / 4);  // about one per ray (bench/report/pvs.md)
    }
    const int launches = (n + chunk - 1) / chunk;
    try {
      if (launches > 0) enqueue(rays, order, 0, std::min(chunk, n), cap, slots_[0]);
      for (int c = 0; c < launches; ++c) {
        if (c + 1 < launches) {
          const int next = (c + 1) * chunk;
          enqueue(rays, order, next, std::min(chunk, n - next), cap, slots_[(c + 1) % 2]);
        }
        collect(order, cap, slots_[c % 2], out);
      }
    } catch (...) {
      // A launch or read still in flight writes into the slots' host vectors: let it end before
      // they go.
      try {
        st_.queue.finish();
      } catch (...) {
      }
      throw;
    }
    return out;
  }

 private:
  PreparedHeights prepare() override { return prepareHeights(field_, HeightOrigin::Zero); }
  std::string programFile() const override { return "pvs.cl"; }
  // A flat surface's program leaves the curved terms out (kernels/shared/heightfield_ray.cl).
  std::string programOptions() const override { return curvature_ == 0.0 ? "-DHF_RAY_FLAT" : ""; }

  void allocate() override {
    line_major_ = lineMajorLayout(st_);
    const RayPyramid pyramid = buildRayPyramid(prepared_.heights, field_.width, field_.height);
    pyramid_ = upload(pyramid.values);
    levels_ = upload(pyramid.levels);
    for (NamedKernel* k : {&hits_kernel_, &lists_kernel_}) {
      *k = kernel(k == &hits_kernel_ ? "pvs_cast" : "pvs_cast_lists");
      k->set("h", heights_)
          .set("width", cl_int(field_.width))
          .set("height", cl_int(field_.height))
          .set("pyramid", pyramid_)
          .set("levels", levels_)
          .set("top", cl_int(pyramid.top))
          .set("line_major", cl_int(line_major_))
          .set("curvature", static_cast<float>(curvature_))
          .set("cell_x", static_cast<float>(field_.cell_size_x))
          .set("cell_y", static_cast<float>(field_.cell_size_y))
          .set("view", cl_int(grid_.view_cell))
          .set("view_x", cl_int(layout_.view_x))
          .set("band_lo", static_cast<float>(grid_.band_low))
          .set("band_hi", static_cast<float>(grid_.band_high));
    }
    lists_kernel_.set("group_counts", cl::Local(kLineGroup * sizeof(cl_int)));
  }

  int itemCount() const override { return 1; }
  void runItem(int, int) override { body_(*this); }
  void finish() override {}

  // The rays in the order they are cast: by the 16 x 16-cell block holding their origin (clamped
  // into the field), blocks row by row. Rays with neighbouring origins read neighbouring heights
  // and pyramid blocks, so a launch's work-items share their cache lines; in the callers' order
  // (random origins all over the field) each ray's first reads miss the CPU's caches. A counting
  // sort, stable: the order depends on the origins alone.
  std::vector<int> originOrder(const std::vector<HeightRay>& rays) const {
    constexpr int kBlockShift = 4;
    const int blocks_x = (layout_.cells_x >> kBlockShift) + 1,
              blocks_y = (layout_.cells_y >> kBlockShift) + 1;
    auto block = [&](const HeightRay& r) {
      const float x = std::clamp(r.ox, 0.0f, float(layout_.cells_x - 1));
      const float y = std::clamp(r.oy, 0.0f, float(layout_.cells_y - 1));
      return (int(y) >> kBlockShift) * blocks_x + (int(x) >> kBlockShift);
    };
    std::vector<int> start(std::size_t(blocks_x) * blocks_y + 1, 0);
    // Each ray's block, in `order` until the rays are placed.
    std::vector<int> order(rays.size());
    for (std::size_t i = 0; i < rays.size(); ++i) ++start[(order[i] = block(rays[i])) + 1];
    for (std::size_t b = 1; b < start.size(); ++b) start[b] += start[b - 1];
    std::vector<int> placed(rays.size());
    for (std::size_t i = 0; i < rays.size(); ++i) placed[start[order[i]]++] = static_cast<int>(i);
    return placed;
  }

  // One launch's buffers, kept from launch to launch (grown, never shrunk), and what it cast.
  struct Slot {
    int reserved_rays = 0;
    std::size_t reserved_list = 0;
    cl::Buffer rays, t, cell, count, pierced, pierced_t, lists;
    std::vector<float> packed, hit_t;
    std::vector<int> hit_cell, counts;
    // The first `read_width` pairs of each work-group's lists, read with the hits, and where a
    // group has more, the rest (`extra_width` per group).
    std::vector<ViewCellPoint> packed_lists, extra_lists;
    std::size_t read_width = 0;
    std::vector<std::size_t> group_used;  // pairs per work-group
    cl::Event read;  // its last non-blocking read
    int first = 0, n = 0;
  };

  // Device buffers for `n` rays with lists of `cap`.
  void reserve(Slot& s, int n, int cap) {
    if (n > s.reserved_rays) {
      s.reserved_rays = n;
      const std::size_t rays = std::size_t(n);
      s.rays = deviceBuffer(st_, rays * 8 * 4);
      s.t = deviceBuffer(st_, rays * 4);
      s.cell = deviceBuffer(st_, rays * 4);
      s.count = deviceBuffer(st_, rays * 4);
    }
    // The packed lists: every work-group's capacity, the last one's whole too.
    const std::size_t list = std::max<std::size_t>(1, roundUp(std::size_t(n), kLineGroup) * cap);
    if (list > s.reserved_list) {
      s.reserved_list = list;
      s.pierced = deviceBuffer(st_, list * 4);
      s.pierced_t = deviceBuffer(st_, list * 4);
      s.lists = deviceBuffer(st_, list * sizeof(ViewCellPoint));
    }
  }

  // Packs the rays order[first .. first + n) into `s`, and queues their upload, the cast and the
  // reads of its hits and list lengths (not waited for).
  void enqueue(const std::vector<HeightRay>& rays, const std::vector<int>& order, int first, int n, int cap,
               Slot& s) {
    reserve(s, n, cap);
    s.first = first;
    s.n = n;
    s.packed.resize(std::size_t(n) * 8);
    const int* ray_of = order.data() + first;
    for (int r = 0; r < n; ++r) {
      // The rays are read in block order, all over the callers' vector: fetched ahead.
      constexpr int kAhead = 16;
      if (r + kAhead < n) __builtin_prefetch(&rays[ray_of[r + kAhead]]);
      const HeightRay& ray = rays[ray_of[r]];
      const float values[8] = {ray.ox, ray.oy, ray.oz, ray.dx, ray.dy, ray.dz, ray.t_max, 0.0f};
      if (line_major_) {
        float* to = s.packed.data() + std::size_t(r) * 8;
        for (int c = 0; c < 8; ++c) to[c] = values[c];
      } else {
        for (int c = 0; c < 8; ++c) s.packed[std::size_t(c) * n + r] = values[c];
      }
    }
    st_.queue.enqueueWriteBuffer(s.rays, CL_FALSE, 0, s.packed.size() * 4, s.packed.data());
    NamedKernel& k = cap > 0 ? lists_kernel_ : hits_kernel_;
    k.set("rays", s.rays).set("n", cl_int(n)).set("hit_t", s.t).set("hit_cell", s.cell);
    if (cap > 0)
      k.set("cap", cl_int(cap))
          .set("counts", s.count)
          .set("pierced", s.pierced)
          .set("pierced_t", s.pierced_t)
          .set("lists", s.lists);
    st_.launch(k, cl::NDRange(roundUp(n, kLineGroup)), cl::NDRange(kLineGroup));
    s.hit_t.resize(std::size_t(n));
    s.hit_cell.resize(std::size_t(n));
    st_.queue.enqueueReadBuffer(s.t, CL_FALSE, 0, std::size_t(n) * 4, s.hit_t.data());
    if (cap > 0) {
      const std::size_t groups = (std::size_t(n) + kLineGroup - 1) / kLineGroup;
      s.read_width = std::min(read_width_, kLineGroup * std::size_t(cap));
      s.packed_lists.resize(groups * s.read_width);
      constexpr std::size_t pair = sizeof(ViewCellPoint);
      const cl::array<cl::size_type, 3> origin{0, 0, 0}, region{s.read_width * pair, groups, 1};
      st_.queue.enqueueReadBufferRect(s.lists, CL_FALSE, origin, origin, region, kLineGroup * cap * pair, 0,
                                      s.read_width * pair, 0, s.packed_lists.data());
      s.counts.resize(std::size_t(n));
      st_.queue.enqueueReadBuffer(s.cell, CL_FALSE, 0, std::size_t(n) * 4, s.hit_cell.data());
      st_.queue.enqueueReadBuffer(s.count, CL_FALSE, 0, std::size_t(n) * 4, s.counts.data(), nullptr,
                                  &s.read);
    } else {
      st_.queue.enqueueReadBuffer(s.cell, CL_FALSE, 0, std::size_t(n) * 4, s.hit_cell.data(), nullptr,
                                  &s.read);
    }
    st_.queue.flush();
  }

  // Waits for the launch in `s` and puts its hits and its rays' list places into `out` (at their
  // rays' own index) and its lists after those already in `out` (in cast order).
  void collect(const std::vector<int>& order, int cap, Slot& s, RayCasts& out) {
    s.read.wait();
    const int n = s.n;
    const int* ray_of = order.data() + s.first;
    if (cap == 0) {
      for (int r = 0; r < n; ++r) {
        out.t[ray_of[r]] = s.hit_t[r];
        out.cell[ray_of[r]] = s.hit_cell[r];
      }
      return;
    }
    // Work-group g's lists are its rays' one after another from pair g * kLineGroup * cap, the
    // first read_width of them read: the rest of a longer one now (the read waits for the next
    // launch), then all one after another.
    const int groups = (n + int(kLineGroup) - 1) / int(kLineGroup);
    std::size_t widest = 0, total = 0;
    s.group_used.resize(std::size_t(groups));
    for (int g = 0; g < groups; ++g) {
      std::size_t used = 0;
      for (int r = g * int(kLineGroup), end = std::min(n, r + int(kLineGroup)); r < end; ++r)
        used += s.counts[r];
      s.group_used[g] = used;
      widest = std::max(widest, used);
      total += used;
    }
    read_width_ = std::max(2 * kLineGroup, widest + widest / 4);
    const std::size_t extra = widest > s.read_width ? widest - s.read_width : 0;
    if (extra > 0) {
      constexpr std::size_t pair = sizeof(ViewCellPoint);
      s.extra_lists.resize(extra * groups);
      const cl::array<cl::size_type, 3> from{s.read_width * pair, 0, 0}, origin{0, 0, 0},
          region{extra * pair, std::size_t(groups), 1};
      st_.queue.enqueueReadBufferRect(s.lists, CL_TRUE, from, origin, region, kLineGroup * cap * pair, 0,
                                      extra * pair, 0, s.extra_lists.data());
      ++out.lists_read_again;
    }
    const std::size_t base = out.view_cells.size();
    out.view_cells.resize(base + total);
    ViewCellPoint* to = out.view_cells.data() + base;
    for (int g = 0; g < groups; ++g) {
      const std::size_t used = s.group_used[g], first = std::min(used, s.read_width);
      to = std::copy_n(s.packed_lists.data() + std::size_t(g) * s.read_width, first, to);
      to = std::copy_n(s.extra_lists.data() + std::size_t(g) * extra, used - first, to);
    }
    std::size_t at = base;
    for (int r = 0; r < n; ++r) {
      const int ray = ray_of[r];
      out.t[ray] = s.hit_t[r];
      out.cell[ray] = s.hit_cell[r];
      out.list_first[ray] = at;
      out.list_count[ray] = s.counts[r];
      at += std::size_t(s.counts[r]);
    }
  }

  const PvsGrid& grid_;
  const double curvature_;
  const PvsLayout layout_;
  const std::function<void(RayCaster&)>& body_;
  bool line_major_ = true;
  cl::Buffer pyramid_, levels_;
  // Pairs per work-group read with a launch's hits: a little more than the longest group of the
  // last launch collected when it was queued (the one before last: the next launch is queued
  // before the last is collected) needed (at least two per ray), so that the lists come with the hits: a read
  // sized after the launch would queue behind the next launch, and the device would stand idle
  // while the host waits for it.
  std::size_t read_width_ = 2 * kLineGroup;
  NamedKernel hits_kernel_, lists_kernel_;
  Slot slots_[2];
};

}  // namespace

void withRayCaster(const ComputeContext& context, const HeightField& field, const PvsGrid& grid,
                   double curvature, std::size_t memory_budget_bytes,
                   const std::function<void(RayCaster&)>& body) {
  validateCurvature(curvature, "the curvature");
  translateOpenClErrors([&] {
    RayCastRoutine routine(stateOf(context), field, grid, curvature, memory_budget_bytes, body);
    routine.run();
  });
}

}  // namespace detail

RayCastResult castHeightFieldRays(const ComputeContext& context, const HeightField& field,
                                  const std::vector<HeightRay>& rays, const RayCastOptions& options) {
  detail::RayCasts cast;
  detail::withRayCaster(context, field, detail::castGrid(options), options.curvature,
                        options.memory_budget_bytes,
                        [&](detail::RayCaster& caster) { cast = caster.cast(rays, options.view_cells); });
  RayCastResult out;
  out.t = std::move(cast.t);
  out.cell = std::move(cast.cell);
  out.first.assign(rays.size() + 1, 0);
  if (cast.list_count.empty()) return out;
  // The lists into the rays' order.
  for (std::size_t r = 0; r < rays.size(); ++r)
    out.first[r + 1] = out.first[r] + std::size_t(cast.list_count[r]);
  out.view_cell.resize(out.first.back());
  out.view_t.resize(out.first.back());
  for (std::size_t r = 0; r < rays.size(); ++r)
    for (int j = 0; j < cast.list_count[r]; ++j) {
      const detail::ViewCellPoint& p = cast.view_cells[cast.list_first[r] + std::size_t(j)];
      out.view_cell[out.first[r] + std::size_t(j)] = p.view_cell;
      out.view_t[out.first[r] + std::size_t(j)] = p.t;
    }
  return out;
}

PvsResult computeDensePvs(const ComputeContext& context, const HeightField& field, const PvsGrid& grid,
                          DenseTargets targets, double curvature, double max_distance) {
  PvsResult out;
  out.layout = pvsLayout(field, grid);
  const PvsLayout& l = out.layout;
  const bool inside = targets == DenseTargets::InsideTiles;
  if (inside && l.tile < 2)
    throw InvalidArgument(
        "a dense reference inside the tiles needs tiles of 2 cells or more (a tile of 1 has "
        "no grid point inside it)");
  out.words = (l.tiles() + 31) / 32;
  out.bits.assign(std::size_t(l.viewCells()) * out.words, 0u);
  out.computed = grid.mask.empty() ? std::vector<std::uint8_t>(l.viewCells(), 1) : grid.mask;
  std::vector<double> heights{grid.band_low};
  if (grid.band_high > grid.band_low)
    heights = {grid.band_low, 0.5 * (grid.band_low + grid.band_high), grid.band_high};
  ViewshedOptions vo;
  vo.target_height = 0.0;
  vo.curvature = curvature;
  vo.max_distance = max_distance;
  for (int v = 0; v < l.viewCells(); ++v) {
    if (!out.computed[v]) continue;
    const int x0 = (v % l.view_x) * l.view_cell, y0 = (v / l.view_x) * l.view_cell;
    const int x1 = std::min(x0 + l.view_cell, l.cells_x), y1 = std::min(y0 + l.view_cell, l.cells_y);
    for (double eye : heights) {
      std::vector<Observer> eyes;
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x)
          if (std::isfinite(field.at(x, y))) eyes.push_back(Observer{x, y, eye});
      if (eyes.empty()) continue;
      const CumulativeViewshed seen = computeCumulativeViewshed(context, field, eyes, vo);
      std::uint32_t* words = &out.bits[std::size_t(v) * out.words];
      for (int y = 0; y < field.height; ++y)
        for (int x = 0; x < field.width; ++x) {
          if (!(seen.count[std::size_t(y) * field.width + x] > 0.0f)) continue;
          // Every tile whose closed square holds (x, y) (inside: whose open square does).
          for (int ty = std::max(0, (y - 1) / l.tile); ty <= std::min(l.tiles_y - 1, y / l.tile); ++ty)
            for (int tx = std::max(0, (x - 1) / l.tile); tx <= std::min(l.tiles_x - 1, x / l.tile); ++tx) {
              if (x < tx * l.tile || x > tx * l.tile + l.tile || y < ty * l.tile || y > ty * l.tile + l.tile)
                continue;
              // (inside: not on the tile's border; the field's last row and column bound the last tiles)
              const int x1 = std::min(tx * l.tile + l.tile, l.cells_x),
                        y1 = std::min(ty * l.tile + l.tile, l.cells_y);
              if (inside && (x == tx * l.tile || x == x1 || y == ty * l.tile || y == y1)) continue;
              const int t = ty * l.tiles_x + tx;
              words[t / 32] |= 1u << (t % 32);
            }
        }
    }
  }
  return out;
}

}  // namespace hfvis
