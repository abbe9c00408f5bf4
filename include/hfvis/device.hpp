// hfvis/device.hpp: choosing an OpenCL device and the context every operation runs in.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace hfvis {

struct DeviceInfo {
  int index = 0;  // position in listDevices(), usable as a selector
  std::string platform;
  std::string name;
  std::string type;  // "GPU", "CPU", "accelerator" or "other"
  std::string driver_version;
  std::string opencl_version;
  std::uint64_t global_memory_bytes = 0;
  std::uint64_t max_allocation_bytes = 0;
  int compute_units = 0;
  // CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT: programs are then built with
  // -cl-fp32-correctly-rounded-divide-sqrt, so float division rounds as in C++ (the scalar
  // references); without it a division may differ by 2.5 ulp.
  bool correctly_rounded_divide = false;
};

// Every device of every platform. Throws NoDeviceError when no platform is installed.
std::vector<DeviceInfo> listDevices();

// How the sweep kernels lay out their per-line scratch (hull stacks, tree nodes).
enum class LineLayout {
  Automatic,  // line-major on CPUs (and the horizon sweep in SIMD lanes), step-major elsewhere
  LineMajor,  // each line's entries contiguous: a work-item walks its line in one stream
  StepMajor,  // entries of one step of all lines contiguous: neighbouring work-items coalesce
};

// How a context is set up. The library reads no environment variable; the CLI and the
// benchmark map theirs onto these with fromEnvironment().
struct ContextOptions {
  // The device: "" prefers a GPU, else the first CPU. Otherwise a device index ("1"), a type
  // ("gpu", "cpu") or a case-insensitive substring of the platform or device name.
  std::string device;
  // Time every kernel launch on the device (each launch then waits for the one before) and
  // print each kernel's total to stderr when the context is destroyed.
  bool profile = false;
  // Development: read the kernels (kernels/*.cl) from this directory instead of the copies
  // embedded in the library, to try a kernel change without rebuilding. "" = embedded.
  std::string kernel_dir;
  // Every layout gives the same results; forcing one lets a CPU test the GPU layout.
  LineLayout line_layout = LineLayout::Automatic;

  // The options the HFVIS_* environment variables give: HFVIS_DEVICE (device), HFVIS_PROFILE=1
  // (profile), HFVIS_KERNEL_DIR (kernel_dir), HFVIS_LINE_LAYOUT=line|step (line_layout).
  // Throws InvalidArgument for another HFVIS_LINE_LAYOUT or HFVIS_PROFILE value.
  static ContextOptions fromEnvironment();
};

// An OpenCL context, queue and program cache on one device. Cheap to copy (shared); never
// empty: create() is the only way to get one. It runs one operation at a time: use one
// context per thread. It keeps the scratch buffers of its last horizon call (hull stacks,
// direction planes) for the next one; they count against the device's memory, not against a
// later call's memory budget.
class ComputeContext {
 public:
  // Throws NoDeviceError when no OpenCL platform is installed or no device matches
  // options.device (the message lists the devices).
  static ComputeContext create(const ContextOptions& options = {});

  const DeviceInfo& device() const;
  const ContextOptions& options() const;

 private:
  // The OpenCL state, opaque here: the library defines it and reaches it through
  // ContextAccess (src/core/opencl_context.hpp).
  struct State;
  friend class ContextAccess;
  ComputeContext() = default;
  std::shared_ptr<State> state_;
};

}  // namespace hfvis
