// intervisibility.cpp: the intervisibility operation on the device: per direction, one
// launch of the convex hull tree sweep on lattice lines (each receiver on the line through
// its own centre, its results added straight into the pixel sums), or of the naive march per
// batch of directions; the requested outputs are downloaded once at the end.
#include "hfvis/intervisibility.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

#include "hfvis/errors.hpp"
#include "core/horizon_common.hpp"
#include "core/hull_tree_device.hpp"
#include "core/hull_tree.hpp"
#include "core/opencl_context.hpp"
#include "core/sweep_framework.hpp"

namespace hfvis {

void validate(const IntervisibilityOptions& options, const IntervisibilityOutputs& outputs) {
  validate(static_cast<const SweepOptions&>(options));
  // (an enum value cast from a bad integer ran as one of them)
  if (options.method != IntervisibilityMethod::HullTree && options.method != IntervisibilityMethod::Naive)
    throw InvalidArgument("unknown intervisibility method " +
                          std::to_string(static_cast<int>(options.method)));
  validate(options.tree);
  if (!outputs.visible_count && !outputs.visible_area && !outputs.statistics) {
    throw InvalidArgument("no output requested");
  }
  if (outputs.statistics && options.method != IntervisibilityMethod::HullTree) {
    throw InvalidArgument("statistics (horizons and iterations) exist only for the hull-tree method");
  }
  detail::validateStripRows(options.strip_rows, options.method == IntervisibilityMethod::Naive);
  if (options.max_error != 0.0 || outputs.error_estimate) {
    if (options.method != IntervisibilityMethod::HullTree)
      throw InvalidArgument("an error estimate and a maximum error exist only for the hull-tree method");
    if (!(options.max_error >= 0.0 && options.max_error < 1.0))
      throw InvalidArgument("the maximum error must be in (0, 1): it is relative to the visible count (got " +
                            std::to_string(options.max_error) + ")");
    if (options.max_error == 0.0 && options.directions < 2)
      throw InvalidArgument("an error estimate needs K >= 2 (it compares the even and the odd directions)");
  }
}

namespace detail {
namespace {

// Adds one direction's per-line totals (receivers, m, t, naive, visible, skips).
void addLineTotals(const std::vector<cl_ulong>& totals, std::size_t lines, IntervisibilityStatistics& s) {
  for (std::size_t j = 0; j < lines; ++j) {
    const cl_ulong* t = &totals[j * kTreeLineTotals];
    s.receivers += t[0];
    s.lines += t[0] > 0;
    s.horizons += t[1];
    s.iterations += t[2];
    s.naive_iterations += t[3];
    s.visible_samples += t[4];
    s.safe_zone_skips += t[5];
    s.lines_over_bound += t[2] > 2 * t[1] + t[0] + t[6];  // nodes: samples and peaks
  }
}

IntervisibilityResult allocateResult(const HeightField& field, const IntervisibilityOptions& options,
                                     const IntervisibilityOutputs& outputs) {
  IntervisibilityResult result;
  result.width = field.width;
  result.height = field.height;
  result.directions = options.directions;
  for (int k = 0; k < options.directions; ++k) result.azimuths.push_back(directionAzimuth(k, options));
  // (the estimate needs the count even when only the area is asked for: finish clears it)
  if (outputs.visible_count || outputs.error_estimate) result.visible_count.resize(field.pixelCount());
  if (outputs.visible_area) result.visible_area.resize(field.pixelCount());
  return result;
}

void download(ContextState& st, const cl::Buffer& sums, std::vector<float>& out) {
  if (!out.empty()) st.queue.enqueueReadBuffer(sums, CL_TRUE, 0, out.size() * sizeof(float), out.data());
}

// Visible counts and areas by the tree.
// How a count run uses its device memory budget: the scratch, and the strips of rows (the
// field's height when it runs in one piece) with the halo of rows their periods reach.
struct CountPlan {
  std::size_t scratch_entries = 0;
  int strip_rows = 0, halo_rows = 0;
};

CountPlan planCount(const HeightField& field, const std::vector<TreeDirection>& directions,
                    const TreeProgramFlags& flags, const IntervisibilityOptions& options,
                    const DeviceInfo& device, bool line_major, bool halves) {
  const std::size_t budget = memoryBudget(options.memory_budget_bytes, device);
  const std::size_t max_alloc = device.max_allocation_bytes ? device.max_allocation_bytes : budget;
  const TreeScratchNeeds needs = treeScratchNeeds(directions, line_major);
  const std::size_t entry = treeEntryBytes(flags), row = field.width * sizeof(float);
  // Heights and the sums (the count also when only the area is asked for: the kernel adds both),
  // and the statistics' per-line totals; with the error estimate's halves (`halves`) the odd
  // directions' sums too, on the device for a whole field (in strips the host holds them).
  const std::size_t per_row = row * (2 + flags.area), odd_per_row = halves ? row * (1 + flags.area) : 0;
  std::size_t max_lines = 0;
  for (const TreeDirection& d : directions) max_lines = std::max(max_lines, d.lines.size());
  const std::size_t totals = flags.stats ? max_lines * kTreeLineTotals * sizeof(cl_ulong) : 0;
  const std::size_t whole = (per_row + odd_per_row) * field.height + totals, least = needs.longest * entry;
  const bool forced = options.strip_rows > 0 && options.strip_rows < field.height;
  CountPlan plan;
  if (!forced && whole + least <= budget && row * field.height <= max_alloc &&
      needs.longest * kTreeNodeBytes <= max_alloc) {
    plan.strip_rows = field.height;
    plan.scratch_entries = std::min({needs.whole, (budget - whole) / entry, max_alloc / kTreeNodeBytes});
    return plan;
  }
  // Strips beside a halo (a period's samples lie in the |b| rows toward its previous receiver) and the
  // lines' states, with as many rows as the budget holds once the scratch has half the rest
  // (or the longest line's tree, if more): a line's tree stays on the device through every
  // strip it crosses.
  // (in strips the sweep computes its peaks itself: no prepass's inputs, peakPrepass)
  TreeProgramFlags strip_flags = flags;
  strip_flags.strips = true;
  const std::size_t strip_entry = treeEntryBytes(strip_flags), strip_least = needs.longest * strip_entry;
  plan.halo_rows = 0;
  for (const TreeDirection& d : directions) plan.halo_rows = std::max(plan.halo_rows, std::abs(d.lattice.b));
  const std::size_t halo = 2 * static_cast<std::size_t>(plan.halo_rows) * row;
  const std::size_t states = max_lines * (kTreeLineStateBytes + sizeof(cl_int2)) + totals;
  const std::size_t rest = budget > halo + states ? budget - halo - states : 0;
  const std::size_t scratch = std::max(strip_least, std::min(needs.whole * strip_entry, rest / 2));
  std::size_t rows = rest > scratch ? (rest - scratch) / per_row : 0;
  rows = std::min(rows, max_alloc / row > 2 * static_cast<std::size_t>(plan.halo_rows)
                            ? max_alloc / row - 2 * plan.halo_rows : 0);
  if (forced) rows = std::min<std::size_t>(rows, options.strip_rows);
  // Strips of every row would run whole, with the whole field's larger entries (the peaks'
  // prepass): a field of more than one row runs in two strips at least here.
  rows = std::min<std::size_t>(rows, field.height > 1 ? field.height - 1 : 1);
  const std::size_t strips_bytes = rows * per_row + halo + states;
  if (rows < 1 || needs.longest * kTreeNodeBytes > max_alloc) {
    throw MemoryBudgetError("one direction needs " + mebibytes(per_row + halo + states + strip_least) +
                            " of device memory in strips of one row (its longest line's tree " + mebibytes(strip_least) +
                            ") but the budget is " + mebibytes(budget) + " (largest single buffer " +
                            mebibytes(max_alloc) + "); raise the memory budget");
  }
  plan.strip_rows = static_cast<int>(rows);
  const std::size_t runs_entry = rows >= static_cast<std::size_t>(field.height) ? entry : strip_entry;
  plan.scratch_entries =
      std::min({needs.whole, (budget - strips_bytes) / runs_entry, max_alloc / kTreeNodeBytes});
  if (plan.scratch_entries < needs.longest)  // (a one-row field, whole, in a budget this small)
    throw MemoryBudgetError("one direction needs " + mebibytes(strips_bytes + least) + " of device memory but the budget is " +
                            mebibytes(budget) + "; raise the memory budget");
  return plan;
}

// Visible counts and areas by the tree, on the whole field or in strips of rows.
class CountRoutine : public TreeRoutine {
 public:
  CountRoutine(ContextState& st, const HeightField& field, const IntervisibilityOptions& options,
               const IntervisibilityOutputs& outputs)
      : TreeRoutine(st, field, options, flagsFor(field, options, outputs)), visibility_(options), outputs_(outputs) {}

