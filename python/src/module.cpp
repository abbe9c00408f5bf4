// python/src/module.cpp: hfvis._core, the C++ library's operations for Python (nanobind).
// The Python layer (python/hfvis/) checks and converts arrays, names keyword arguments and builds
// xarray and Dask results; this module holds one OpenCL context per process and device, releases
// the GIL while the library runs, and turns the library's exceptions into hfvis's Python ones.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "hfvis/hfvis.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace hfvis::python {
namespace {

using Heights = nb::ndarray<const float, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using Planes = nb::ndarray<const float, nb::ndim<3>, nb::c_contig, nb::device::cpu>;
template <typename T>
using ArrayOf = nb::ndarray<nb::numpy, T>;
using Array = ArrayOf<float>;

// A context and the lock that keeps it to one operation at a time (ComputeContext's rule): the
// threads of a process (Dask's threaded scheduler) share it in turn.
struct SharedContext {
  std::mutex running;
  ComputeContext context;
};

// The process that first set OpenCL up (a context, or the device list), or 0. A process forked
// from it inherits none of OpenCL's threads and driver state, and its first call hung for good
// (multiprocessing's default fork start method on Linux, after any hfvis call in the parent; the
// comment here said such a child made its own context): such a child is refused, naming the start
// methods that work. A child forked before the parent touched OpenCL sets it up as its own.
void requireOpenClOfThisProcess() {
  static std::atomic<pid_t> first{0};
  pid_t expected = 0;
  if (first.compare_exchange_strong(expected, getpid()) || expected == getpid()) return;
  throw NoDeviceError(
      "this process was forked from one that had already set OpenCL up (an hfvis call there): OpenCL "
      "cannot run in such a child (its threads and the driver's state are the parent's; a call hung). Start "
      "workers with multiprocessing's 'spawn' or 'forkserver' method (multiprocessing.get_context('spawn')), "
      "use Dask's distributed LocalCluster, or make the processes before the first hfvis call");
}

// One context per device selector, made on first use and kept for the process, so that repeated
// calls pay no start-up (device discovery, kernel builds). The contexts are never destroyed: an
// OpenCL runtime torn down while the interpreter exits can hang or crash.
std::shared_ptr<SharedContext> contextFor(const std::string& device) {
  // (before the lock: a child forked while another thread held it, building a context, would wait
  // on it for good)
  requireOpenClOfThisProcess();
  static std::mutex guard;
  static auto* contexts = new std::map<std::string, std::shared_ptr<SharedContext>>();
  std::lock_guard<std::mutex> lock(guard);
  auto found = contexts->find(device);
  if (found != contexts->end()) return found->second;
  ContextOptions options;
  options.device = device;
  auto shared = std::shared_ptr<SharedContext>(new SharedContext{{}, ComputeContext::create(options)},
                                               [](SharedContext*) {});
  contexts->emplace(device, shared);
  return shared;
}

// The contexts this thread holds: a progress callback that calls hfvis again on the same device
// would wait for good on the lock its own thread holds (a probe's find: the call hung).
thread_local std::vector<const SharedContext*> held_here;

// Runs body(context) on the device's context without the GIL.
template <typename Body>
auto onDevice(const std::string& device, Body&& body) {
  nb::gil_scoped_release released;
  const std::shared_ptr<SharedContext> shared = contextFor(device);
  if (std::find(held_here.begin(), held_here.end(), shared.get()) != held_here.end())
    throw Error(
        "hfvis was called from within the progress callback of a run on the same device, which "
        "waits for the callback: call it after the run returns (or on another device)");
  std::lock_guard<std::mutex> lock(shared->running);
  held_here.push_back(shared.get());
  struct Release {
    ~Release() { held_here.pop_back(); }
  } release;
  return body(shared->context);
}

// The library's progress callback: with the GIL taken back, Ctrl-C (a pending KeyboardInterrupt)
// and the user's callback (None: none); either's exception stops the run, and reaches Python.
// It holds the callback borrowed (the caller's argument keeps it alive for the call): the library
// copies and destroys the std::function without the GIL, where no reference count may change.
std::function<void(int, int)> progressHook(nb::handle callback) {
  PyObject* borrowed = callback.ptr();
  return [borrowed](int done, int total) {
    nb::gil_scoped_acquire acquired;
    if (PyErr_CheckSignals() != 0) throw nb::python_error();
    const nb::handle user(borrowed);
    if (!user.is_none()) user(done, total);
  };
}

// A numpy array that owns `values` (no copy), of the given shape.
template <typename T>
ArrayOf<T> toArray(std::vector<T>&& values, std::vector<size_t> shape) {
  auto* owned = new std::vector<T>(std::move(values));
  nb::capsule owner(owned, [](void* p) noexcept { delete static_cast<std::vector<T>*>(p); });
  return ArrayOf<T>(owned->data(), shape.size(), shape.data(), owner);
}

Array plane(std::vector<float>&& values, const HeightField& field) {
  return toArray(std::move(values), {size_t(field.height), size_t(field.width)});
}

Array planes(std::vector<float>&& values, int count, const HeightField& field) {
  return toArray(std::move(values), {size_t(count), size_t(field.height), size_t(field.width)});
}

HeightField makeField(Heights heights, double cell_size_x, double cell_size_y,
                      std::vector<double> row_cell_size_x, std::vector<double> row_cell_size_y,
                      double z_scale, std::vector<double> origin, std::vector<double> origin_row_cell_size_x,
                      std::vector<double> origin_row_cell_size_y) {
  HeightField field;
  field.height = static_cast<int>(heights.shape(0));
  field.width = static_cast<int>(heights.shape(1));
  field.heights.assign(heights.data(), heights.data() + heights.size());
  field.cell_size_x = cell_size_x;
  field.cell_size_y = cell_size_y;
  field.row_cell_size_x = std::move(row_cell_size_x);
  field.row_cell_size_y = std::move(row_cell_size_y);
  field.z_scale = z_scale;
  // Empty, or where the field lies in a larger one (a Dask chunk with its halo): column, row,
  // the larger field's width and height and its base (heightBase: python/hfvis/_dask.py computes
  // the same), and with per-row spacing its rows' cell sizes (HeightField::origin).
  if (!origin.empty()) {
    if (origin.size() != 5)
      throw InvalidArgument("origin must be (col, row, whole_width, whole_height, base)");
    field.origin = {static_cast<int>(origin[0]),
                    static_cast<int>(origin[1]),
                    static_cast<int>(origin[2]),
                    static_cast<int>(origin[3]),
                    origin[4],
                    std::move(origin_row_cell_size_x),
                    std::move(origin_row_cell_size_y)};
  }
  validate(field);
  return field;
}

// The library's exceptions as hfvis's Python ones (python/hfvis/_errors.py).
void translateErrors(const std::exception_ptr& thrown, void*) {
  const auto raise = [](const char* name, const char* what) {
    nb::object type = nb::module_::import_("hfvis._errors").attr(name);
    PyErr_SetString(type.ptr(), what);
  };
  try {
    std::rethrow_exception(thrown);
  } catch (const InvalidArgument& e) {
    raise("InvalidArgumentError", e.what());
  } catch (const IoError& e) {
    raise("IoError", e.what());
  } catch (const NoDeviceError& e) {
    raise("NoDeviceError", e.what());
  } catch (const MemoryBudgetError& e) {
    raise("MemoryBudgetError", e.what());
  } catch (const OpenClError& e) {
    raise("DeviceError", e.what());
  } catch (const KernelBuildError& e) {
    raise("DeviceError", e.what());
  } catch (const Error& e) {
    raise("Error", e.what());
  }
}

void bindOptions(nb::module_& m) {
  nb::class_<SweepOptions>(m, "SweepOptions")
      .def(nb::init<>())
      .def_rw("directions", &SweepOptions::directions)
      .def_rw("azimuth_offset", &SweepOptions::azimuth_offset)
      .def_rw("samples_per_unit", &SweepOptions::samples_per_unit)
      .def_rw("curvature", &SweepOptions::curvature)
      .def_rw("max_distance", &SweepOptions::max_distance)
      .def_rw("memory_budget_bytes", &SweepOptions::memory_budget_bytes);
  nb::enum_<HorizonMethod>(m, "HorizonMethod")
      .value("sweep", HorizonMethod::Sweep)
      .value("naive", HorizonMethod::Naive);
  nb::class_<HorizonOptions, SweepOptions>(m, "HorizonOptions")
      .def(nb::init<>())
      .def_rw("method", &HorizonOptions::method)
      .def_rw("azimuth_tolerance", &HorizonOptions::azimuth_tolerance)
      .def_rw("strip_rows", &HorizonOptions::strip_rows)
      .def_rw("max_error", &HorizonOptions::max_error);
  nb::enum_<IntervisibilityMethod>(m, "IntervisibilityMethod")
      .value("hull_tree", IntervisibilityMethod::HullTree)
      .value("naive", IntervisibilityMethod::Naive);
  nb::class_<IntervisibilityOptions, SweepOptions>(m, "IntervisibilityOptions")
      .def(nb::init<>())
      .def_rw("method", &IntervisibilityOptions::method)
      .def_rw("strip_rows", &IntervisibilityOptions::strip_rows)
      .def_rw("max_error", &IntervisibilityOptions::max_error);
  nb::class_<ViewshedOptions>(m, "ViewshedOptions")
      .def(nb::init<>())
      .def_rw("absolute", &ViewshedOptions::absolute)
      .def_rw("target_height", &ViewshedOptions::target_height)
      .def_rw("max_distance", &ViewshedOptions::max_distance)
      .def_rw("curvature", &ViewshedOptions::curvature)
      .def_rw("azimuth_from_deg", &ViewshedOptions::azimuth_from_deg)
      .def_rw("azimuth_to_deg", &ViewshedOptions::azimuth_to_deg)
      .def_rw("elevation_min_deg", &ViewshedOptions::elevation_min_deg)
      .def_rw("elevation_max_deg", &ViewshedOptions::elevation_max_deg)
      .def_rw("memory_budget_bytes", &ViewshedOptions::memory_budget_bytes);
  nb::class_<InsolationOptions>(m, "InsolationOptions")
      .def(nb::init<>())
      .def_rw("latitude_deg", &InsolationOptions::latitude_deg)
      .def_rw("longitude_deg", &InsolationOptions::longitude_deg)
      .def_rw("from_utc", &InsolationOptions::from_utc)
      .def_rw("to_utc", &InsolationOptions::to_utc)
      .def_rw("step_minutes", &InsolationOptions::step_minutes)
      .def_rw("size_deg", &InsolationOptions::size_deg)
      .def_rw("azimuth_bucket_deg", &InsolationOptions::azimuth_bucket_deg)
      .def_rw("apparent", &InsolationOptions::apparent);
  nb::class_<BounceOptions, SweepOptions>(m, "BounceOptions").def(nb::init<>());
  nb::enum_<RegionVisibilityMethod>(m, "RegionVisibilityMethod")
      .value("exact", RegionVisibilityMethod::Exact)
      .value("viewsheds", RegionVisibilityMethod::Viewsheds)
      .value("culled", RegionVisibilityMethod::Culled)
      .value("bitmask", RegionVisibilityMethod::Bitmask)
      .value("auto", RegionVisibilityMethod::Auto);
  nb::class_<RegionVisibilityOptions>(m, "RegionVisibilityOptions")
      .def(nb::init<>())
      .def_rw("method", &RegionVisibilityOptions::method)
      .def_rw("target_height", &RegionVisibilityOptions::target_height)
      .def_rw("max_distance", &RegionVisibilityOptions::max_distance)
      .def_rw("curvature", &RegionVisibilityOptions::curvature)
      .def_rw("seed", &RegionVisibilityOptions::seed)
      .def_rw("decorrelate", &RegionVisibilityOptions::decorrelate);
  nb::enum_<PvsMethod>(m, "PvsMethod")
      .value("agvs", PvsMethod::Agvs)
      .value("sgvs", PvsMethod::Sgvs)
      .value("per_cell", PvsMethod::PerCell);
  nb::class_<PvsGrid>(m, "PvsGrid")
      .def(nb::init<>())
      .def_rw("view_cell", &PvsGrid::view_cell)
      .def_rw("band_low", &PvsGrid::band_low)
      .def_rw("band_high", &PvsGrid::band_high)
      .def_rw("tile", &PvsGrid::tile)
      .def_rw("mask", &PvsGrid::mask);
  nb::class_<PvsOptions>(m, "PvsOptions")
      .def(nb::init<>())
      .def_rw("method", &PvsOptions::method)
      .def_rw("samples", &PvsOptions::samples)
      .def_rw("pixel_error", &PvsOptions::pixel_error)
      .def_rw("seconds", &PvsOptions::seconds)
      .def_rw("batch", &PvsOptions::batch)
      .def_rw("seed", &PvsOptions::seed)
      .def_rw("resolution", &PvsOptions::resolution)
      .def_rw("filter", &PvsOptions::filter)
      .def_rw("view_filter", &PvsOptions::view_filter)
      .def_rw("curvature", &PvsOptions::curvature)
      .def_rw("max_distance", &PvsOptions::max_distance)
      .def_rw("estimate_entries", &PvsOptions::estimate_entries)
      .def_rw("witnesses", &PvsOptions::witnesses)
      .def_rw("memory_budget_bytes", &PvsOptions::memory_budget_bytes)
      .def_rw("start", &PvsOptions::start);
}

nb::dict horizons(const HeightField& field, HorizonOptions options, bool angles, bool distances,
                  bool sky_view_factor, bool ambient_occlusion, bool error_estimate,
                  const std::string& device, nb::object progress) {
  HorizonOutputs wanted;
  wanted.horizon_angles = angles;
  wanted.horizon_distances = distances;
  wanted.sky_view_factor = sky_view_factor;
  wanted.ambient_occlusion = ambient_occlusion;
  wanted.error_estimate = error_estimate;
  options.progress = progressHook(progress);
  HorizonResult r =
      onDevice(device, [&](const ComputeContext& c) { return computeHorizons(c, field, options, wanted); });
  nb::dict out;
  out["azimuths"] = r.azimuths;
  if (angles) out["angles"] = planes(std::move(r.angles), r.directions, field);
  if (distances) out["distances"] = planes(std::move(r.distances), r.directions, field);
  if (sky_view_factor) out["sky_view_factor"] = plane(std::move(r.sky_view_factor), field);
  if (ambient_occlusion) out["ambient_occlusion"] = plane(std::move(r.ambient_occlusion), field);
  // The K run (max_error chooses it) and, with an estimate, the estimate and its 99th percentile.
  out["directions"] = r.directions;
  if (!r.error_estimate.empty()) {
    out["error"] = plane(std::move(r.error_estimate), field);
    out["estimated_error"] = r.estimated_error;
  }
  // With max_error (sky-view factor, occlusion): the Richardson divisor the estimate was divided by
  // (one tile: the least is the most) and each run's K, as the CLI's hfvis:richardson_divisor and
  // hfvis:runs.
  if (r.richardson_divisor_most > 0.0) {
    out["richardson_divisor"] = r.richardson_divisor_most;
    out["runs"] = r.runs;
  }
  return out;
}

nb::dict intervisibility(const HeightField& field, IntervisibilityOptions options, bool error_estimate,
                         const std::string& device, nb::object progress) {
  IntervisibilityOutputs wanted;
  wanted.visible_count = true;
  wanted.visible_area = true;
  wanted.error_estimate = error_estimate;
  options.progress = progressHook(progress);
  IntervisibilityResult r = onDevice(
      device, [&](const ComputeContext& c) { return computeIntervisibility(c, field, options, wanted); });
  nb::dict out;
  out["azimuths"] = r.azimuths;
  out["visible_count"] = plane(std::move(r.visible_count), field);
  out["visible_area"] = plane(std::move(r.visible_area), field);
  // The K run (max_error chooses it) and, with an estimate, the estimate and its 99th percentile.
  out["directions"] = r.directions;
  if (!r.error_estimate.empty()) {
    out["error"] = plane(std::move(r.error_estimate), field);
    out["estimated_error"] = r.estimated_error;
  }
  return out;
}

Array viewshed(const HeightField& field, int col, int row, double height, const ViewshedOptions& options,
               const std::string& device) {
  const Observer observer{col, row, height};
  validate(field, observer);
  ViewshedResult r =
      onDevice(device, [&](const ComputeContext& c) { return computeViewshed(c, field, observer, options); });
  return plane(std::move(r.visible), field);
}

Array cumulativeViewshed(const HeightField& field, const std::vector<int>& cols, const std::vector<int>& rows,
                         const std::vector<double>& heights, ViewshedOptions options,
                         const std::string& device, nb::object progress) {
  if (cols.size() != rows.size() || cols.size() != heights.size())
    throw InvalidArgument("the observers' columns, rows and heights differ in number");
  std::vector<Observer> observers;
  for (std::size_t i = 0; i < cols.size(); ++i) {
    observers.push_back({cols[i], rows[i], heights[i]});
    validate(field, observers.back());
  }
  options.progress = progressHook(progress);
  CumulativeViewshed r = onDevice(device, [&](const ComputeContext& c) {
    return computeCumulativeViewshed(c, field, observers, options);
  });
  return plane(std::move(r.count), field);
}

nb::dict sunShading(const HeightField& field, double azimuth_deg, double elevation_deg, double size_deg,
                    SweepOptions options, const std::string& device, nb::object progress) {
  SunLight sun;
  sun.position = {azimuth_deg, elevation_deg};
  sun.size_deg = size_deg;
  options.progress = progressHook(progress);
  SunShadingResult r =
      onDevice(device, [&](const ComputeContext& c) { return computeSunShading(c, field, sun, options); });
  nb::dict out;
  out["azimuth"] = r.azimuth;
  out["sun"] = plane(std::move(r.sun), field);
  out["direct"] = plane(std::move(r.direct), field);
  return out;
}

nb::dict insolation(const HeightField& field, const InsolationOptions& options, SweepOptions sweep,
                    const std::string& device, nb::object progress) {
  sweep.progress = progressHook(progress);
  InsolationResult r =
      onDevice(device, [&](const ComputeContext& c) { return computeInsolation(c, field, options, sweep); });
  nb::dict out;
  out["sun_hours"] = plane(std::move(r.sun_hours), field);
  out["direct"] = plane(std::move(r.direct), field);
  out["steps"] = r.steps;
  out["sweeps"] = r.sweeps;
  return out;
}

EnvironmentMap environmentFromArray(
    nb::ndarray<const float, nb::ndim<3>, nb::c_contig, nb::device::cpu> radiance,
    std::vector<std::string> names, double rotation_deg, int table_rows) {
  EnvironmentMap map;
  map.channels = static_cast<int>(radiance.shape(0));
  map.height = static_cast<int>(radiance.shape(1));
  map.width = static_cast<int>(radiance.shape(2));
  map.radiance.assign(radiance.data(), radiance.data() + radiance.size());
  map.names = std::move(names);
  map.rotation_deg = rotation_deg;
  map.table_rows = table_rows;
  validate(map);
  return map;
}

nb::tuple environmentLight(const HeightField& field, const EnvironmentMap& map, HorizonOptions options,
                           const std::string& device, nb::object progress) {
  options.progress = progressHook(progress);
  EnvironmentLightResult r = onDevice(
      device, [&](const ComputeContext& c) { return computeEnvironmentLight(c, field, map, options); });
  const int channels = static_cast<int>(r.names.size());
  // The K run (max_error chooses it) and, with max_error, the estimate and its 99th percentile.
  nb::object error = nb::none();
  if (!r.error_estimate.empty()) error = nb::cast(plane(std::move(r.error_estimate), field));
  return nb::make_tuple(planes(std::move(r.irradiance), channels, field), r.names, r.directions, error,
                        r.estimated_error);
}

// A region's samples: the rectangle (inclusive corners) sampled `samples` times, or, when
// `points` holds any, these points (column, row, height each).
RegionSampling regionSampling(const std::array<int, 4>& rectangle,
                              const std::vector<std::array<double, 3>>& points, int samples, double height,
                              bool absolute) {
  RegionSampling sampling;
  sampling.rectangle = {rectangle[0], rectangle[1], rectangle[2], rectangle[3]};
  sampling.samples = samples;
  sampling.height = height;
  sampling.absolute = absolute;
  for (const auto& p : points) sampling.points.push_back({p[0], p[1], p[2]});
  if (!points.empty()) sampling.samples = static_cast<int>(points.size());
  return sampling;
}

// Sample positions as an N x 3 array: column, row, absolute (z-scaled) height.
ArrayOf<double> regionPoints(const std::vector<RegionPoint>& points) {
  std::vector<double> values;
  for (const RegionPoint& p : points) values.insert(values.end(), {p.col, p.row, p.height});
  return toArray(std::move(values), {points.size(), 3});
}

// light_image: None, or the light's colours as 3 x rows x columns (R, G, B planes).
nb::dict regionVisibility(const HeightField& field, const RegionSampling& sources,
                          RegionVisibilityOptions options, const std::string& device, nb::object progress,
                          nb::object light_image) {
  options.progress = progressHook(progress);
  if (!light_image.is_none()) {
    const Planes rgb = nb::cast<Planes>(light_image);
    options.light_image.height = static_cast<int>(rgb.shape(1));
    options.light_image.width = static_cast<int>(rgb.shape(2));
    options.light_image.rgb.assign(rgb.data(), rgb.data() + rgb.size());
  }
  validate(options);
  validate(field, sources);
  RegionVisibilityResult r = onDevice(
      device, [&](const ComputeContext& c) { return computeRegionVisibility(c, field, sources, options); });
  nb::dict out;
  out["fraction"] = plane(std::move(r.fraction), field);
  out["bits"] = toArray(std::move(r.bits), {size_t(field.height), size_t(field.width), size_t(r.words)});
  out["samples"] = r.samples;
  out["method"] = regionVisibilityMethodName(r.method);  // the one that ran
  if (options.light_image.width > 0) {
    std::vector<float> rgb = std::move(r.red);
    rgb.insert(rgb.end(), r.green.begin(), r.green.end());
    rgb.insert(rgb.end(), r.blue.begin(), r.blue.end());
    out["rgb"] = planes(std::move(rgb), 3, field);
  }
  return out;
}

nb::dict regionPairVisibility(const HeightField& field, const RegionSampling& sources,
                              const RegionSampling& receivers, RegionVisibilityOptions options,
                              const std::string& device, nb::object progress) {
  options.progress = progressHook(progress);
  validate(options);
  validate(field, sources);
  validate(field, receivers);
  RegionPairVisibilityResult r = onDevice(device, [&](const ComputeContext& c) {
    return computeRegionPairVisibility(c, field, sources, receivers, options);
  });
  nb::dict out;
  out["bits"] = toArray(std::move(r.bits), {size_t(r.receiver_samples), size_t(r.words)});
  out["sources"] = regionPoints(r.sources);
  out["receivers"] = regionPoints(r.receivers);
  out["source_fraction"] = toArray(std::move(r.source_fraction), {size_t(r.source_samples)});
  out["receiver_fraction"] = toArray(std::move(r.receiver_fraction), {size_t(r.receiver_samples)});
  out["clear_pairs"] = r.clear_pairs;
  out["pairs"] = r.pairs;
  return out;
}

// PVS progress: Ctrl-C and the user's callback, called as progress(samples, pixel_error); as
// progressHook.
std::function<void(const PvsResult&)> pvsProgressHook(nb::handle callback) {
  PyObject* borrowed = callback.ptr();
  return [borrowed](const PvsResult& sofar) {
    nb::gil_scoped_acquire acquired;
    if (PyErr_CheckSignals() != 0) throw nb::python_error();
    const nb::handle user(borrowed);
    if (!user.is_none()) user(sofar.samples, sofar.pixel_error);
  };
}

nb::dict pvs(const HeightField& field, const PvsGrid& grid, PvsOptions options, const std::string& device,
             nb::object progress) {
  options.progress = pvsProgressHook(progress);
  validate(options);
  PvsResult r =
      onDevice(device, [&](const ComputeContext& c) { return computePvs(c, field, grid, options); });
  const PvsLayout& l = r.layout;
  nb::dict layout;
  for (const auto& [name, value] : {std::pair<const char*, int>{"view_x", l.view_x},
                                    {"view_y", l.view_y},
                                    {"tiles_x", l.tiles_x},
                                    {"tiles_y", l.tiles_y},
                                    {"cells_x", l.cells_x},
                                    {"cells_y", l.cells_y},
                                    {"view_cell", l.view_cell},
                                    {"tile", l.tile}})
    layout[name] = value;
  nb::dict out;
  out["layout"] = layout;
  out["entries"] = r.entries();
  out["bits"] = toArray(std::move(r.bits), {size_t(l.viewCells()), size_t(r.words)});
  out["computed"] = toArray(std::move(r.computed), {size_t(l.viewCells())});
  out["samples"] = r.samples;
  out["estimate_samples"] = r.estimate_samples;
  out["rays"] = r.rays;
  out["rejected"] = r.rejected;
  out["filtered"] = r.filtered;
  out["discontinuities"] = r.discontinuities;
  out["pixel_error"] = r.pixel_error;
  out["seconds"] = r.seconds;
  std::vector<int> view_cells, tiles;
  std::vector<float> eyes, targets;
  for (const PvsWitness& w : r.witnesses) {
    view_cells.push_back(w.view_cell);
    tiles.push_back(w.tile);
    eyes.insert(eyes.end(), w.eye, w.eye + 3);
    targets.insert(targets.end(), w.target, w.target + 3);
  }
  const size_t witnesses = r.witnesses.size();
  nb::dict witness;
  witness["view_cell"] = toArray(std::move(view_cells), {witnesses});
  witness["tile"] = toArray(std::move(tiles), {witnesses});
  witness["eye"] = toArray(std::move(eyes), {witnesses, 3});
  witness["target"] = toArray(std::move(targets), {witnesses, 3});
  out["witnesses"] = witness;
  nb::list history;
  for (const PvsProgress& p : r.history) {
    nb::dict row;
    row["samples"] = p.samples;
    row["rays"] = p.rays;
    row["entries"] = p.entries;
    row["seconds"] = p.seconds;
    row["pixel_error"] = p.pixel_error;
    row["settling"] = p.settling;
    nb::dict mixture;
    for (int d = 0; d < kPvsDistributions && d < int(p.probability.size()); ++d)
      mixture[pvsDistributionName(d)] = p.probability[d];
    row["mixture"] = mixture;
    history.append(row);
  }
  out["history"] = history;
  return out;
}

// The lists as the CLI's JSON holds them ("receivers"), key for key.
nb::list horizonLists(const HeightField& field, const SweepOptions& options, const std::vector<int>& cols,
                      const std::vector<int>& rows) {
  if (cols.size() != rows.size()) throw InvalidArgument("the receivers' columns and rows differ in number");
  std::vector<ReceiverPixel> receivers;
  for (std::size_t i = 0; i < cols.size(); ++i) receivers.push_back({cols[i], rows[i]});
  validateReceivers(field, receivers);
  std::vector<ReceiverHorizons> lists = [&] {
    nb::gil_scoped_release released;
    return computeHorizonLists(field, options, receivers);
  }();
  nb::list out;
  for (const ReceiverHorizons& receiver : lists) {
    nb::list directions;
    for (const DirectionHorizons& d : receiver.directions) {
      nb::list horizons;
      for (const VisibilityHorizon& z : d.horizons) {
        nb::dict h;
        h["sample"] = z.sample;
        h["distance"] = z.distance;
        h["elevation_rad"] = z.elevation;
        h["segment_begin"] = z.segment_begin;
        h["segment_end"] = z.segment_end;
        h["near_distance"] = z.near_distance;
        h["visible_samples"] = z.visible_samples;
        horizons.append(h);
      }
      nb::dict direction;
      direction["k"] = d.direction;
      direction["azimuth_rad"] = d.azimuth;
      direction["sample_spacing"] = d.sample_spacing;
      direction["ray_samples"] = d.ray_samples;
      direction["visible_samples"] = d.visible_samples;
      direction["horizons"] = horizons;
      directions.append(direction);
    }
    nb::dict r;
    r["col"] = receiver.pixel.col;
    r["row"] = receiver.pixel.row;
    r["height"] = receiver.height;
    r["nodata"] = receiver.nodata;
    r["directions"] = directions;
    out.append(r);
  }
  return out;
}

nb::dict bounce(const HeightField& field, Planes radiance, BounceOptions options, const std::string& device,
                nb::object progress) {
  ExitRadiance exit;
  exit.width = static_cast<int>(radiance.shape(2));
  exit.height = static_cast<int>(radiance.shape(1));
  const std::size_t plane_size = radiance.shape(1) * radiance.shape(2);
  for (std::size_t c = 0; c < radiance.shape(0); ++c)
    exit.channels.emplace_back(radiance.data() + c * plane_size, radiance.data() + (c + 1) * plane_size);
  validate(options);
  validate(field, exit);
  options.progress = progressHook(progress);
  BounceResult r =
      onDevice(device, [&](const ComputeContext& c) { return computeBounce(c, field, exit, options); });
  std::vector<float> stacked;
  for (auto& p : r.irradiance) stacked.insert(stacked.end(), p.begin(), p.end());
  nb::dict out;
  out["azimuths"] = r.azimuths;
  out["irradiance"] = planes(std::move(stacked), static_cast<int>(r.irradiance.size()), field);
  return out;
}

nb::list devices() {
  requireOpenClOfThisProcess();
  nb::list out;
  for (const DeviceInfo& d : listDevices()) {
    nb::dict info;
    info["index"] = d.index;
    info["platform"] = d.platform;
    info["name"] = d.name;
    info["type"] = d.type;
    info["driver_version"] = d.driver_version;
    info["opencl_version"] = d.opencl_version;
    info["global_memory_bytes"] = d.global_memory_bytes;
    info["max_allocation_bytes"] = d.max_allocation_bytes;
    info["compute_units"] = d.compute_units;
    out.append(info);
  }
  return out;
}

}  // namespace
}  // namespace hfvis::python

