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

#include <map>
#include <memory>
#include <mutex>
#include <utility>

#include "hfvis/hfvis.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace hfvis::python {
namespace {

using Heights = nb::ndarray<const float, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using Array = nb::ndarray<nb::numpy, float>;

// A context and the lock that keeps it to one operation at a time (ComputeContext's rule): the
// threads of a process (Dask's threaded scheduler) share it in turn.
struct SharedContext {
  std::mutex running;
  ComputeContext context;
};

// One context per device selector, made on first use and kept for the process, so that repeated
// calls pay no start-up (device discovery, kernel builds). The contexts are never destroyed: an
// OpenCL runtime torn down while the interpreter exits can hang or crash. A process forked from
// one that held contexts (multiprocessing, Dask's forked workers) makes its own: the parent's
// OpenCL state is not usable in the child.
std::shared_ptr<SharedContext> contextFor(const std::string& device) {
  static std::mutex guard;
  static pid_t owner = getpid();
  static auto* contexts = new std::map<std::string, std::shared_ptr<SharedContext>>();
  std::lock_guard<std::mutex> lock(guard);
  if (getpid() != owner) {
    contexts = new std::map<std::string, std::shared_ptr<SharedContext>>();  // the parent's, left alone
    owner = getpid();
  }
  auto found = contexts->find(device);
  if (found != contexts->end()) return found->second;
  ContextOptions options;
  options.device = device;
  auto shared = std::shared_ptr<SharedContext>(new SharedContext{{}, ComputeContext::create(options)},
                                               [](SharedContext*) {});
  contexts->emplace(device, shared);
  return shared;
}

// Runs body(context) on the device's context without the GIL.
template <typename Body>
auto onDevice(const std::string& device, Body&& body) {
  nb::gil_scoped_release released;
  const std::shared_ptr<SharedContext> shared = contextFor(device);
  std::lock_guard<std::mutex> lock(shared->running);
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
Array toArray(std::vector<float>&& values, std::vector<size_t> shape) {
  auto* owned = new std::vector<float>(std::move(values));
  nb::capsule owner(owned, [](void* p) noexcept { delete static_cast<std::vector<float>*>(p); });
  return Array(owned->data(), shape.size(), shape.data(), owner);
}

Array plane(std::vector<float>&& values, const HeightField& field) {
  return toArray(std::move(values), {size_t(field.height), size_t(field.width)});
}

Array planes(std::vector<float>&& values, int count, const HeightField& field) {
  return toArray(std::move(values), {size_t(count), size_t(field.height), size_t(field.width)});
}

HeightField makeField(Heights heights, double cell_size_x, double cell_size_y,
                      std::vector<double> row_cell_size_x, std::vector<double> row_cell_size_y,
                      double z_scale, std::vector<double> origin) {
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
  // the larger field's width and height and its lowest height (HeightField::origin).
  if (!origin.empty()) {
    if (origin.size() != 5) throw InvalidArgument("origin must be (col, row, whole_width, whole_height, lowest)");
    field.origin = {static_cast<int>(origin[0]), static_cast<int>(origin[1]), static_cast<int>(origin[2]),
                    static_cast<int>(origin[3]), origin[4]};
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
      .def_rw("strip_rows", &HorizonOptions::strip_rows);
  nb::enum_<IntervisibilityMethod>(m, "IntervisibilityMethod")
      .value("hull_tree", IntervisibilityMethod::HullTree)
      .value("naive", IntervisibilityMethod::Naive);
  nb::class_<IntervisibilityOptions, SweepOptions>(m, "IntervisibilityOptions")
      .def(nb::init<>())
      .def_rw("method", &IntervisibilityOptions::method)
      .def_rw("strip_rows", &IntervisibilityOptions::strip_rows);
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
}

nb::dict horizons(const HeightField& field, HorizonOptions options, bool angles, bool distances,
                  bool sky_view_factor, bool ambient_occlusion, const std::string& device,
                  nb::object progress) {
  HorizonOutputs wanted;
  wanted.horizon_angles = angles;
  wanted.horizon_distances = distances;
  wanted.sky_view_factor = sky_view_factor;
  wanted.ambient_occlusion = ambient_occlusion;
  options.progress = progressHook(progress);
  HorizonResult r =
      onDevice(device, [&](const ComputeContext& c) { return computeHorizons(c, field, options, wanted); });
  nb::dict out;
  out["azimuths"] = r.azimuths;
  if (angles) out["angles"] = planes(std::move(r.angles), r.directions, field);
  if (distances) out["distances"] = planes(std::move(r.distances), r.directions, field);
  if (sky_view_factor) out["sky_view_factor"] = plane(std::move(r.sky_view_factor), field);
  if (ambient_occlusion) out["ambient_occlusion"] = plane(std::move(r.ambient_occlusion), field);
  return out;
}

nb::dict intervisibility(const HeightField& field, IntervisibilityOptions options, const std::string& device,
                         nb::object progress) {
  IntervisibilityOutputs wanted;
  wanted.visible_count = true;
  wanted.visible_area = true;
  options.progress = progressHook(progress);
  IntervisibilityResult r = onDevice(
      device, [&](const ComputeContext& c) { return computeIntervisibility(c, field, options, wanted); });
  nb::dict out;
  out["azimuths"] = r.azimuths;
  out["visible_count"] = plane(std::move(r.visible_count), field);
  out["visible_area"] = plane(std::move(r.visible_area), field);
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
  return nb::make_tuple(planes(std::move(r.irradiance), channels, field), r.names);
}

nb::list devices() {
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
        "row_cell_size_y"_a, "z_scale"_a, "origin"_a = std::vector<double>{});
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
        "ambient_occlusion"_a, "device"_a, "progress"_a.none());
  m.def("intervisibility", &intervisibility, "field"_a, "options"_a, "device"_a, "progress"_a.none());
  m.def("viewshed", &viewshed, "field"_a, "col"_a, "row"_a, "height"_a, "options"_a, "device"_a);
  m.def("cumulative_viewshed", &cumulativeViewshed, "field"_a, "cols"_a, "rows"_a, "heights"_a, "options"_a,
        "device"_a, "progress"_a.none());
  m.def("sun_shading", &sunShading, "field"_a, "azimuth_deg"_a, "elevation_deg"_a, "size_deg"_a, "options"_a,
        "device"_a, "progress"_a.none());
  m.def("insolation", &insolation, "field"_a, "options"_a, "sweep"_a, "device"_a, "progress"_a.none());
  m.def("environment_light", &environmentLight, "field"_a, "map"_a, "options"_a, "device"_a,
        "progress"_a.none());
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
