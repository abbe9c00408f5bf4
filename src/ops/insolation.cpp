// insolation.cpp: sunshine hours and direct irradiation over a span of time (see
// hfvis/insolation.hpp): the sun's positions step by step, grouped into buckets of azimuth; per
// bucket one horizon sweep, and insolation_add (kernels/insolation.cl) adds its steps to every
// pixel's sums on the device.
#include "hfvis/insolation.hpp"

#include <cmath>
#include <limits>
#include <map>
#include <string>

#include "core/number_text.hpp"
#include "core/opencl_context.hpp"
#include "core/sweep_framework.hpp"
#include "core/sweep_routine.hpp"
#include "core/unit_normals.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/horizon.hpp"
#include "hfvis/sun.hpp"
#include "ops/insolation_steps.hpp"

namespace hfvis {
namespace {

constexpr double kDegree = M_PI / 180.0;

}  // namespace

void validate(const InsolationOptions& o) {
  if (!(std::isfinite(o.from_utc) && std::isfinite(o.to_utc) && o.from_utc < o.to_utc))
    throw InvalidArgument("the span of time must run forward, `from` before `to`, both finite (got " +
                          detail::exactNumber(o.from_utc) + " to " + detail::exactNumber(o.to_utc) +
                          " seconds since 1970, UTC)");
  if (!(o.step_minutes > 0.0 && o.step_minutes <= 1440.0))
    throw InvalidArgument("the step must be in (0, 1440] minutes (got " + std::to_string(o.step_minutes) + ")");
  if (!(o.size_deg >= 0.0 && o.size_deg <= 10.0))
    throw InvalidArgument("the sun's size must be in [0, 10] degrees (got " + std::to_string(o.size_deg) +
                          ")");
  // (a bucket's index is the azimuth over it, a long: 1e-30 degrees put every step in one bucket)
  if (!(o.azimuth_bucket_deg >= kLeastAzimuthBucketDeg && o.azimuth_bucket_deg <= 10.0))
    throw InvalidArgument("the azimuth bucket must be in [" + detail::shortNumber(kLeastAzimuthBucketDeg) +
                          ", 10] degrees (got " + detail::shortNumber(o.azimuth_bucket_deg) + ")");
  const double steps = std::ceil((o.to_utc - o.from_utc) / (60.0 * o.step_minutes));
  if (steps > 1e7) throw InvalidArgument("the span holds more than 10 million steps; take a longer step");
  // The ends of the span: sunPosition refuses a place or year beyond its range. The span is
  // [from, to) and the sun is taken at each step's middle: a span that ends as 2201 begins runs
  // (it was refused for its excluded end).
  sunPosition(o.from_utc, o.latitude_deg, o.longitude_deg);
  sunPosition(std::nextafter(o.to_utc, o.from_utc), o.latitude_deg, o.longitude_deg);
}

namespace detail {

double sunDiscRadius(const InsolationOptions& options) { return std::max(0.5 * options.size_deg * kDegree, 1e-12); }

std::map<long, std::vector<SunStep>> sunStepsByBucket(const InsolationOptions& options) {
  const double radius = sunDiscRadius(options);
  std::map<long, std::vector<SunStep>> buckets;
  const double step = 60.0 * options.step_minutes;
  for (double t0 = options.from_utc; t0 < options.to_utc; t0 += step) {
    const double t1 = std::min(options.to_utc, t0 + step);
    const SunPosition p = sunPosition(0.5 * (t0 + t1), options.latitude_deg, options.longitude_deg, options.apparent);
    if (p.elevation_deg * kDegree <= -radius) continue;
    const glm::dvec3 s = sunDirection(p);
    const long bucket = std::lround(p.azimuth_deg / options.azimuth_bucket_deg);
    buckets[bucket].push_back({static_cast<float>(s.x), static_cast<float>(s.y), static_cast<float>(s.z),
                               static_cast<float>(p.elevation_deg * kDegree), static_cast<float>((t1 - t0) / 3600.0)});
  }
  return buckets;
}

HorizonOptions bucketSweep(long bucket, const InsolationOptions& options, const SweepOptions& sweep) {
  HorizonOptions horizon;
  static_cast<SweepOptions&>(horizon) = sweep;
  horizon.progress = nullptr;
  horizon.directions = 1;
  horizon.azimuth_offset = std::remainder((bucket * options.azimuth_bucket_deg - 90.0) * kDegree, 2.0 * M_PI);
  // A step within half a bucket of its centre: every step of the bucket within a bucket of it.
  horizon.azimuth_tolerance = std::min(0.1, 0.5 * options.azimuth_bucket_deg * kDegree);
  return horizon;
}

}  // namespace detail

namespace {

using detail::SunStep;

// One routine item per azimuth bucket: the horizon sweep in its azimuth, then insolation_add adds
// its steps to every pixel's sums on the device.
class InsolationRoutine : public detail::DeviceRoutine {
 public:
  InsolationRoutine(detail::ContextState& st, const ComputeContext& context, const HeightField& field,
                    const InsolationOptions& options, const SweepOptions& sweep,
                    std::vector<std::pair<long, std::vector<SunStep>>> buckets, double radius,
                    InsolationResult& out)
      : DeviceRoutine(st, field, sweep.progress, sweep.memory_budget_bytes),
        context_(context),
        options_(options),
        sweep_(sweep),
        buckets_(std::move(buckets)),
        radius_(radius),
        out_(out) {}

