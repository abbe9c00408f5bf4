// opencl_context.cpp: device discovery and selection, context creation, program cache.
#include "core/opencl_context.hpp"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <vector>

namespace hfvis {
namespace detail {

const std::map<std::string, std::string>& embeddedKernelSources();  // generated

namespace {

constexpr const char* kInstallHint =
    "install an OpenCL driver: `apt-get install pocl-opencl-icd` runs kernels on the CPU; "
    "GPUs need their vendor's ICD";

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::string trim(std::string s) {
  while (!s.empty() && (s.back() == '\0' || std::isspace(static_cast<unsigned char>(s.back())))) s.pop_back();
  return s;
}

std::string typeName(cl_device_type type) {
  if (type & CL_DEVICE_TYPE_GPU) return "GPU";
  if (type & CL_DEVICE_TYPE_CPU) return "CPU";
  if (type & CL_DEVICE_TYPE_ACCELERATOR) return "accelerator";
  return "other";
}

struct FoundDevice {
  DeviceInfo info;
  cl::Device device;
};

// Whether `path` is, or could be made (as PoCL would make it), a directory this user may
// create files in. Made, not judged by permissions: the superuser passes every access check,
// and still cannot create a directory in /proc or on a read-only file system.
bool usableDirectory(const std::string& path) {
  std::error_code error;
  std::filesystem::create_directories(path, error);
  return std::filesystem::is_directory(path, error) &&
         ::faccessat(AT_FDCWD, path.c_str(), W_OK | X_OK, AT_EACCESS) == 0;
}

// Whether the ICD loader will load PoCL: an .icd file naming it in OCL_ICD_VENDORS (a directory
// or one file) or /etc/OpenCL/vendors.
bool poclRegistered() {
  const char* vendors = std::getenv("OCL_ICD_VENDORS");
  const std::filesystem::path where = vendors && *vendors ? vendors : "/etc/OpenCL/vendors";
  std::error_code error;
  std::vector<std::filesystem::path> files;
  if (std::filesystem::is_directory(where, error)) {
    for (const auto& entry : std::filesystem::directory_iterator(where, error)) files.push_back(entry.path());
  } else {
    files.push_back(where);
  }
  for (const auto& file : files) {
    std::ifstream in(file);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (lower(text).find("pocl") != std::string::npos) return true;
  }
  return false;
}

// PoCL (the CPU driver) compiles kernels into a cache directory: POCL_CACHE_DIR, else
// $XDG_CACHE_HOME/pocl/kcache, else $HOME/.cache/pocl/kcache. Where that cannot be written it
// reports no device at all (or aborts, for an empty POCL_CACHE_DIR), which reads as a missing
// driver. So: a POCL_CACHE_DIR that cannot be used is an error that says so; where PoCL is
// registered, a default one that cannot be written (the user nobody, a read-only home) is replaced by a
// private directory of this user's under $TMPDIR (or /tmp), kept between runs so kernels are compiled once.
void preparePoclCache() {
  const std::string fix =
      ": PoCL, the CPU OpenCL driver, keeps its compiled kernels there; point it at a "
      "writable directory or unset it";
  if (const char* set = std::getenv("POCL_CACHE_DIR")) {
    if (!*set) throw Error("POCL_CACHE_DIR is set but empty" + fix);
    if (!usableDirectory(set))
      throw Error(std::string("POCL_CACHE_DIR='") + set + "' is not a directory this user can write" + fix);
    return;
  }
  if (!poclRegistered()) return;  // no PoCL: its cache is nobody's business
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  const char* home = std::getenv("HOME");
  const std::string standard = xdg && *xdg == '/' ? std::string(xdg) + "/pocl/kcache"
                               : home && *home    ? std::string(home) + "/.cache/pocl/kcache"
                                                  : std::string();
  if (!standard.empty() && usableDirectory(standard)) return;
  const char* tmp = std::getenv("TMPDIR");
  const std::string own =
      std::string(tmp && *tmp == '/' ? tmp : "/tmp") + "/hfvis-pocl-cache-" + std::to_string(::geteuid());
  ::mkdir(own.c_str(), 0700);
  // Only a directory of this user's that nobody else can write: another user's directory (or a
  // link to one) there could feed PoCL compiled kernels.
  struct stat status {};
  if (::lstat(own.c_str(), &status) != 0 || !S_ISDIR(status.st_mode) || status.st_uid != ::geteuid() ||
      (status.st_mode & 0022) != 0)
    throw Error("the OpenCL kernel cache cannot be written at '" + standard +
                "' (HOME or XDG_CACHE_HOME) nor at '" + own +
                "': set POCL_CACHE_DIR to a writable directory");
  ::setenv("POCL_CACHE_DIR", own.c_str(), 1);
}

std::vector<FoundDevice> findDevices() {
  static std::once_flag cache_once;
  std::call_once(cache_once, preparePoclCache);
  std::vector<cl::Platform> platforms;
  try {
    cl::Platform::get(&platforms);
  } catch (const cl::Error& e) {
    throw NoDeviceError(std::string("no OpenCL platform found (") + e.what() + " returned " +
                        std::to_string(e.err()) + "): " + kInstallHint);
  }
  std::vector<FoundDevice> found;
  for (const auto& platform : platforms) {
    std::vector<cl::Device> devices;
    try {
      platform.getDevices(CL_DEVICE_TYPE_ALL, &devices);
    } catch (const cl::Error&) {
      continue;  // a platform without devices (CL_DEVICE_NOT_FOUND)
    }
    for (const auto& device : devices) {
      FoundDevice f{{}, device};
      f.info.index = static_cast<int>(found.size());
      f.info.platform = trim(platform.getInfo<CL_PLATFORM_NAME>());
      f.info.name = trim(device.getInfo<CL_DEVICE_NAME>());
      f.info.type = typeName(device.getInfo<CL_DEVICE_TYPE>());
      f.info.driver_version = trim(device.getInfo<CL_DRIVER_VERSION>());
      f.info.opencl_version = trim(device.getInfo<CL_DEVICE_VERSION>());
      f.info.global_memory_bytes = device.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
      f.info.max_allocation_bytes = device.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>();
      f.info.compute_units = static_cast<int>(device.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>());
      f.info.correctly_rounded_divide =
          (device.getInfo<CL_DEVICE_SINGLE_FP_CONFIG>() & CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT) != 0;
      found.push_back(f);
    }
  }
  if (found.empty()) throw NoDeviceError(std::string("no OpenCL device found: ") + kInstallHint);
  return found;
}

const FoundDevice& selectDevice(const std::vector<FoundDevice>& devices, const std::string& selector) {
  if (selector.empty()) {
    for (const auto& d : devices)
      if (d.info.type == "GPU") return d;
    for (const auto& d : devices)
      if (d.info.type == "CPU") return d;
    return devices.front();
  }
  const bool numeric =
      std::all_of(selector.begin(), selector.end(), [](unsigned char c) { return std::isdigit(c); });
  if (numeric) {
    const unsigned long index = std::stoul(selector);
    if (index < devices.size()) return devices[index];
  } else {
    const std::string want = lower(selector);
    for (const auto& d : devices)
      if (lower(d.info.type) == want) return d;
    for (const auto& d : devices)
      if (lower(d.info.name).find(want) != std::string::npos ||
          lower(d.info.platform).find(want) != std::string::npos)
        return d;
  }
  std::string names;
  for (const auto& d : devices)
    names += "\n  " + std::to_string(d.info.index) + ": " + d.info.name + " (" + d.info.type + ")";
  throw NoDeviceError("no OpenCL device matches '" + selector + "'; devices are:" + names);
}

}  // namespace

std::string kernelSource(const std::string& file, const std::string& kernel_dir, std::string* include_dir) {
  if (!kernel_dir.empty()) {
    const std::string path = kernel_dir + "/" + file;
    // (a FIFO there blocked for good, a directory or an empty file gave a bare OpenCL error)
    struct stat status {};
    if (::stat(path.c_str(), &status) != 0 || !S_ISREG(status.st_mode) || status.st_size == 0)
      throw IoError(path,
                    "cannot read kernel source: not a regular file with text (a kernel directory, "
                    "HFVIS_KERNEL_DIR, is set)");
    std::ifstream in(path);
    if (!in) throw IoError(path, "cannot read kernel source (a kernel directory is set)");
    std::ostringstream text;
    text << in.rdbuf();
    *include_dir = kernel_dir;
    return text.str();
  }
  const auto& sources = embeddedKernelSources();
  const auto it = sources.find(file);
  if (it == sources.end()) throw Error("no embedded kernel source named " + file);
  include_dir->clear();
  return it->second;
}

cl::Program ContextState::program(const std::string& file, const std::string& defines) {
  std::string include_dir;
  const std::string source = kernelSource(file, options.kernel_dir, &include_dir);
  return programFromSource(file, source, include_dir, defines);
}

cl::Program ContextState::programFromSource(const std::string& file, const std::string& source,
                                            const std::string& include_dir, const std::string& defines) {
  // -w (OpenCL's own option): PoCL's compiler printed "17 warnings generated." to standard error
  // under -q, every one about the ABI of PoCL's own builtins (long8 arguments without AVX-512),
  // nothing a user or these kernels can act on. A failed build's log still holds its errors.
  std::string build_options = "-cl-std=CL1.2 -cl-kernel-arg-info -w " + defines;
  if (info.correctly_rounded_divide) build_options += " -cl-fp32-correctly-rounded-divide-sqrt";
  if (!include_dir.empty()) build_options += " -I " + include_dir;
  const std::string key = file + '\n' + build_options + '\n' + source;
  std::lock_guard<std::mutex> lock(mutex_);
  if (auto it = programs_.find(key); it != programs_.end()) return it->second;
  cl::Program program(context, source);
  try {
    program.build({device}, build_options.c_str());
  } catch (const cl::Error&) {
    std::string log;
    try {
      log = program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device);
    } catch (const cl::Error&) {
      log = "(no build log)";
    }
    // A driver that compiles through files (PoCL) fails with a bare line under a small `ulimit -f`
    // (its files are about a megabyte: a limit of 64 MiB or more is not named).
    rlimit limit{};
    if (::getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY &&
        limit.rlim_cur < (64u << 20))
      log += "\n(the file size limit, ulimit -f, is " + std::to_string(limit.rlim_cur) +
             " bytes: the OpenCL driver may write its compiled kernels to files, which a limit this small "
             "stops)";
    throw KernelBuildError(file + " with options '" + build_options + "'", log);
  }
  programs_.emplace(key, program);
  return program;
}

std::shared_ptr<const NamedKernel::Names> ContextState::argumentNames(const cl::Program& program,
                                                                      const cl::Kernel& kernel,
                                                                      const std::string& name) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto& entry = argument_names_[{program(), name}];
  if (!entry) {
    auto names = std::make_shared<NamedKernel::Names>();
    names->kernel = name;
    const cl_uint count = kernel.getInfo<CL_KERNEL_NUM_ARGS>();
    for (cl_uint i = 0; i < count; ++i)
      names->arguments.push_back(trim(kernel.getArgInfo<CL_KERNEL_ARG_NAME>(i)));
    entry = std::move(names);
  }
  return entry;
}

