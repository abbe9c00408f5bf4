// bench/methods.cpp: runs the library's methods and the baselines of
// bench/kernels/horizon_baselines.cl (host side: pyramid build, batching, downloads).
#include "methods.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "hfvis/errors.hpp"
#include "hfvis/horizon.hpp"
#include "metrics.hpp"
#include "core/opencl_context.hpp"
#include "core/sweep_framework.hpp"
#include "core/sweep_geometry.hpp"

namespace hfvis::bench {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Directions per launch, as the library batches them: bounds one launch's output planes.
constexpr int kBatch = 32;

std::vector<detail::SweepDirection> directionsOf(const HeightField& field, int directions,
                                                 double samples_per_unit) {
  std::vector<detail::SweepDirection> all;
  for (int k = 0; k < directions; ++k)
    all.push_back(detail::makeSweepDirection(field, 2.0 * kPi * k / directions, samples_per_unit));
  return all;
}

std::string programOptions(const MethodSpec& spec) {
  std::ostringstream s;
  s << "-DHFVIS_HAS_NODATA=0";
  if (spec.kind == MethodKind::Radius)
    s << " -DHFVIS_RADIUS_STEPS=" << std::max(1L, std::lround(spec.parameter * spec.samples_per_unit));
  if (spec.kind == MethodKind::Pyramid) s << " -DHFVIS_PYRAMID_NEAR=" << spec.parameter;
  return s.str();
}

// Levels 1.. of the max pyramid in one buffer; `levels` gets (offset, width, height, 0) per
// level, level 0 being the heights themselves.
cl::Buffer buildPyramid(detail::ContextState& st, cl::Program& program, const cl::Buffer& heights, int width,
                        int height, std::vector<cl_int4>& levels) {
  levels.push_back({{0, width, height, 0}});
  std::size_t total = 0;
  for (int l = 1; l < 16; ++l) {
    const int w = std::max(1, (width - 1 + (1 << l) - 1) >> l),
              h = std::max(1, (height - 1 + (1 << l) - 1) >> l);
    levels.push_back({{static_cast<cl_int>(total), w, h, 0}});
    total += static_cast<std::size_t>(w) * h;
    if (w == 1 && h == 1) break;
  }
  cl::Buffer pyramid = detail::deviceBuffer(st, total * sizeof(float));
  detail::NamedKernel level(st, program, "pyramid_level");
  for (std::size_t l = 1; l < levels.size(); ++l) {
    const cl_int4 src = levels[l - 1], dst = levels[l];
    level.set("src", l == 1 ? heights : pyramid);
    level.set("src_offset", static_cast<cl_uint>(l == 1 ? 0 : src.s[0]));
    level.set("src_w", src.s[1]);
    level.set("src_h", src.s[2]);
    level.set("dst", pyramid);
    level.set("dst_offset", static_cast<cl_uint>(dst.s[0]));
    level.set("dst_w", dst.s[1]);
    level.set("dst_h", dst.s[2]);
    level.set("span", l == 1 ? 2 : 1);
    // A fixed local size: PoCL compiles a kernel once per local size it is launched with.
    st.launch(level, cl::NDRange(detail::roundUp(dst.s[1], 8), detail::roundUp(dst.s[2], 8)),
              cl::NDRange(8, 8));
  }
  return pyramid;
}

MethodOutput runBaseline(const ComputeContext& context, const HeightField& field, const MethodSpec& spec) {
  if (field.width < 2 || field.height < 2)
    throw InvalidArgument("the baselines need a field of at least 2 x 2");
  if (field.nodataCount() > 0) throw InvalidArgument("the baselines do not handle nodata heights");
  return detail::translateOpenClErrors([&] {
    detail::ContextState& st = detail::stateOf(context);
    cl::Program program = st.programFromSource("horizon_baselines.cl", detail::benchKernelSources().at("horizon_baselines.cl"), "",
                                                 programOptions(spec));
    const std::vector<float> prepared = detail::prepareHeights(field).heights;
    const std::size_t plane = field.pixelCount();
    cl::Buffer heights(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, plane * sizeof(float),
                       const_cast<float*>(prepared.data()));
    std::vector<cl_int4> levels;
    cl::Buffer pyramid, level_table;
    if (spec.kind == MethodKind::Pyramid) {
      pyramid = buildPyramid(st, program, heights, field.width, field.height, levels);
      level_table = cl::Buffer(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                               levels.size() * sizeof(cl_int4), levels.data());
    }
    const auto all = directionsOf(field, spec.directions, spec.samples_per_unit);
    cl::Buffer planes = detail::deviceBuffer(st, std::min(spec.directions, kBatch) * plane * sizeof(float));
    MethodOutput out;
    if (spec.angles) out.angles.resize(spec.directions * plane);
    const char* name = spec.kind == MethodKind::Pyramid ? "pyramid_march"
                       : spec.kind == MethodKind::Floor ? "bandwidth_floor"
                                                        : "radius_march";
    detail::NamedKernel kernel(st, program, name);
    // The marches run in the library's pixel tiles (their trip count is the tile's longest
    // ray); the floor has one work-item per 16 pixels of a row.
    const bool floor = spec.kind == MethodKind::Floor;
    const cl::NDRange local = floor ? cl::NDRange(16, 4) : cl::NDRange(baselineTileX(), baselineTileY());
    const cl::NDRange global =
        floor ? cl::NDRange(detail::roundUp((field.width + 15) / 16, 16), detail::roundUp(field.height, 4))
              : cl::NDRange(detail::roundUp(field.width, baselineTileX()),
                            detail::roundUp(field.height, baselineTileY()));
    for (int first = 0; first < spec.directions; first += kBatch) {
      const int count = std::min(kBatch, spec.directions - first);
      if (spec.kind == MethodKind::Floor) {
        cl::Buffer directions(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                              count * sizeof(detail::SweepDirection),
                              const_cast<detail::SweepDirection*>(&all[first]));
        kernel.set("heights", heights);
        kernel.set("width", field.width);
        kernel.set("height", field.height);
        kernel.set("directions", directions);
        kernel.set("batch_size", count);
        kernel.set("angles", planes);
        st.launch(kernel, global, local);
      } else {
        // One launch per direction, the geometry as arguments (see radius_march).
        for (int b = 0; b < count; ++b) {
          const detail::SweepDirection& d = all[first + b];
          kernel.set("heights", heights);
          kernel.set("width", field.width);
          kernel.set("height", field.height);
          if (spec.kind == MethodKind::Pyramid) {
            kernel.set("pyramid", pyramid);
            kernel.set("levels", level_table);
            kernel.set("level_count", static_cast<int>(levels.size()));
          }
          kernel.set("dir_x", d.dir_x);
          kernel.set("dir_y", d.dir_y);
          kernel.set("step_length", d.step_length);
          kernel.set("samples_per_unit", d.samples_per_unit);
          kernel.set("ground_per_pixel", d.ground_per_pixel);
          kernel.set("angles", planes);
          kernel.set("plane_offset", static_cast<cl_uint>(b * plane));
          st.launch(kernel, global, local);
        }
      }
      if (spec.angles)
        st.queue.enqueueReadBuffer(planes, CL_TRUE, 0, count * plane * sizeof(float),
                                   &out.angles[first * plane]);
    }
    st.queue.finish();
    return out;
  });
}

}  // namespace