  IntervisibilityResult take() { return std::move(result_); }

 private:
  static TreeProgramFlags flagsFor(const HeightField& field, const IntervisibilityOptions& options,
                                   const IntervisibilityOutputs& outputs) {
    TreeProgramFlags flags;
    flags.area = outputs.visible_area;
    flags.stats = outputs.statistics;
    flags.tuning = options.tree;
    flags.curvature = options.curvature != 0.0;
    flags.row_spacing = hasRowSpacing(field);
    return flags;
  }

  // The heights, then the directions and the plan (which decide the program: strips or not).
  PreparedHeights prepare() override {
    PreparedHeights prepared = prepareHeights(field_);
    flags_.has_nodata = prepared.has_nodata;
    directions_ = treeDirections(field_, options_, flags_.row_spacing, outputs_.error_estimate);
    checkTreeLimits(directions_, prepared.heights);
    plan_ = planCount(field_, directions_, flags_, visibility_, st_.info, lineMajorLayout(st_),
                      outputs_.error_estimate);
    flags_.strips = inStrips();
    return prepared;
  }
  bool heightsResident() const override { return !inStrips(); }
  bool inStrips() const { return plan_.strip_rows < field_.height; }

  void allocate() override {
    result_ = allocateResult(field_, visibility_, outputs_);
    allocateTreeScratch(st_, flags_, directions_, plan_.scratch_entries, buffers_);
    buffers_.radiance = buffers_.normals = buffers_.irradiance = deviceBuffer(st_, 0);
    const bool halves = outputs_.error_estimate;
    buffers_.height_base = prepared_.base;
    if (!inStrips()) {
      const std::size_t plane = field_.pixelCount();
      buffers_.heights = heights_;
      count_sums_[0] = zeros(plane);
      area_sums_[0] = zeros(outputs_.visible_area ? plane : 0);
      count_sums_[1] = halves ? zeros(plane) : count_sums_[0];
      area_sums_[1] = halves ? zeros(outputs_.visible_area ? plane : 0) : area_sums_[0];
      return;
    }
    const std::size_t strip = static_cast<std::size_t>(plan_.strip_rows) * field_.width * sizeof(float);
    const std::size_t rows = std::min(plan_.strip_rows + 2 * plan_.halo_rows, field_.height);
    buffers_.heights = deviceBuffer(st_, rows * field_.width * sizeof(float));
    buffers_.count_sum = deviceBuffer(st_, strip);
    buffers_.area_sum = deviceBuffer(st_, outputs_.visible_area ? strip : 0);
    std::size_t max_lines = 0;
    for (const TreeDirection& d : directions_) max_lines = std::max(max_lines, d.lines.size());
    states_ = deviceBuffer(st_, max_lines * kTreeLineStateBytes);
    // The host holds the sums (allocateResult's zeros), a strip's rows on the device at a time.
    if (result_.visible_count.empty()) result_.visible_count.assign(field_.pixelCount(), 0.0f);
    if (halves) {
      odd_count_.assign(field_.pixelCount(), 0.0f);
      if (outputs_.visible_area) odd_area_.assign(field_.pixelCount(), 0.0f);
    }
  }

