// region_visibility.cpp: visibility between regions (see hfvis/region_visibility.hpp): the
// samples' tables and the field go to the device once; kernels/region_visibility.cl writes the
// bitmasks, the fractions are counted here.
#include "hfvis/region_visibility.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "core/horizon_common.hpp"
#include "core/host_bands.hpp"
#include "core/number_text.hpp"
#include "core/opencl_context.hpp"
#include "core/sweep_framework.hpp"
#include "core/sweep_geometry.hpp"
#include "core/sweep_routine.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/viewshed.hpp"
#include "ops/region_visibility_sight.hpp"

namespace hfvis {
namespace {

// Receiver words (32 samples each) per launch: bounds a launch's time (a GPU's watchdog) on large fields.
constexpr int kWordsPerLaunch = 1 << 16;

// The culling pyramid's levels at most: blocks of up to 2^15 cells a side.
constexpr int kCullLevels = 16;

// The kernel's RegionField struct.
struct DeviceField {
  cl_int width, height;
  cl_float cell_x, cell_y;
  cl_float curvature;
  cl_float max_d2;
};

std::string corner(int col, int row) { return std::to_string(col) + "," + std::to_string(row); }

void validateField(const HeightField& field) {
  validate(field);
  if (field.pixelCount() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw InvalidArgument("region visibility takes fields of at most 2^31 - 1 points (got " +
                          std::to_string(field.pixelCount()) + ")");
  if (detail::hasRowSpacing(field))
    throw InvalidArgument(
        "region visibility on latitude / longitude grids (per-row spacing) is not supported; "
        "reproject the DEM to a projected CRS");
}

int popcount(std::uint32_t v) { return __builtin_popcount(v); }

// The kernel's BitmaskTable struct.
struct DeviceBitmaskTable {
  cl_float centre_x, centre_y, rho;
  cl_int angles, offsets;
};

// The bitmask method's table (kernels/region_visibility.cl, BitmaskTable): per edge angle i and
// offset j, the samples p with n_i . (p - centre) >= c_j, decided in double (the kernel's lookups
// allow for the table's own resolution around it).
struct BitmaskTable {
  DeviceBitmaskTable shape{};
  float lo_x = 0, lo_y = 0, hi_x = 0, hi_y = 0;  // the samples' bounding box
  std::vector<std::uint32_t> masks;
};

BitmaskTable bitmaskTable(const std::vector<float>& points, int size) {
  BitmaskTable t;
  const int samples = static_cast<int>(points.size() / 3), words = (samples + 31) / 32;
  t.lo_x = t.hi_x = points[0], t.lo_y = t.hi_y = points[1];
  for (int s = 0; s < samples; ++s) {
    t.lo_x = std::min(t.lo_x, points[3 * s]), t.hi_x = std::max(t.hi_x, points[3 * s]);
    t.lo_y = std::min(t.lo_y, points[3 * s + 1]), t.hi_y = std::max(t.hi_y, points[3 * s + 1]);
  }
  const double cx = 0.5 * (double(t.lo_x) + t.hi_x), cy = 0.5 * (double(t.lo_y) + t.hi_y);
  double rho = 0.0;
  for (int s = 0; s < samples; ++s)
    rho = std::max(rho, std::hypot(points[3 * s] - cx, points[3 * s + 1] - cy));
  // Slightly larger, and never 0 (a one-point light), so that offset 0 holds every sample.
  rho = rho * (1.0 + 1e-5) + 1e-5 * (1.0 + std::fabs(cx) + std::fabs(cy));
  t.shape = {static_cast<float>(cx), static_cast<float>(cy), static_cast<float>(rho), size, size};
  t.masks.assign(std::size_t(size) * (size + 1) * words, 0u);
  const double pi = std::acos(-1.0);
  for (int i = 0; i < size; ++i) {
    const double nx = std::cos(2.0 * pi * i / size), ny = std::sin(2.0 * pi * i / size);
    for (int s = 0; s < samples; ++s) {
      const double along = nx * (points[3 * s] - double(t.shape.centre_x)) +
                           ny * (points[3 * s + 1] - double(t.shape.centre_y));
      // Inside for offsets c_j = -rho + 2 rho j / size <= along.
      for (int j = 0; j <= size && -double(t.shape.rho) + 2.0 * t.shape.rho * j / size <= along; ++j)
        t.masks[(std::size_t(i) * (size + 1) + j) * words + s / 32] |= 1u << (s % 32);
    }
  }
  return t;
}

// The highest finite height (z-scaled; -infinity if none).
float fieldTop(const detail::PreparedHeights& p) { return p.highest; }

// The largest finite |height| (z-scaled; 0 if none).
float largestHeight(const detail::PreparedHeights& p) {
  return p.lowest <= p.highest ? std::max(std::fabs(p.lowest), std::fabs(p.highest)) : 0.0f;
}

// The field as the region kernels take it, prepared once (RegionField) or per call: the z-scaled
// heights (HeightOrigin::Zero: the viewshed's, so both decide the same sight lines) and, for the
// culled march and the bitmask method, the culling pyramid, on the host and the device.
struct RegionSurface {
  const HeightField* field = nullptr;
  detail::PreparedHeights prepared;
  detail::CullPyramid pyramid;       // levels 0: none built (the exact march, a field one point thick)
  cl::Buffer heights, pyramid_top;   // on the device (`device`)
};

// `field` validated (validateField). `pyramid`: build the culling pyramid; `device`: upload.
RegionSurface prepareSurface(detail::ContextState& st, const HeightField& field, bool pyramid, bool device) {
  RegionSurface out;
  out.field = &field;
  out.prepared = detail::prepareHeights(field, detail::HeightOrigin::Zero);
  const std::vector<float>& h = out.prepared.heights;
  if (pyramid) out.pyramid = detail::cullPyramid(h, field.width, field.height);
  if (!device) return out;
  const auto upload = [&](const std::vector<float>& values) {
    if (values.empty()) return detail::deviceBuffer(st, 0);
    return cl::Buffer(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, values.size() * sizeof(float),
                      const_cast<float*>(values.data()));
  };
  // (the two copies at once where the field is split too: at 4096^2, 157 MB of fresh pages, about
  // 70 ms one after the other)
  const int uploads = out.pyramid.levels > 0 ? 2 : 1;  // the heights, then the pyramid
  detail::forEachBand(uploads, detail::bandsFor(field.height, field.width), [&](int, int first, int last) {
    for (int u = first; u < last; ++u) {
      if (u == 0)
        out.heights = upload(h);
      else
        out.pyramid_top = upload(out.pyramid.top);
    }
  });
  return out;
}

// The bits of `count` receivers from the device, receiver-major: one routine item per launch
// of up to kWordsPerLaunch / words receivers (a work-item marches all its receiver's words:
// a launch's work stays bounded whatever S).
class RegionBitsRoutine : public detail::DeviceRoutine {
 public:
  RegionBitsRoutine(detail::ContextState& st, const RegionSurface& surface, const std::vector<float>& sources,
                    const std::vector<float>& source_points, bool source_absolute,
                    const std::vector<float>* receivers, bool receiver_absolute, int count,
                    const RegionVisibilityOptions& options)
      : DeviceRoutine(st, *surface.field, options.progress, 0),
        surface_(surface),
        sources_(sources),
        source_points_(source_points),
        source_absolute_(source_absolute),
        receivers_(receivers),
        receiver_absolute_(receiver_absolute),
        count_(count),
        options_(options),
        samples_(detail::regionTableSamples(sources)),
        words_((samples_ + 31) / 32) {}

  std::vector<std::uint32_t> bits;  // after run(): receiver-major
  // After run(), the bitmask method's: bits the march decided, and of those visible.
  std::uint64_t exact_tested = 0, exact_tested_visible = 0;

 private:
  // The heights and the pyramid are the surface's, prepared and uploaded by the caller (which
  // placed the samples on the same heights), per call or once for many (RegionField).
  detail::PreparedHeights prepare() override { return {}; }
  bool heightsResident() const override { return false; }
  std::string programFile() const override { return "region_visibility.cl"; }

  void allocate() override {
    heights_ = surface_.heights;
    receiver_major_ = detail::lineMajorLayout(st_);
    const std::size_t entries = static_cast<std::size_t>(count_) * words_;
    // The bitmasks live whole on the device and on the host, twice there in the word-major
    // layout (read back, then transposed): refuse what the budget (half the device's memory; on a
    // CPU device, the host's) cannot hold rather than fail in an allocation.
    const std::size_t copies = receiver_major_ ? 2 : 3;
    // (the bitmask method's table too: angles x (offsets + 1) masks of the samples, on both sides)
    const std::size_t table_size = static_cast<std::size_t>(options_.bitmask_table);
    const std::size_t table_bytes = options_.method == RegionVisibilityMethod::Bitmask
                                        ? 2 * table_size * (table_size + 1) * words_ * sizeof(std::uint32_t)
                                        : 0;
    // (a pair's per-end tables, which the culled march may build: a record per sample of each side)
    const std::size_t record_bytes =
        receivers_ && options_.method == RegionVisibilityMethod::Culled
            ? (static_cast<std::size_t>(count_) + samples_) * REGION_END_RECORD * sizeof(float)
            : 0;
    const std::size_t bytes = copies * entries * sizeof(std::uint32_t) + table_bytes + record_bytes;
    const std::size_t budget = memoryBudget();
    if (bytes > budget)
      throw MemoryBudgetError(
          "the bitmasks with their host copies (and a bitmask method's table, a pair's per-end tables) "
          "need " +
          detail::mebibytes(bytes) + " but the memory budget is " + detail::mebibytes(budget) +
          "; take fewer samples or a smaller field");
    source_table_ = upload(sources_);
    source_points_buffer_ = upload(source_points_);
    // A pixel run binds the source table in the receivers' place (never read).
    receiver_table_ = receivers_ ? upload(*receivers_) : source_table_;
    bits_ = detail::deviceBuffer(st_, entries * sizeof(std::uint32_t));
    const double max_d2 = options_.max_distance * options_.max_distance;
    const DeviceField device{field_.width,
                             field_.height,
                             static_cast<float>(field_.cell_size_x),
                             static_cast<float>(field_.cell_size_y),
                             static_cast<float>(options_.curvature),
                             options_.max_distance > 0.0 ? static_cast<float>(max_d2) : 0.0f};
    bool probed_clear = false;
    const bool bitmask = options_.method == RegionVisibilityMethod::Bitmask;
    if (options_.method == RegionVisibilityMethod::Culled || bitmask) {
      const detail::CullPyramid& pyramid = surface_.pyramid;
      levels_ = pyramid.levels;
      margin_ = pyramid.margin;
      gradient_ = pyramid.gradient;
      finite_ = pyramid.finite;
      if (levels_ > 0) pyramid_ = surface_.pyramid_top;
      if (levels_ > 0 && receivers_) probed_clear = probeClear(pyramid, device);
    }
    // The per-end tables that certify clear sight lines (region_end_table), a pair's only: its
    // shared sources' and its receivers', where the probe found enough clear lines (elsewhere they
    // cost more than they save). An area light over every pixel takes none: its receivers lie on
    // the surface (their first band holds their own height, so nothing is certified from that end)
    // and its sources' tables alone did not measurably speed it (bench/report/region_visibility.md).
    certify_receivers_ = levels_ > 0 && receivers_ != nullptr && probed_clear;
    certify_sources_ = certify_receivers_ && !options_.decorrelate;
    if (certify_sources_ || certify_receivers_) {
      // The tables' bound of the sight lines' end heights: the highest surface plus the largest
      // height over it (an absolute height is bounded by it too).
      const float surface = largestHeight(surface_.prepared);
      float above = float(options_.target_height);
      for (const std::vector<float>* table : {&sources_, receivers_})
        for (std::size_t i = 8; table && i < table->size(); i += 5)
          above = std::max(above, std::fabs((*table)[i]));
      const auto box = [](const std::vector<float>& table) {
        return cl_float4{{table[0], table[1], table[2], table[3]}};
      };
      // (a pair's receivers drawn on the device, as region_visibility_bits draws them)
      const auto records = [&](bool placed, int count, bool absolute, const cl_float4& other) {
        cl::Buffer out = detail::deviceBuffer(st_, std::size_t(count) * REGION_END_RECORD * sizeof(float));
        detail::NamedKernel tables = kernel("region_end_tables");
        tables.set("h", heights_)
            .set("pyramid", pyramid_)
            .set("levels", cl_int(levels_))
            .set("margin", margin_)
            .set("z_bound", surface + above)
            .set("f", device)
            .set("placed", cl_int(placed))
            .set("points", source_points_buffer_)
            .set("table", receiver_table_)
            .set("absolute", cl_int(absolute))
            .set("seed", cl_uint(options_.seed))
            .set("count", cl_int(count))
            .set("other", other)
            .set("records", out);
        st_.launch(tables, cl::NDRange(detail::roundUp(count, detail::kLineGroup)),
                   cl::NDRange(detail::kLineGroup));
        return out;
      };
      if (certify_sources_) source_records_ = records(true, samples_, source_absolute_, box(*receivers_));
      if (certify_receivers_) receiver_records_ = records(false, count_, receiver_absolute_, box(sources_));
    }
    if (bitmask) {
      const BitmaskTable table = bitmaskTable(source_points_, options_.bitmask_table);
      table_ = upload(table.masks);
      tested_ = detail::deviceBuffer(st_, std::size_t(count_) * 2 * sizeof(cl_uint));
      kernel_ = kernel("region_bitmask_bits");
      setSurface(kernel_)
          .set("field_top", fieldTop(surface_.prepared))
          .set("f", device)
          .set("source_points", source_points_buffer_)
          .set("samples", cl_int(samples_))
          .set("light_z", source_points_[2])
          .set("target_height", static_cast<float>(options_.target_height))
          .set("table", table_)
          .set("t", table.shape)
          .set("lo_x", table.lo_x)
          .set("lo_y", table.lo_y)
          .set("hi_x", table.hi_x)
          .set("hi_y", table.hi_y)
          .set("words", cl_int(words_))
          .set("receiver_count", cl_int(count_))
          .set("receiver_major", cl_int(receiver_major_))
          .set("bits", bits_)
          .set("tested", tested_);
      return;
    }
    kernel_ = kernel("region_visibility_bits");
    setSurface(kernel_)
        .set("certify_receivers", cl_int(certify_receivers_))
        .set("certify_sources", cl_int(certify_sources_))
        .set("receiver_records", certify_receivers_ ? receiver_records_ : heights_)
        .set("source_records", certify_sources_ ? source_records_ : heights_)
        .set("f", device)
        .set("sources", source_table_)
        .set("source_points", source_points_buffer_)
        .set("source_absolute", cl_int(source_absolute_))
        .set("samples", cl_int(samples_))
        .set("pixel_receivers", cl_int(receivers_ == nullptr))
        .set("receivers", receiver_table_)
        .set("receiver_absolute", cl_int(receiver_absolute_))
        .set("receiver_count", cl_int(count_))
        .set("target_height", static_cast<float>(options_.target_height))
        .set("seed", cl_uint(options_.seed))
        .set("decorrelate", cl_int(options_.decorrelate))
        .set("words", cl_int(words_))
        .set("receiver_major", cl_int(receiver_major_))
        .set("bits", bits_);
  }

  // The surface's arguments, which both kernels take first: heights, the culling pyramid (the
  // heights stand in without one), its margin, the gradient bound and whether every height is finite.
  detail::NamedKernel& setSurface(detail::NamedKernel& k) const {
    return k.set("h", heights_)
        .set("pyramid", levels_ > 0 ? pyramid_ : heights_)
        .set("levels", cl_int(levels_))
        .set("margin", margin_)
        .set("gradient", gradient_)
        .set("finite_field", cl_int(finite_));
  }

  // Whether at least kProbeClear of kProbeLines sight lines spread over a pair's sources (stream
  // 0's, standing in for decorrelated ones too) and receivers, marched here, are clear: a pair where fewer
  // than about 1 line in 16 is clear skips the certifying tables (measured: they cost more than they save
  // there).
  bool probeClear(const detail::CullPyramid& pyramid, const DeviceField& device) const {
    constexpr int kProbeLines = 64, kProbeClear = 4;
    const std::vector<float>& h = surface_.prepared.heights;
    int clear = 0;
    for (int i = 0; i < kProbeLines; ++i) {
      const int s = int(std::int64_t(i) * samples_ / kProbeLines), r = int(std::int64_t(i) * 37 % count_);
      float xr, yr, zr;
      detail::region_sample(receivers_->data(), h.data(), field_.width, field_.height, receiver_absolute_,
                            detail::region_table_seed(receivers_->data(), options_.seed), 0u, r, &xr, &yr,
                            &zr);
      int blocked_at;
      if (!std::isnan(zr) &&
          detail::region_sight_visible_culled(h.data(), field_.width, field_.height, device.cell_x,
                                              device.cell_y, device.curvature, device.max_d2,
                                              pyramid.top.data(), pyramid.levels, pyramid.margin, 1.0f, 0.0f,
                                              0.0f, 0.0f, source_points_[3 * s], source_points_[3 * s + 1],
                                              source_points_[3 * s + 2], xr, yr, zr, 0.0f, 0.0f, &blocked_at))
        ++clear;
    }
    return clear >= kProbeClear;
  }

  int receiversPerLaunch() const { return std::max(1, kWordsPerLaunch / words_); }
  int itemCount() const override { return (count_ + receiversPerLaunch() - 1) / receiversPerLaunch(); }

  void runItem(int item, int) override {
    const int first = item * receiversPerLaunch(), chunk = std::min(receiversPerLaunch(), count_ - first);
    kernel_.set("first", cl_int(first));
    st_.launch(kernel_, cl::NDRange(detail::roundUp(chunk, detail::kLineGroup)),
               cl::NDRange(detail::kLineGroup));
  }

  void finish() override {
    const std::size_t entries = static_cast<std::size_t>(count_) * words_;
    std::vector<std::uint32_t> out(entries);
    st_.queue.enqueueReadBuffer(bits_, CL_TRUE, 0, entries * sizeof(std::uint32_t), out.data());
    if (options_.method == RegionVisibilityMethod::Bitmask) {
      std::vector<cl_uint> tested(std::size_t(count_) * 2);
      st_.queue.enqueueReadBuffer(tested_, CL_TRUE, 0, tested.size() * sizeof(cl_uint), tested.data());
      for (std::size_t i = 0; i < tested.size(); i += 2)
        exact_tested += tested[i], exact_tested_visible += tested[i + 1];
    }
    if (receiver_major_) {
      bits = std::move(out);
      return;
    }
    bits.resize(entries);
    for (int r = 0; r < count_; ++r)
      for (int w = 0; w < words_; ++w) bits[std::size_t(r) * words_ + w] = out[std::size_t(w) * count_ + r];
  }

  const RegionSurface& surface_;
  const std::vector<float>& sources_;
  const std::vector<float>& source_points_;  // stream 0's samples, x, y, z each
  const bool source_absolute_;
  const std::vector<float>* receivers_;
  const bool receiver_absolute_;
  const int count_;
  const RegionVisibilityOptions& options_;
  const int samples_, words_;
  bool receiver_major_ = true;
  int levels_ = 0;  // the culling pyramid's (0: the exact march)
  cl_float margin_ = 0.0f, gradient_ = 0.0f;
  bool finite_ = false;
  bool certify_sources_ = false, certify_receivers_ = false;  // per-end tables (culled only)
  cl::Buffer source_table_, source_points_buffer_, receiver_table_, bits_, pyramid_, source_records_,
      receiver_records_, table_, tested_;
  detail::NamedKernel kernel_;
};

std::vector<std::uint32_t> runBits(const ComputeContext& context, const RegionSurface& surface,
                                   const std::vector<float>& sources,
                                   const std::vector<float>& source_points, bool source_absolute,
                                   const std::vector<float>* receivers, bool receiver_absolute, int count,
                                   const RegionVisibilityOptions& options,
                                   RegionVisibilityResult* tested = nullptr) {
  return detail::translateOpenClErrors([&] {
    RegionBitsRoutine routine(detail::stateOf(context), surface, sources, source_points, source_absolute,
                              receivers, receiver_absolute, count, options);
    routine.run();
    if (tested) {
      tested->exact_tested = routine.exact_tested;
      tested->exact_tested_visible = routine.exact_tested_visible;
    }
    return std::move(routine.bits);
  });
}

// The viewsheds method: one viewshed per source sample from its own eye height (absolute), the
// visible targets' bits set, receiver-major.
std::vector<std::uint32_t> viewshedBits(const ComputeContext& context, const HeightField& field,
                                        const std::vector<RegionPoint>& samples,
                                        const RegionVisibilityOptions& options) {
  if (options.decorrelate)
    throw InvalidArgument(
        "the viewsheds method takes shared samples (no decorrelation): a viewshed per sample");
  for (const RegionPoint& p : samples)
    if (p.col != std::floor(p.col) || p.row != std::floor(p.row))
      throw InvalidArgument(
          "the viewsheds method needs sources on grid points (a one-point rectangle or points at "
          "whole columns and rows); sample " +
          std::to_string(p.col) + "," + std::to_string(p.row) + " is not");
  const int words = (static_cast<int>(samples.size()) + 31) / 32;
  std::vector<std::uint32_t> bits(field.pixelCount() * words, 0u);
  ViewshedOptions vo;
  vo.absolute = true;
  vo.target_height = options.target_height;
  vo.max_distance = options.max_distance;
  vo.curvature = options.curvature;
  for (std::size_t s = 0; s < samples.size(); ++s) {
    const Observer o{static_cast<int>(samples[s].col), static_cast<int>(samples[s].row), samples[s].height};
    const ViewshedResult v = computeViewshed(context, field, o, vo);
    for (std::size_t p = 0; p < v.visible.size(); ++p)
      if (v.visible[p] == 1.0f) bits[p * words + s / 32] |= 1u << (s % 32);
    if (options.progress) options.progress(static_cast<int>(s) + 1, static_cast<int>(samples.size()));
  }
  return bits;
}

// A table's samples from stream 0 of `seed` (mixed with the table's own: region_table_seed) on
// the z-scaled heights (region_sample, as the kernel places them): x, y, z each.
std::vector<float> tableSamplePoints(const HeightField& field, const std::vector<float>& table,
                                     const std::vector<float>& heights, bool absolute, std::uint32_t seed) {
  std::vector<float> points;
  const std::uint32_t table_seed = detail::region_table_seed(table.data(), seed);
  for (int s = 0; s < detail::regionTableSamples(table); ++s) {
    float x, y, z;
    detail::region_sample(table.data(), heights.data(), field.width, field.height, absolute, table_seed, 0u,
                          s, &x, &y, &z);
    points.insert(points.end(), {x, y, z});
  }
  return points;
}

std::vector<RegionPoint> regionPoints(const std::vector<float>& xyz) {
  std::vector<RegionPoint> points;
  for (std::size_t i = 0; i + 2 < xyz.size(); i += 3) points.push_back({xyz[i], xyz[i + 1], xyz[i + 2]});
  return points;
}

// The light image's bilinear colour (hfvis::LightImage) at position (x, y) of a table's
// rectangle.
std::array<double, 3> lightColour(const LightImage& image, const std::vector<float>& table, float x,
                                  float y) {
  // The continuous texel coordinate: texel centres at whole numbers, clamped to the edge ones.
  const auto texel = [](double at, double lo, double hi, int n) {
    const double u = hi > lo ? (at - lo) / (hi - lo) : 0.5;
    return std::clamp(u * n - 0.5, 0.0, n - 1.0);
  };
  const double tx = texel(x, table[0], table[2], image.width),
               ty = texel(y, table[1], table[3], image.height);
  const int i0 = static_cast<int>(tx), j0 = static_cast<int>(ty);
  const int i1 = std::min(i0 + 1, image.width - 1), j1 = std::min(j0 + 1, image.height - 1);
  const double fx = tx - i0, fy = ty - j0;
  const std::size_t plane = std::size_t(image.width) * image.height;
  std::array<double, 3> rgb{};
  for (int c = 0; c < 3; ++c) {
    const float* v = image.rgb.data() + c * plane;
    const auto at = [&](int i, int j) { return double(v[std::size_t(j) * image.width + i]); };
    // As lerps: an image of one colour gives that colour exactly.
    const double top = at(i0, j0) + fx * (at(i1, j0) - at(i0, j0));
    const double bottom = at(i0, j1) + fx * (at(i1, j1) - at(i0, j1));
    rgb[c] = top + fy * (bottom - top);
  }
  return rgb;
}

// The result's red, green, blue: per receiver the colours of the samples it sees, over S. The
// shared samples' colours are looked up once; decorrelated, each receiver's own (stream p + 1).
void colourLight(RegionVisibilityResult& out, const HeightField& field, const std::vector<float>& table,
                 const std::vector<float>& points, const RegionVisibilityOptions& options) {
  const LightImage& image = options.light_image;
  std::vector<std::array<double, 3>> shared;
  for (std::size_t i = 0; i + 2 < points.size(); i += 3)
    shared.push_back(lightColour(image, table, points[i], points[i + 1]));
  const std::size_t count = field.pixelCount();
  const std::uint32_t table_seed = detail::region_table_seed(table.data(), options.seed);
  for (auto* plane : {&out.red, &out.green, &out.blue})
    plane->assign(count, std::numeric_limits<float>::quiet_NaN());
  for (std::size_t p = 0; p < count; ++p) {
    if (!std::isfinite(field.heights[p])) continue;
    std::array<double, 3> sum{};
    for (int w = 0; w < out.words; ++w)
      for (std::uint32_t word = out.bits[p * out.words + w]; word != 0u; word &= word - 1u) {
        const int s = 32 * w + __builtin_ctz(word);
        std::array<double, 3> colour;
        if (options.decorrelate) {
          // (only the position: absolute spares the surface lookup)
          float x, y, z;
          detail::region_sample(table.data(), nullptr, field.width, field.height, 1, table_seed,
                                static_cast<unsigned>(p) + 1u, s, &x, &y, &z);
          colour = lightColour(image, table, x, y);
        } else {
          colour = shared[s];
        }
        for (int c = 0; c < 3; ++c) sum[c] += colour[c];
      }
    out.red[p] = static_cast<float>(sum[0] / out.samples);
    out.green[p] = static_cast<float>(sum[1] / out.samples);
    out.blue[p] = static_cast<float>(sum[2] / out.samples);
  }
}

}  // namespace

namespace detail {

CullPyramid cullPyramid(const std::vector<float>& h, int width, int height, bool checked, int bands) {
  CullPyramid out;
  if (width < 2 || height < 2) return out;  // no cells: the march runs uncut
  const auto at = [&](int c, int r) { return h[std::size_t(r) * width + c]; };
  // The field's largest finite height, step between neighbours and cell twist: the march's
  // values over a block stray from its corners' range by rounding relative to the heights, and
  // by a step or a twist times a position's rounding (a crossing a rounding outside the block, a
  // piece's middle a rounding into the next cell): at most ulp(max(width, height)) each.
  double largest = 0.0, step = 0.0, twist = 0.0;
  bool any_infinite = false;
  // Every height finite (most fields): the same maxima row by row without the checks (the call's
  // fixed cost: this pass and level 0 took about half of it, bench/report/region_visibility.md),
  // in bands of rows on the host's threads (host_bands.hpp), each band's maxima then combined.
  const int given_bands = bands;
  if (bands <= 0) bands = bandsFor(height, width);
  bool all_finite = !checked;
  {
    std::vector<char> band_finite(bands, 1);
    forEachBand(height, bands, [&](int band, int first, int last) {
      bool finite = true;
      for (std::size_t i = std::size_t(first) * width; i < std::size_t(last) * width; ++i)
        finite &= std::fabs(h[i]) <= std::numeric_limits<float>::max();
      band_finite[band] = finite;
    });
    for (const char finite : band_finite) all_finite = all_finite && finite;
  }
  if (all_finite) {
    // (kLanes running maxima each, so that the maxima do not wait on one another)
    constexpr int kLanes = 8;
    struct Maxima {
      std::array<float, kLanes> largest{}, step{};
      std::array<double, kLanes> twist{};
    };
    std::vector<Maxima> band_maxima(bands);
    forEachBand(height, bands, [&](int band, int first, int last) {
      Maxima m;  // (local: the lanes stay in registers, where the heights' pointer may not alias them)
      // (whole runs of kLanes columns lane by lane, so that the compiler keeps the lanes in one
      // vector; then the rest)
      for (int r = first; r < last; ++r) {
        const float* row = h.data() + std::size_t(r) * width;
        const float* next = row + width;
        const bool below = r + 1 < height;
        int c = 0;
        for (; c + kLanes < width; c += kLanes) {
          for (int i = 0; i < kLanes; ++i) {
            m.largest[i] = std::max(m.largest[i], std::fabs(row[c + i]));
            m.step[i] = std::max(m.step[i], std::fabs(row[c + i + 1] - row[c + i]));
          }
          if (!below) continue;
          for (int i = 0; i < kLanes; ++i) {
            m.step[i] = std::max(m.step[i], std::fabs(next[c + i] - row[c + i]));
            m.twist[i] = std::max(m.twist[i], std::fabs(double(row[c + i]) - row[c + i + 1] - next[c + i] +
                                                        next[c + i + 1]));
          }
        }
        for (; c < width; ++c) {
          m.largest[0] = std::max(m.largest[0], std::fabs(row[c]));
          if (c + 1 < width) m.step[0] = std::max(m.step[0], std::fabs(row[c + 1] - row[c]));
          if (!below) continue;
          m.step[0] = std::max(m.step[0], std::fabs(next[c] - row[c]));
          if (c + 1 < width)
            m.twist[0] = std::max(m.twist[0], std::fabs(double(row[c]) - row[c + 1] - next[c] + next[c + 1]));
        }
      }
      band_maxima[band] = m;
    });
    for (const Maxima& m : band_maxima)
      for (int i = 0; i < kLanes; ++i) {
        largest = std::max(largest, double(m.largest[i]));
        step = std::max(step, double(m.step[i]));
        twist = std::max(twist, m.twist[i]);
      }
  }
  for (int r = 0; !all_finite && r < height; ++r)
    for (int c = 0; c < width; ++c) {
      const float v = at(c, r);
      any_infinite = any_infinite || std::isinf(v);
      out.finite = out.finite && std::isfinite(v);
      if (!std::isfinite(v)) continue;
      largest = std::max(largest, double(std::fabs(v)));
      if (c + 1 < width && std::isfinite(at(c + 1, r)))
        step = std::max(step, double(std::fabs(at(c + 1, r) - v)));
      if (r + 1 < height && std::isfinite(at(c, r + 1)))
        step = std::max(step, double(std::fabs(at(c, r + 1) - v)));
      if (c + 1 < width && r + 1 < height) {
        const double t = double(v) - at(c + 1, r) - at(c, r + 1) + at(c + 1, r + 1);
        if (std::isfinite(t)) twist = std::max(twist, std::fabs(t));
      }
    }
  const double position_ulp = std::ldexp(double(std::max(width, height)), -23);
  out.margin = static_cast<float>(8e-5 * largest + 4.0 * position_ulp * (step + twist));
  out.gradient = static_cast<float>(step + twist);
  // The levels' sizes (as region_cull_width), then the levels in place, one after another.
  std::vector<std::size_t> offsets = {0};
  for (int w = width - 1, hh = height - 1;;) {
    offsets.push_back(offsets.back() + std::size_t(w) * hh);
    if ((w == 1 && hh == 1) || int(offsets.size()) - 1 == kCullLevels) break;
    w = (w + 1) / 2, hh = (hh + 1) / 2;
  }
  out.levels = int(offsets.size()) - 1;
  out.top.assign(offsets.back(), -std::numeric_limits<float>::infinity());
  // Level 0: per cell its corners' highest valid height; +INFINITY where an infinite height lies
  // on the cell or a cell beside it (the march's values there are unbounded or NaN).
  int w = width - 1, hh = height - 1;
  if (all_finite)
    forEachBand(hh, bands, [&](int, int first, int last) {
      for (int r = first; r < last; ++r) {
        const float* row = h.data() + std::size_t(r) * width;
        const float* next = row + width;
        float* level = out.top.data() + std::size_t(r) * w;
        for (int c = 0; c < w; ++c)  // (the corners in the order of the loop below: the same zeros' signs)
          level[c] = std::max(std::max(std::max(row[c], row[c + 1]), next[c]), next[c + 1]);
      }
    });
  for (int r = 0; !all_finite && r < hh; ++r)
    for (int c = 0; c < w; ++c) {
      bool unbounded = false;
      for (int y = std::max(0, r - 1); any_infinite && y <= std::min(height - 1, r + 2) && !unbounded; ++y)
        for (int x = std::max(0, c - 1); x <= std::min(width - 1, c + 2); ++x)
          if (std::isinf(at(x, y))) unbounded = true;
      float top = -std::numeric_limits<float>::infinity();
      for (const float v : {at(c, r), at(c + 1, r), at(c, r + 1), at(c + 1, r + 1)})
        if (!std::isnan(v)) top = std::max(top, v);
      out.top[std::size_t(r) * w + c] = unbounded ? std::numeric_limits<float>::infinity() : top;
    }
  for (int k = 1; k < out.levels; ++k) {
    const float* child = out.top.data() + offsets[k - 1];
    float* parent = out.top.data() + offsets[k];
    const int pw = (w + 1) / 2, ph = (hh + 1) / 2;
    // Per parent its children in row order (no value is NaN: the maxima of the pass they replace).
    forEachBand(ph, given_bands > 0 ? given_bands : bandsFor(ph, 4LL * pw), [&](int, int first, int last) {
      for (int r = first; r < last; ++r) {
        const float* upper = child + std::size_t(2 * r) * w;
        const float* lower = 2 * r + 1 < hh ? upper + w : nullptr;
        float* p = parent + std::size_t(r) * pw;
        for (int c = 0; c < pw; ++c) {
          float v = upper[2 * c];
          if (2 * c + 1 < w) v = std::max(v, upper[2 * c + 1]);
          if (lower) {
            v = std::max(v, lower[2 * c]);
            if (2 * c + 1 < w) v = std::max(v, lower[2 * c + 1]);
          }
          p[c] = v;
        }
      }
    });
    w = pw, hh = ph;
  }
  return out;
}

void countPairFractions(RegionPairVisibilityResult& out) {
  out.pairs = static_cast<std::uint64_t>(out.source_samples) * out.receiver_samples;
  out.clear_pairs = 0;
  out.source_fraction.assign(out.source_samples, 0.0f);
  out.receiver_fraction.assign(out.receiver_samples, 0.0f);
  std::vector<int> seen_by(out.source_samples, 0);
  for (int r = 0; r < out.receiver_samples; ++r) {
    int seen = 0;
    for (int s = 0; s < out.source_samples; ++s)
      if (out.visible(r, s)) ++seen, ++seen_by[s];
    out.clear_pairs += seen;
    out.receiver_fraction[r] = static_cast<float>(static_cast<double>(seen) / out.source_samples);
  }
  for (int s = 0; s < out.source_samples; ++s)
    out.source_fraction[s] = static_cast<float>(static_cast<double>(seen_by[s]) / out.receiver_samples);
}

std::vector<float> regionSampleTable(const HeightField& field, const RegionSampling& sampling,
                                     const std::vector<float>* heights) {
  validateSampling(field, sampling, heights);
  std::vector<float> table;
  if (!sampling.points.empty()) {
    float lo_x = std::numeric_limits<float>::max(), lo_y = lo_x, hi_x = -lo_x, hi_y = -lo_x;
    for (const RegionPoint& p : sampling.points) {
      lo_x = std::min(lo_x, float(p.col)), hi_x = std::max(hi_x, float(p.col));
      lo_y = std::min(lo_y, float(p.row)), hi_y = std::max(hi_y, float(p.row));
    }
    table = {lo_x, lo_y, hi_x, hi_y};
    for (const RegionPoint& p : sampling.points)
      table.insert(table.end(), {float(p.col), float(p.row), 0.0f, 0.0f, float(p.height)});
    return table;
  }
  const PixelRectangle& r = sampling.rectangle;
  const int x0 = std::min(r.col0, r.col1), x1 = std::max(r.col0, r.col1);
  const int y0 = std::min(r.row0, r.row1), y1 = std::max(r.row0, r.row1);
  const double ex = x1 - x0, ey = y1 - y0;
  const int s_count = sampling.samples;
  // Rows of n strata, n chosen so that the strata are about square; the last row holds the rest.
  int n = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(s_count))));
  if (ex == 0.0)
    n = 1;
  else if (ey == 0.0)
    n = s_count;
  else
    n = static_cast<int>(std::ceil(std::sqrt(s_count * ex / ey)));
  n = std::clamp(n, 1, s_count);
  const int rows = (s_count + n - 1) / n;
  table = {float(x0), float(y0), float(x1), float(y1)};
  for (int s = 0; s < s_count; ++s) {
    const int j = s / n, i = s % n;
    const int in_row = j == rows - 1 ? s_count - (rows - 1) * n : n;
    const double sx = ex / in_row, sy = ey / rows;
    table.insert(table.end(),
                 {float(x0 + sx * i), float(y0 + sy * j), float(sx), float(sy), float(sampling.height)});
  }
  return table;
}

}  // namespace detail