std::string MethodSpec::name() const {
  switch (kind) {
    case MethodKind::Sweep:
      return "sweep";
    case MethodKind::Naive:
      return "naive";
    case MethodKind::Radius:
      return "radius_" + std::to_string(parameter);
    case MethodKind::Pyramid:
      return "pyramid_" + std::to_string(parameter);
    case MethodKind::Floor:
      return "floor";
  }
  return "?";
}

std::string MethodSpec::outputs() const {
  if (angles) return "angles";
  if (kind != MethodKind::Sweep && kind != MethodKind::Naive) return "device";
  return ambient_occlusion ? "ao" : "svf";
}

MethodOutput runMethod(const ComputeContext& context, const HeightField& field, const MethodSpec& spec) {
  if (spec.kind != MethodKind::Sweep && spec.kind != MethodKind::Naive)
    return runBaseline(context, field, spec);
  HorizonOptions options;
  options.directions = spec.directions;
  options.samples_per_unit = spec.samples_per_unit;
  options.max_distance = spec.max_distance;
  options.method = spec.kind == MethodKind::Sweep ? HorizonMethod::Sweep : HorizonMethod::Naive;
  HorizonOutputs outputs;
  outputs.horizon_angles = spec.angles;
  outputs.sky_view_factor = !spec.angles && !spec.ambient_occlusion;
  outputs.ambient_occlusion = !spec.angles && spec.ambient_occlusion;
  HorizonResult result = computeHorizons(context, field, options, outputs);
  MethodOutput out;
  out.angles = std::move(result.angles);
  out.svf = std::move(outputs.ambient_occlusion ? result.ambient_occlusion : result.sky_view_factor);
  out.azimuths = std::move(result.azimuths);
  return out;
}