  // With the error estimate, the odd-numbered directions add into sums of their own.
  bool oddHalf(int direction) const {
    return outputs_.error_estimate && directions_[direction].index % 2 == 1;
  }

  void sweep(int direction, int) override {
    const bool odd = oddHalf(direction);
    if (!inStrips()) {
      buffers_.count_sum = count_sums_[odd];
      buffers_.area_sum = area_sums_[odd];
      return TreeRoutine::sweep(direction, 0);
    }
    std::vector<float>& count = odd ? odd_count_ : result_.visible_count;
    std::vector<float>& area = odd ? odd_area_ : result_.visible_area;
    const TreeDirection& d = directions_[direction];
    TreeKernel k = treeKernel(st_, program_, d, field_.width, field_.height, buffers_);
    const int b = d.lattice.b, strips = (field_.height + plan_.strip_rows - 1) / plan_.strip_rows;
    const std::size_t row = field_.width * sizeof(float);
    std::vector<LatticeLine> lines = d.lines;
    const auto chunks = chunkLines(lines, d.slotsPerPeriod(), buffers_.scratch_entries, lineMajorLayout(st_));
    for (std::size_t c = 0; c < chunks.size(); ++c) {
      const LineChunk& chunk = chunks[c];
      const cl::Buffer chunk_lines(st_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                                   chunk.count * sizeof(LatticeLine), lines.data() + chunk.first);
      k.kernel.set("lines", chunk_lines);
      k.kernel.set("n_lines", static_cast<int>(chunk.count));
      k.kernel.set("stride", static_cast<cl_uint>(chunk.stride));
      k.kernel.set("first_line", static_cast<int>(chunk.first));
      k.kernel.set("states", states_);
      // The strips in the order the lines run through them (receiver i in row row - i b).
      for (int t = 0; t < strips; ++t) {
        const int s = b > 0 ? strips - 1 - t : t;
        const int s0 = s * plan_.strip_rows, s1 = std::min(field_.height, s0 + plan_.strip_rows);
        std::vector<cl_int2> ranges(chunk.count);
        bool any = false;
        for (std::size_t i = 0; i < chunk.count; ++i) {
          const auto [first, end] = receiversInRows(lines[chunk.first + i], b, s0, s1);
          ranges[i] = {{first, end}};
          any = any || first < end;
        }
        if (any) sweepStrip(k, ranges, s0, s1, row, count, area);
        if (options_.strip_progress)
          options_.strip_progress(int(c) * strips + t + 1, int(chunks.size()) * strips);
      }
    }
  }