void validate(const RegionVisibilityOptions& options) {
  if (!std::isfinite(options.target_height) || options.target_height < 0.0)
    throw InvalidArgument("the target height must be finite and at least 0");
  if (!std::isfinite(options.max_distance) || options.max_distance < 0.0)
    throw InvalidArgument("the maximum distance must be finite and at least 0 (0: no limit)");
  // (the kernels take its square in float32: below about 1e-19 that is 0, which means no limit)
  if (options.max_distance > 0.0 && options.max_distance < kLeastMaxDistance)
    throw InvalidArgument("the maximum distance " + detail::shortNumber(options.max_distance) +
                          " is too short to hold: give at least " + detail::shortNumber(kLeastMaxDistance) +
                          " ground units, or 0 for no limit");
  detail::validateCurvature(options.curvature, "the curvature");
  const LightImage& image = options.light_image;
  if (image.width != 0 || image.height != 0 || !image.rgb.empty()) {
    if (image.width < 1 || image.height < 1 ||
        image.rgb.size() !=
            3 * static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height))
      throw InvalidArgument("a light image needs width, height >= 1 and 3 * width * height values (got " +
                            std::to_string(image.width) + " x " + std::to_string(image.height) + ", " +
                            std::to_string(image.rgb.size()) + " values)");
    const std::size_t plane = image.rgb.size() / 3;
    for (std::size_t i = 0; i < image.rgb.size(); ++i)
      if (!std::isfinite(image.rgb[i]) || image.rgb[i] < 0.0f)
        throw InvalidArgument(
            "the light image's colours must be finite and >= 0; channel " + std::string(1, "RGB"[i / plane]) +
            " at column " + std::to_string(i % plane % image.width) + ", row " +
            std::to_string(i % plane / image.width) + " holds " + std::to_string(image.rgb[i]));
  }
  if (options.method != RegionVisibilityMethod::Exact &&
      options.method != RegionVisibilityMethod::Viewsheds &&
      options.method != RegionVisibilityMethod::Culled && options.method != RegionVisibilityMethod::Bitmask &&
      options.method != RegionVisibilityMethod::Auto)
    throw InvalidArgument("unknown region visibility method " +
                          std::to_string(static_cast<int>(options.method)));
  if (options.bitmask_table < 8 || options.bitmask_table > 1024)
    throw InvalidArgument("the bitmask table takes 8 .. 1024 angles and offsets (got " +
                          std::to_string(options.bitmask_table) + ")");
}

