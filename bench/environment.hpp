// bench/environment.hpp: where a benchmark ran (device, driver, CPU, load, build), recorded
// next to the measurements so that every figure in the report says where it came from.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "hfvis/device.hpp"

namespace hfvis::bench {

using KeyValues = std::vector<std::pair<std::string, std::string>>;

// Device, OpenCL driver, CPU model and count, memory, kernel, compiler, date (UTC) and the
// current load average.
KeyValues describeEnvironment(const DeviceInfo& device);

// "1.23 0.98 0.50" from /proc/loadavg ("" where unavailable).
std::string loadAverage();

// Current UTC time as ISO 8601.
std::string utcNow();

}  // namespace hfvis::bench