 private:
  // The kernel reads the horizons and normals, not the heights (the sweeps prepare their own).
  detail::PreparedHeights prepare() override { return {}; }
  bool heightsResident() const override { return false; }
  std::string programFile() const override { return "insolation.cl"; }

  void allocate() override {
    const std::size_t pixels = field_.pixelCount();
    normals_ = detail::unitNormals(field_);  // x, y, z, 0 per pixel
    normal_buffer_ = upload(normals_);
    sun_hours_ = zeros(pixels);
    direct_ = zeros(pixels);
    horizon_ = detail::deviceBuffer(st_, pixels * sizeof(float));
  }

  int itemCount() const override { return static_cast<int>(buckets_.size()); }

  void runItem(int item, int) override {
    const auto& [bucket, steps] = buckets_[item];
    HorizonOutputs outputs;
    outputs.horizon_angles = true;
    // Kept until the base's queue.finish() after the item, as the buffers below: the write reads it.
    angles_ = computeHorizons(context_, field_, detail::bucketSweep(bucket, options_, sweep_), outputs).angles;
    const std::size_t pixels = field_.pixelCount();
    st_.queue.enqueueWriteBuffer(horizon_, CL_FALSE, 0, pixels * sizeof(float), angles_.data());
    std::vector<cl_float4> suns;
    std::vector<float> hours;
    for (const SunStep& s : steps) suns.push_back(cl_float4{{s.x, s.y, s.z, s.elevation}}), hours.push_back(s.hours);
    sun_buffer_ = upload(suns);
    hour_buffer_ = upload(hours);
    detail::NamedKernel add = kernel("insolation_add");
    add.set("horizon", horizon_);
    add.set("normals", normal_buffer_);
    add.set("pixels", static_cast<cl_uint>(pixels));
    add.set("steps", sun_buffer_);
    add.set("hours", hour_buffer_);
    add.set("n_steps", static_cast<int>(suns.size()));
    add.set("radius", static_cast<float>(radius_));
    add.set("sun_hours", sun_hours_);
    add.set("direct", direct_);
    st_.launch(add, cl::NDRange(detail::roundUp(pixels, detail::kLineGroup)),
               cl::NDRange(detail::kLineGroup));
    ++out_.sweeps;
  }

  void finish() override {
    const std::size_t pixels = field_.pixelCount();
    out_.sun_hours.resize(pixels);
    out_.direct.resize(pixels);
    st_.queue.enqueueReadBuffer(sun_hours_, CL_TRUE, 0, pixels * sizeof(float), out_.sun_hours.data());
    st_.queue.enqueueReadBuffer(direct_, CL_TRUE, 0, pixels * sizeof(float), out_.direct.data());
    // No step with the sun up: nodata is still nodata.
    if (buckets_.empty())
      for (std::size_t p = 0; p < pixels; ++p)
        if (std::isnan(normals_[4 * p]))
          out_.sun_hours[p] = out_.direct[p] = std::numeric_limits<float>::quiet_NaN();
  }

  const ComputeContext& context_;
  const InsolationOptions& options_;
  const SweepOptions& sweep_;
  std::vector<std::pair<long, std::vector<SunStep>>> buckets_;  // by azimuth bucket
  double radius_;
  InsolationResult& out_;
  std::vector<float> normals_, angles_;
  cl::Buffer normal_buffer_, sun_hours_, direct_, horizon_, sun_buffer_, hour_buffer_;
};

}  // namespace

InsolationResult computeInsolation(const ComputeContext& context, const HeightField& field,
                                   const InsolationOptions& options, const SweepOptions& sweep) {
  validate(field);
  validate(options);
  validate(sweep);
  const double radius = detail::sunDiscRadius(options);
  const std::map<long, std::vector<SunStep>> buckets = detail::sunStepsByBucket(options);
  InsolationResult out;
  for (const auto& bucket : buckets) out.steps += static_cast<int>(bucket.second.size());
  out.width = field.width;
  out.height = field.height;
  return detail::translateOpenClErrors([&] {
    InsolationRoutine routine(detail::stateOf(context), context, field, options, sweep,
                              {buckets.begin(), buckets.end()}, radius, out);
    routine.run();
    return out;
  });
}

}  // namespace hfvis