void validate(const HeightField& field, const RegionSampling& sampling) {
  detail::validateSampling(field, sampling, nullptr);
}

namespace detail {

void validateSampling(const HeightField& field, const RegionSampling& sampling,
                      const std::vector<float>* prepared) {
  const auto held = [](double height) {
    return std::isfinite(height) && std::fabs(height) <= kMostGivenHeight;
  };
  if (!held(sampling.height))
    throw InvalidArgument("a region's height must be finite and within +-" +
                          detail::shortNumber(kMostGivenHeight) + " (got " +
                          detail::shortNumber(sampling.height) + ")");
  if (!sampling.points.empty()) {
    if (sampling.points.size() > static_cast<std::size_t>(kMaxRegionSamples))
      throw InvalidArgument("a region takes at most " + std::to_string(kMaxRegionSamples) + " points (got " +
                            std::to_string(sampling.points.size()) + ")");
    std::vector<float> own;
    if (!prepared) own = detail::prepareHeights(field, detail::HeightOrigin::Zero).heights;
    const std::vector<float>& heights = prepared ? *prepared : own;
    for (const RegionPoint& p : sampling.points) {
      // (a point just outside must not print as one inside)
      const std::string at = detail::exactNumber(p.col) + "," + detail::exactNumber(p.row);
      if (!(p.col >= 0.0 && p.col <= field.width - 1.0 && p.row >= 0.0 && p.row <= field.height - 1.0))
        throw InvalidArgument("region point " + at + " is outside the " + std::to_string(field.width) +
                              " x " + std::to_string(field.height) + " field");
      if (!held(p.height))
        throw InvalidArgument("region point " + at + " has a height (" + detail::shortNumber(p.height) +
                              ") not finite or beyond +-" + detail::shortNumber(kMostGivenHeight));
      const float s =
          detail::region_surface_at(heights.data(), field.width, field.height, float(p.col), float(p.row));
      if (std::isnan(s)) throw InvalidArgument("region point " + at + " lies over nodata");
    }
    return;
  }
  const PixelRectangle& r = sampling.rectangle;
  const std::string rect = corner(r.col0, r.row0) + " .. " + corner(r.col1, r.row1);
  for (const auto& [c, w] : {std::pair{r.col0, field.width}, {r.col1, field.width}})
    if (c < 0 || c >= w)
      throw InvalidArgument("region " + rect + " is outside the " + std::to_string(field.width) + " x " +
                            std::to_string(field.height) + " field");
  for (int row : {r.row0, r.row1})
    if (row < 0 || row >= field.height)
      throw InvalidArgument("region " + rect + " is outside the " + std::to_string(field.width) + " x " +
                            std::to_string(field.height) + " field");
  if (sampling.samples < 1 || sampling.samples > kMaxRegionSamples)
    throw InvalidArgument("a region takes 1 .. " + std::to_string(kMaxRegionSamples) + " samples (got " +
                          std::to_string(sampling.samples) + ")");
  for (int row = std::min(r.row0, r.row1); row <= std::max(r.row0, r.row1); ++row)
    for (int col = std::min(r.col0, r.col1); col <= std::max(r.col0, r.col1); ++col)
      if (!std::isfinite(field.at(col, row)))
        throw InvalidArgument("region " + rect + " holds nodata (at " + corner(col, row) + ")");
}

}  // namespace detail