void ContextState::launch(const NamedKernel& kernel, const cl::NDRange& global, const cl::NDRange& local) {
  const cl::Kernel& ready = kernel.ready();
  if (!options.profile) {
    queue.enqueueNDRangeKernel(ready, cl::NullRange, global, local);
    return;
  }
  cl::Event event;
  queue.enqueueNDRangeKernel(ready, cl::NullRange, global, local, nullptr, &event);
  event.wait();
  const double seconds = (event.getProfilingInfo<CL_PROFILING_COMMAND_END>() -
                          event.getProfilingInfo<CL_PROFILING_COMMAND_START>()) *
                         1e-9;
  auto& entry = kernel_seconds[kernel.name()];
  entry.first += seconds;
  entry.second += 1;
}

cl::Buffer ContextState::reusableBuffer(const std::string& role, std::size_t bytes) {
  bytes = std::max<std::size_t>(bytes, sizeof(float));
  auto& entry = buffers_[role];
  // Grown when too small, and shrunk when more than twice the size asked for, so a context
  // never holds much more than its last call needed.
  if (entry.second < bytes || entry.second / 2 > bytes) {
    entry.first = cl::Buffer();  // release the smaller one before allocating
    entry.first = cl::Buffer(context, CL_MEM_READ_WRITE, bytes);
    entry.second = bytes;
  }
  return entry.first;
}