ShadingOutput runShading(const ComputeContext& context, const HeightField& field, MethodKind kind,
                         int directions) {
  HorizonOptions options;
  options.directions = directions;
  options.method = kind == MethodKind::Naive ? HorizonMethod::Naive : HorizonMethod::Sweep;
  HorizonOutputs outputs;
  outputs.sky_view_factor = outputs.ambient_occlusion = true;
  HorizonResult result = computeHorizons(context, field, options, outputs);
  return {std::move(result.sky_view_factor), std::move(result.ambient_occlusion)};
}

MarchSteps naiveMarchSteps(const HeightField& field, int directions, double samples_per_unit, int tile_x,
                           int tile_y, int max_steps) {
  MarchSteps steps;
  const int w = field.width, h = field.height;
  // The exit distance of pixel (c, r) is min(column term, row term), as in horizon_naive
  // (kernels/horizon.cl) and bl_tile_reach (bench/kernels/horizon_baselines.cl).
  auto reach = [&](double dir, int coordinate, int size) {
    return dir > 0.0 ? (size - 1 - coordinate) / dir : dir < 0.0 ? coordinate / -dir : double(w + h);
  };
  for (const auto& d : directionsOf(field, directions, samples_per_unit)) {
    for (int r0 = 0; r0 < h; r0 += tile_y) {
      for (int c0 = 0; c0 < w; c0 += tile_x) {
        const int c1 = std::min(c0 + tile_x, w) - 1, r1 = std::min(r0 + tile_y, h) - 1;
        // The tile's longest ray starts at the corner farthest from the exit edges.
        const double tile = std::min(std::max(reach(d.dir_x, c0, w), reach(d.dir_x, c1, w)),
                                     std::max(reach(d.dir_y, r0, h), reach(d.dir_y, r1, h)));
        double run = std::floor(std::min(tile, double(w + h)) * samples_per_unit) + 1.0;
        if (max_steps > 0) run = std::min<double>(run, max_steps);
        steps.executed += run * tile_x * tile_y;
        for (int r = r0; r <= r1; ++r) {
          for (int c = c0; c <= c1; ++c) {
            double inside =
                std::floor(std::min(reach(d.dir_x, c, w), reach(d.dir_y, r, h)) * samples_per_unit + 1e-6);
            if (max_steps > 0) inside = std::min<double>(inside, max_steps);
            steps.inside += inside;
          }
        }
      }
    }
  }
  return steps;
}

int baselineTileX() { return static_cast<int>(detail::kTileX); }
int baselineTileY() { return static_cast<int>(detail::kTileY); }

}  // namespace hfvis::bench
