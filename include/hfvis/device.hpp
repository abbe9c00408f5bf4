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

namespace detail {
struct ContextState;
}

// An OpenCL context, queue and program cache on one device. Cheap to copy (shared). It
// runs one operation at a time: use one context per thread. It keeps the scratch buffers of
// its last horizon call (hull stacks, direction planes) for the next one; they count
// against the device's memory, not against a later call's memory budget.
class ComputeContext {
 public:
  // selector: "" uses the HFVIS_DEVICE environment variable, else prefers a GPU, else
  // the first CPU. Otherwise a device index ("1"), a type ("gpu", "cpu") or a
  // case-insensitive substring of the platform or device name.
  static ComputeContext create(const std::string& selector = "");

  const DeviceInfo& device() const;
  detail::ContextState& state() const { return *state_; }

 private:
  std::shared_ptr<detail::ContextState> state_;
};

}  // namespace hfvis