std::vector<RegionPoint> regionSamplePoints(const HeightField& field, const RegionSampling& sampling,
                                            std::uint32_t seed) {
  validate(field);
  const std::vector<float> table = detail::regionSampleTable(field, sampling);
  const std::vector<float> heights = detail::prepareHeights(field, detail::HeightOrigin::Zero).heights;
  return regionPoints(tableSamplePoints(field, table, heights, sampling.absolute, seed));
}

const char* regionVisibilityMethodName(RegionVisibilityMethod method) {
  switch (method) {
    case RegionVisibilityMethod::Exact: return "exact";
    case RegionVisibilityMethod::Viewsheds: return "viewsheds";
    case RegionVisibilityMethod::Culled: return "culled";
    case RegionVisibilityMethod::Bitmask: return "bitmask";
    case RegionVisibilityMethod::Auto: return "auto";
  }
  return "unknown";
}

namespace {

// S of a region: its points, or its rectangle's samples.
std::size_t sourceSamples(const RegionSampling& sources) {
  return sources.points.empty() ? std::size_t(sources.samples) : sources.points.size();
}

// Why the bitmask method cannot take this light over `field` ("" when it can): its occluders are
// back-projected onto one plane, through one table of the shared samples, and they are the field's
// cells, which a field one point thick has none of (its walls would hide nothing).
std::string bitmaskRefusal(const HeightField& field, const RegionSampling& sources,
                           const RegionVisibilityOptions& options) {
  if (field.width < 2 || field.height < 2)
    return "the bitmask method takes a field of cells, at least 2 x 2 points (this one is " +
           std::to_string(field.width) + " x " + std::to_string(field.height) + "): take --method culled";
  bool planar = sources.absolute;
  for (const RegionPoint& p : sources.points) planar = planar && p.height == sources.points[0].height;
  if (!planar)
    return "the bitmask method takes a planar light: a rectangle at an absolute height (--absolute), or "
           "points all at one absolute height; not heights above the surface";
  if (options.decorrelate) return "the bitmask method takes shared samples (no decorrelation): one table of them";
  if (options.curvature != 0.0)
    return "the bitmask method takes no curvature: its back-projections are straight lines";
  const std::size_t samples = sourceSamples(sources);
  if (samples > std::size_t(kMaxBitmaskSamples))
    return "the bitmask method takes at most " + std::to_string(kMaxBitmaskSamples) + " samples (got " +
           std::to_string(samples) + ")";
  return "";
}

// The method an every-pixel run takes: options.method, or for Auto the bitmask method where it
// takes the light and S is at least kBitmaskFromSamples (same bits, sooner), else the culled march.
RegionVisibilityMethod methodFor(const HeightField& field, const RegionSampling& sources,
                                 const RegionVisibilityOptions& options) {
  if (options.method == RegionVisibilityMethod::Bitmask) {
    const std::string refusal = bitmaskRefusal(field, sources, options);
    if (!refusal.empty()) throw InvalidArgument(refusal);
  }
  if (options.method != RegionVisibilityMethod::Auto) return options.method;
  return sourceSamples(sources) >= std::size_t(kBitmaskFromSamples) &&
                 bitmaskRefusal(field, sources, options).empty()
             ? RegionVisibilityMethod::Bitmask
             : RegionVisibilityMethod::Culled;
}

}  // namespace