  // One strip of one chunk: its heights (with the halo) and sums (`count`, `area`: the host's
  // planes of its half) up, the sweep, the sums back.
  void sweepStrip(TreeKernel& k, const std::vector<cl_int2>& ranges, int s0, int s1, std::size_t row,
                  std::vector<float>& count, std::vector<float>& area) {
    const int h0 = std::max(0, s0 - plan_.halo_rows), h1 = std::min(field_.height, s1 + plan_.halo_rows);
    const std::size_t width = field_.width, sums = (s1 - s0) * row;
    st_.queue.enqueueWriteBuffer(buffers_.heights, CL_FALSE, 0, (h1 - h0) * row,
                                 &prepared_.heights[h0 * width]);
    st_.queue.enqueueWriteBuffer(buffers_.count_sum, CL_FALSE, 0, sums, &count[s0 * width]);
    if (outputs_.visible_area)
      st_.queue.enqueueWriteBuffer(buffers_.area_sum, CL_FALSE, 0, sums, &area[s0 * width]);
    const cl::Buffer ranges_buffer(st_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                                   ranges.size() * sizeof(cl_int2), const_cast<cl_int2*>(ranges.data()));
    k.kernel.set("row0", h0);
    k.kernel.set("out_row0", s0);
    k.kernel.set("strip_receivers", ranges_buffer);
    st_.launch(k.kernel, cl::NDRange(roundUp(ranges.size(), kLineGroup)), cl::NDRange(kLineGroup));
    st_.queue.enqueueReadBuffer(buffers_.count_sum, CL_FALSE, 0, sums, &count[s0 * width]);
    if (outputs_.visible_area)
      st_.queue.enqueueReadBuffer(buffers_.area_sum, CL_FALSE, 0, sums, &area[s0 * width]);
    st_.queue.finish();  // before the ranges go
  }