NB_MODULE(_core, m) {
  using namespace hfvis;
  using namespace hfvis::python;
  m.doc() = "hfvis's C++ library; call it through the hfvis package's functions";
  nb::register_exception_translator(translateErrors);
  bindOptions(m);

  // Made by height_field() and passed back to the operations; Python reads nothing of them.
  nb::class_<HeightField>(m, "HeightField");
  m.def("height_field", &makeField, "heights"_a, "cell_size_x"_a, "cell_size_y"_a, "row_cell_size_x"_a,
        "row_cell_size_y"_a, "z_scale"_a, "origin"_a = std::vector<double>{},
        "origin_row_cell_size_x"_a = std::vector<double>{},
        "origin_row_cell_size_y"_a = std::vector<double>{});
  m.attr("least_cell_size") = kLeastCellSize;
  m.attr("most_cell_size") = kMostCellSize;
  m.def("require_heights_kept_in_float32", &requireHeightsKeptInFloat32, "rounding"_a, "lowest"_a,
        "highest"_a, "cell_size"_a);
  m.def(
      "geographic_cell_sizes",
      [](const std::array<double, 6>& geotransform, int height) {
        HeightField field;
        field.height = height;
        setGeographicCellSizes(field, geotransform);
        return nb::make_tuple(field.cell_size_x, field.cell_size_y, field.row_cell_size_x,
                              field.row_cell_size_y);
      },
      "geotransform"_a, "height"_a);

  m.def(
      "read_height_field",
      [](const std::string& path, const std::string& channel) {
        HeightFieldReadOptions options;
        options.channel = channel;
        HeightField field = [&] {
          nb::gil_scoped_release released;
          return readHeightField(path, options);
        }();
        nb::object transform = nb::none();
        if (field.georeference.geotransform) transform = nb::cast(*field.georeference.geotransform);
        return nb::make_tuple(plane(std::move(field.heights), field), field.cell_size_x, field.cell_size_y,
                              field.row_cell_size_x, field.row_cell_size_y, transform,
                              field.georeference.crs_wkt);
      },
      "path"_a, "channel"_a);

  nb::class_<EnvironmentMap>(m, "EnvironmentMap");
  m.def("environment_map", &environmentFromArray, "radiance"_a, "names"_a, "rotation_deg"_a, "table_rows"_a);
  m.def(
      "read_environment_map",
      [](const std::string& path, double rotation_deg, int table_rows) {
        EnvironmentMap map = readEnvironmentMap(path);
        map.rotation_deg = rotation_deg;
        map.table_rows = table_rows;
        validate(map);
        return map;
      },
      "path"_a, "rotation_deg"_a, "table_rows"_a);

  m.def("horizons", &horizons, "field"_a, "options"_a, "angles"_a, "distances"_a, "sky_view_factor"_a,
        "ambient_occlusion"_a, "error_estimate"_a, "device"_a, "progress"_a.none());
  m.def("intervisibility", &intervisibility, "field"_a, "options"_a, "error_estimate"_a, "device"_a,
        "progress"_a.none());
  m.def("viewshed", &viewshed, "field"_a, "col"_a, "row"_a, "height"_a, "options"_a, "device"_a);
  m.def("cumulative_viewshed", &cumulativeViewshed, "field"_a, "cols"_a, "rows"_a, "heights"_a, "options"_a,
        "device"_a, "progress"_a.none());
  m.def("sun_shading", &sunShading, "field"_a, "azimuth_deg"_a, "elevation_deg"_a, "size_deg"_a, "options"_a,
        "device"_a, "progress"_a.none());
  m.def("insolation", &insolation, "field"_a, "options"_a, "sweep"_a, "device"_a, "progress"_a.none());
  m.def("environment_light", &environmentLight, "field"_a, "map"_a, "options"_a, "device"_a,
        "progress"_a.none());
  nb::class_<RegionSampling>(m, "RegionSampling");
  m.def("region_sampling", &regionSampling, "rectangle"_a, "points"_a, "samples"_a, "height"_a, "absolute"_a);
  m.def("region_visibility", &regionVisibility, "field"_a, "sources"_a, "options"_a, "device"_a,
        "progress"_a.none(), "light_image"_a.none() = nb::none());
  m.def("region_pair_visibility", &regionPairVisibility, "field"_a, "sources"_a, "receivers"_a, "options"_a,
        "device"_a, "progress"_a.none());
  m.def("pvs", &pvs, "field"_a, "grid"_a, "options"_a, "device"_a, "progress"_a.none());
  m.def("horizon_lists", &horizonLists, "field"_a, "options"_a, "cols"_a, "rows"_a);
  m.def("bounce", &bounce, "field"_a, "radiance"_a, "options"_a, "device"_a, "progress"_a.none());
  m.def(
      "sun_position",
      [](double utc, double latitude_deg, double longitude_deg, bool apparent) {
        const SunPosition p = sunPosition(utc, latitude_deg, longitude_deg, apparent);
        return nb::make_tuple(p.azimuth_deg, p.elevation_deg);
      },
      "utc"_a, "latitude_deg"_a, "longitude_deg"_a, "apparent"_a);
  m.def("parse_utc_time", &parseUtcTime, "text"_a);
  m.def("devices", &devices);
  m.attr("__version__") = versionString();
}