namespace {

// A run over every pixel of `field` (validated): on `prepared` (a RegionField's surface), or on a
// surface prepared here for this call alone.
RegionVisibilityResult regionVisibility(const ComputeContext& context, const HeightField& field,
                                        const RegionSurface* prepared, const RegionSampling& sources,
                                        const RegionVisibilityOptions& options) {
  validate(options);
  const bool coloured = options.light_image.width > 0;
  if (coloured && !sources.points.empty())
    throw InvalidArgument("a light image lies over a rectangle light, not over explicit points");
  RegionVisibilityOptions run = options;
  run.method = methodFor(field, sources, options);
  const std::vector<float> table =
      detail::regionSampleTable(field, sources, prepared ? &prepared->prepared.heights : nullptr);
  const bool viewsheds = run.method == RegionVisibilityMethod::Viewsheds;
  RegionSurface own;
  if (!prepared)
    own = detail::translateOpenClErrors([&] {
      const bool pyramid =
          run.method == RegionVisibilityMethod::Culled || run.method == RegionVisibilityMethod::Bitmask;
      return prepareSurface(detail::stateOf(context), field, pyramid, !viewsheds);
    });
  const RegionSurface& surface = prepared ? *prepared : own;
  const std::vector<float>& heights = surface.prepared.heights;
  RegionVisibilityResult out;
  out.width = field.width;
  out.height = field.height;
  out.samples = detail::regionTableSamples(table);
  out.words = (out.samples + 31) / 32;
  const int count = static_cast<int>(field.pixelCount());
  const std::vector<float> points = tableSamplePoints(field, table, heights, sources.absolute, options.seed);
  if (viewsheds)
    out.bits = viewshedBits(context, field, regionPoints(points), run);
  else
    out.bits = runBits(context, surface, table, points, sources.absolute, nullptr, false, count, run, &out);
  out.fraction.resize(field.pixelCount());
  for (int p = 0; p < count; ++p) {
    int seen = 0;
    for (int w = 0; w < out.words; ++w) seen += popcount(out.bits[std::size_t(p) * out.words + w]);
    out.fraction[p] = !std::isfinite(field.heights[p])
                          ? std::numeric_limits<float>::quiet_NaN()
                          : static_cast<float>(static_cast<double>(seen) / out.samples);
  }
  out.method = run.method;
  if (coloured) colourLight(out, field, table, points, run);
  return out;
}

// A region pair on `field` (validated), as regionVisibility.
RegionPairVisibilityResult regionPairVisibility(const ComputeContext& context, const HeightField& field,
                                                const RegionSurface* prepared, const RegionSampling& sources,
                                                const RegionSampling& receivers,
                                                const RegionVisibilityOptions& options) {
  validate(options);
  if (options.method == RegionVisibilityMethod::Viewsheds ||
      options.method == RegionVisibilityMethod::Bitmask)
    throw InvalidArgument(std::string("the ") +
                          (options.method == RegionVisibilityMethod::Bitmask ? "bitmask" : "viewsheds") +
                          " method takes every-pixel receivers, not a region pair");
  if (options.light_image.width > 0)
    throw InvalidArgument("a light image colours every-pixel receivers, not a region pair");
  RegionVisibilityOptions run = options;  // Auto: the culled march (the bitmask method takes no pair)
  if (run.method == RegionVisibilityMethod::Auto) run.method = RegionVisibilityMethod::Culled;
  const std::vector<float>* prepared_heights = prepared ? &prepared->prepared.heights : nullptr;
  const std::vector<float> source_table = detail::regionSampleTable(field, sources, prepared_heights);
  const std::vector<float> receiver_table = detail::regionSampleTable(field, receivers, prepared_heights);
  RegionSurface own;
  if (!prepared)
    own = detail::translateOpenClErrors([&] {
      return prepareSurface(detail::stateOf(context), field, run.method == RegionVisibilityMethod::Culled,
                            true);
    });
  const RegionSurface& surface = prepared ? *prepared : own;
  const std::vector<float>& heights = surface.prepared.heights;
  RegionPairVisibilityResult out;
  out.source_samples = detail::regionTableSamples(source_table);
  out.receiver_samples = detail::regionTableSamples(receiver_table);
  out.words = (out.source_samples + 31) / 32;
  const std::vector<float> source_points =
      tableSamplePoints(field, source_table, heights, sources.absolute, options.seed);
  out.sources = regionPoints(source_points);
  out.receivers =
      regionPoints(tableSamplePoints(field, receiver_table, heights, receivers.absolute, options.seed));
  out.bits = runBits(context, surface, source_table, source_points, sources.absolute, &receiver_table,
                     receivers.absolute, out.receiver_samples, run);
  detail::countPairFractions(out);
  return out;
}

}  // namespace