  void endBatch(int first, int count) override {
    if (!outputs_.statistics) return;
    for (int k = first; k < first + count; ++k) {
      totals_.resize(directions_[k].lines.size() * kTreeLineTotals);
      st_.queue.enqueueReadBuffer(buffers_.line_totals, CL_TRUE, 0, totals_.size() * sizeof(cl_ulong),
                                  totals_.data());
      addLineTotals(totals_, directions_[k].lines.size(), result_.statistics);
    }
  }

  void finish() override {
    if (!inStrips()) {  // else the host holds them
      download(st_, count_sums_[0], result_.visible_count);
      download(st_, area_sums_[0], result_.visible_area);
      if (outputs_.error_estimate) {
        odd_count_.resize(result_.visible_count.size());
        odd_area_.resize(result_.visible_area.size());
        download(st_, count_sums_[1], odd_count_);
        download(st_, area_sums_[1], odd_area_);
      }
    }
    if (outputs_.error_estimate) {
      double even_weight = 0.0, odd_weight = 0.0;
      for (const TreeDirection& d : directions_) (d.index % 2 ? odd_weight : even_weight) += d.lattice.weight;
      splitVisibilityHalves(result_, odd_count_, odd_area_, even_weight, odd_weight);
    }
    if (!outputs_.visible_count) result_.visible_count.clear();  // (the kernel adds it anyway)
  }

  const IntervisibilityOptions& visibility_;
  const IntervisibilityOutputs& outputs_;
  CountPlan plan_;
  cl::Buffer states_;
  // A whole field's sums on the device: [0] the even-numbered directions' (all of them without
  // the error estimate), [1] the odd-numbered ones' (the same buffers without it).
  cl::Buffer count_sums_[2], area_sums_[2];
  std::vector<float> odd_count_, odd_area_;  // the odd half's sums on the host
  IntervisibilityResult result_;
  std::vector<cl_ulong> totals_;
};

// Visible counts and areas by the naive march, a batch of directions per launch.
class NaiveCountRoutine : public SweepRoutine {
 public:
  NaiveCountRoutine(ContextState& st, const HeightField& field, const IntervisibilityOptions& options,
                    const IntervisibilityOutputs& outputs)
      : SweepRoutine(st, field, options), visibility_(options), outputs_(outputs) {}

  IntervisibilityResult take() { return std::move(result_); }

 private:
  std::string programFile() const override { return "intervisibility.cl"; }
  std::string programOptions() const override {
    TreeProgramFlags flags;
    flags.has_nodata = prepared_.has_nodata;
    flags.area = outputs_.visible_area;
    flags.stats = false;
    flags.curvature = visibility_.curvature != 0.0;
    flags.row_spacing = hasRowSpacing(field_);
    return treeProgramOptions(flags, st_);
  }

  void allocate() override {
    const std::size_t plane = field_.pixelCount();
    rays_ = runDirections(field_, visibility_);
    // A ray has at most (W + H) S steps; the kernel's predicate takes steps as exact floats,
    // and its distance sums (up to n^2 / 2 steps) are 32-bit to keep its loop vectorised.
    const double longest = (double(field_.width) + field_.height) * visibility_.samples_per_unit + 2.0;
    std::size_t longest_position = static_cast<std::size_t>(longest);
    if (hasRowSpacing(field_)) {  // positions in units: at most the steps times a step's most units
      unit_ = groundUnit(field_);
      rows_ = naiveRowTables(field_, rays_, unit_);
      longest_position *= static_cast<std::size_t>(*std::max_element(rows_.units.begin(), rows_.units.end()));
    }
    checkStepLimits(longest_position, prepared_.heights);
    if (outputs_.visible_area && longest * longest / 2.0 >= 4294967295.0) {
      throw InvalidArgument("the naive march's rays would have up to " + std::to_string(std::size_t(longest)) +
                            " samples, too many for its visible area (at most 92681): lower the samples per "
                            "unit or use the hull tree");
    }
    count_sum_ = zeros(plane);
    area_sum_ = zeros(outputs_.visible_area ? plane : 0);
    result_ = allocateResult(field_, visibility_, outputs_);
  }

  int directionCount() const override { return visibility_.directions; }
  int batchSize() const override { return kMaxDirectionsPerBatch; }
  void sweep(int, int) override {}  // a launch per batch

