// bench/environment.cpp: the benchmark's record of the machine it ran on.
#include "environment.hpp"

#include <sys/utsname.h>

#include <ctime>
#include <fstream>
#include <sstream>
#include <thread>

namespace hfvis::bench {
namespace {

// The value of the first "key : value" line of a /proc file whose key starts with `key`.
std::string procField(const std::string& path, const std::string& key) {
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind(key, 0) != 0) continue;
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string value = line.substr(colon + 1);
    value.erase(0, value.find_first_not_of(" \t"));
    return value;
  }
  return "";
}

}  // namespace

std::string loadAverage() {
  std::ifstream in("/proc/loadavg");
  std::string one, five, fifteen;
  in >> one >> five >> fifteen;
  return in ? one + " " + five + " " + fifteen : "";
}

std::string utcNow() {
  const std::time_t now = std::time(nullptr);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return text;
}

KeyValues describeEnvironment(const DeviceInfo& device) {
  KeyValues kv;
  kv.emplace_back("date_utc", utcNow());
  kv.emplace_back("device", device.name);
  kv.emplace_back("device_type", device.type);
  kv.emplace_back("platform", device.platform);
  kv.emplace_back("opencl_driver", device.driver_version);
  kv.emplace_back("opencl_version", device.opencl_version);
  kv.emplace_back("compute_units", std::to_string(device.compute_units));
  kv.emplace_back("device_memory_mib", std::to_string(device.global_memory_bytes >> 20));
  kv.emplace_back("cpu_model", procField("/proc/cpuinfo", "model name"));
  kv.emplace_back("hardware_threads", std::to_string(std::thread::hardware_concurrency()));
  kv.emplace_back("memory_total", procField("/proc/meminfo", "MemTotal"));
  utsname u{};
  if (uname(&u) == 0)
    kv.emplace_back("os_kernel", std::string(u.sysname) + " " + u.release + " " + u.machine);
  kv.emplace_back("compiler", __VERSION__);
  kv.emplace_back("load_average_start", loadAverage());
  return kv;
}

}  // namespace hfvis::bench