struct RegionField::State {
  State(const ComputeContext& c, const HeightField& f) : context(c), field(f) {}
  ComputeContext context;
  HeightField field;      // the caller's, copied
  RegionSurface surface;  // over `field`, with the pyramid, on the device
};

class RegionFieldAccess {
 public:
  static const RegionField::State& state(const RegionField& f) {
    if (!f.state_) throw InvalidArgument("a moved-from RegionField (it holds no prepared field)");
    return *f.state_;
  }
};

RegionField::RegionField(const ComputeContext& context, const HeightField& field) {
  validateField(field);
  auto state = std::make_shared<State>(context, field);
  state->surface = detail::translateOpenClErrors(
      [&] { return prepareSurface(detail::stateOf(context), state->field, true, true); });
  state_ = std::move(state);
}

const HeightField& RegionField::field() const { return RegionFieldAccess::state(*this).field; }
const ComputeContext& RegionField::context() const { return RegionFieldAccess::state(*this).context; }

RegionVisibilityResult computeRegionVisibility(const ComputeContext& context, const HeightField& field,
                                               const RegionSampling& sources,
                                               const RegionVisibilityOptions& options) {
  validateField(field);
  return regionVisibility(context, field, nullptr, sources, options);
}

RegionPairVisibilityResult computeRegionPairVisibility(const ComputeContext& context,
                                                       const HeightField& field,
                                                       const RegionSampling& sources,
                                                       const RegionSampling& receivers,
                                                       const RegionVisibilityOptions& options) {
  validateField(field);
  return regionPairVisibility(context, field, nullptr, sources, receivers, options);
}

RegionVisibilityResult computeRegionVisibility(const RegionField& field, const RegionSampling& sources,
                                               const RegionVisibilityOptions& options) {
  const auto& state = RegionFieldAccess::state(field);
  return regionVisibility(state.context, state.field, &state.surface, sources, options);
}

RegionPairVisibilityResult computeRegionPairVisibility(const RegionField& field,
                                                       const RegionSampling& sources,
                                                       const RegionSampling& receivers,
                                                       const RegionVisibilityOptions& options) {
  const auto& state = RegionFieldAccess::state(field);
  return regionPairVisibility(state.context, state.field, &state.surface, sources, receivers, options);
}

}  // namespace hfvis