  void endBatch(int first, int count) override {
    const std::vector<SweepDirection> batch(rays_.begin() + first, rays_.begin() + first + count);
    const cl::Buffer directions = uploadDirections(st_, batch);
    NamedKernel naive(st_, program_, "intervisibility_naive");
    naive.set("heights", heights_);
    naive.set("width", field_.width);
    naive.set("height", field_.height);
    naive.set("directions", directions);
    naive.set("batch_size", count);
    naive.set("sector", intervisibilitySector(visibility_));
    naive.set("height_base", prepared_.base);
    // With per-row spacing positions are units: the drop per unit squared, distances in units.
    const double per_unit = unit_ * unit_;
    naive.set("curvature", static_cast<float>(visibility_.curvature * (unit_ > 0.0 ? per_unit : 1.0)));
    std::vector<cl_int> max_steps;
    for (const SweepDirection& d : batch)
      max_steps.push_back(stepsWithin(visibility_.max_distance,
                                      unit_ > 0.0 ? unit_ : double(d.step_length) * d.ground_per_pixel));
    auto upload = [&](const void* data, std::size_t bytes) {
      if (!bytes) return deviceBuffer(st_, 0);
      return cl::Buffer(st_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, bytes, const_cast<void*>(data));
    };
    const cl::Buffer max_steps_buffer = upload(max_steps.data(), max_steps.size() * sizeof(cl_int));
    naive.set("max_steps", max_steps_buffer);
    // This batch's slices of the row tables.
    const std::size_t half_rows = 2 * static_cast<std::size_t>(field_.height) - 1, rows = 2 * field_.height;
    const cl::Buffer units = upload(rows_.units.empty() ? nullptr : &rows_.units[first * half_rows],
                                    rows_.units.empty() ? 0 : count * half_rows * sizeof(cl_int));
    const cl::Buffer factors = upload(rows_.factors.empty() ? nullptr : &rows_.factors[first * rows],
                                      rows_.factors.empty() ? 0 : count * rows * sizeof(float));
    naive.set("row_units", units);
    naive.set("row_factors", factors);
    naive.set("count_sum", count_sum_);
    naive.set("area_sum", area_sum_);
    st_.launch(naive, cl::NDRange(roundUp(field_.width, kTileX), roundUp(field_.height, kTileY)),
               cl::NDRange(kTileX, kTileY));
  }

  void finish() override {
    download(st_, count_sum_, result_.visible_count);
    download(st_, area_sum_, result_.visible_area);
  }

  const IntervisibilityOptions& visibility_;
  const IntervisibilityOutputs& outputs_;
  std::vector<SweepDirection> rays_;
  double unit_ = 0.0;   // per-row spacing: the ground length of a position unit (groundUnit)
  NaiveRowTables rows_;  // and the row tables
  cl::Buffer count_sum_, area_sum_;
  IntervisibilityResult result_;
};

}  // namespace

}  // namespace detail

IntervisibilityResult computeIntervisibility(const ComputeContext& context, const HeightField& field,
                                             const IntervisibilityOptions& options,
                                             const IntervisibilityOutputs& outputs) {
  validate(field);
  validate(options, outputs);
  detail::checkPixelIndexing(field, 1);
  return detail::translateOpenClErrors([&] {
    detail::ContextState& st = detail::stateOf(context);
    if (options.method == IntervisibilityMethod::HullTree) {
      const auto run = [&](const IntervisibilityOptions& attempt, const IntervisibilityOutputs& wanted) {
        detail::CountRoutine routine(st, field, attempt, wanted);
        routine.run();
        return routine.take();
      };
      if (options.max_error == 0.0) return run(options, outputs);
      // Ask for an error: runs at growing K until the estimate meets it (the horizon sweep's steps).
      IntervisibilityOutputs estimated = outputs;
      estimated.error_estimate = true;
      return detail::runForMaxError<IntervisibilityResult>(options.max_error, [&](int directions) {
        IntervisibilityOptions attempt = options;
        attempt.directions = directions;
        return run(attempt, estimated);
      });
    }
    detail::NaiveCountRoutine routine(st, field, options, outputs);
    routine.run();
    return routine.take();
  });
}

}  // namespace hfvis