ContextState::~ContextState() {
  for (const auto& [name, entry] : kernel_seconds)
    std::fprintf(stderr, "hfvis profile: %-20s %9.3f s in %d launches\n", name.c_str(), entry.first,
                 entry.second);
}

}  // namespace detail

std::vector<DeviceInfo> listDevices() {
  std::vector<DeviceInfo> infos;
  for (const auto& d : detail::findDevices()) infos.push_back(d.info);
  return infos;
}

ContextOptions ContextOptions::fromEnvironment() {
  auto variable = [](const char* name) {
    const char* value = std::getenv(name);
    return std::string(value ? value : "");
  };
  ContextOptions options;
  options.device = variable("HFVIS_DEVICE");
  options.kernel_dir = variable("HFVIS_KERNEL_DIR");
  const std::string profile = variable("HFVIS_PROFILE");
  if (profile != "" && profile != "0" && profile != "1")
    throw InvalidArgument("HFVIS_PROFILE must be 1 (or 0) (got '" + profile + "')");
  options.profile = profile == "1";
  const std::string layout = variable("HFVIS_LINE_LAYOUT");
  if (layout == "line") {
    options.line_layout = LineLayout::LineMajor;
  } else if (layout == "step") {
    options.line_layout = LineLayout::StepMajor;
  } else if (!layout.empty()) {
    throw InvalidArgument("HFVIS_LINE_LAYOUT must be 'line' or 'step' (got '" + layout + "')");
  }
  return options;
}

ComputeContext ComputeContext::create(const ContextOptions& options) {
  const auto devices = detail::findDevices();
  const auto& found = detail::selectDevice(devices, options.device);
  ComputeContext context;
  context.state_ = std::make_shared<State>();
  context.state_->options = options;
  detail::translateOpenClErrors([&] {
    context.state_->info = found.info;
    context.state_->device = found.device;
    context.state_->context = cl::Context(found.device);
    context.state_->queue = cl::CommandQueue(context.state_->context, found.device,
                                             options.profile ? CL_QUEUE_PROFILING_ENABLE : 0);
    return 0;
  });
  return context;
}

const DeviceInfo& ComputeContext::device() const { return state_->info; }

const ContextOptions& ComputeContext::options() const { return state_->options; }

}  // namespace hfvis
