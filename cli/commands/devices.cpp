// cli/commands/devices.cpp: "hfvis devices": the OpenCL devices, and the one automatic selection
// picks (hfvis/device.hpp).
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <iostream>

#include "../pipeline.hpp"
#include "hfvis/errors.hpp"

namespace hfvis::cli {
namespace {

std::string formatMemory(std::uint64_t bytes) {
  const double gib = static_cast<double>(bytes) / (1024.0 * 1024.0 * 1024.0);
  if (gib >= 1.0) return formatFixed(gib, 1) + " GiB";
  return formatFixed(static_cast<double>(bytes) / (1024.0 * 1024.0), 0) + " MiB";
}

// Prints the device table to stdout.
int runDevices(const CommandLine&) {
  const std::vector<DeviceInfo> devices = listDevices();

  // Which device automatic selection picks (honours HFVIS_DEVICE, as every command does).
  int automatic = -1;
  std::string automatic_error;
  try {
    automatic = ComputeContext::create(ContextOptions::fromEnvironment()).device().index;
  } catch (const Error& error) {
    automatic_error = error.what();
  }

  const std::vector<std::string> header{"index", "type", "name", "platform", "driver", "memory"};
  std::vector<std::vector<std::string>> rows;
  for (const DeviceInfo& device : devices) {
    rows.push_back({std::to_string(device.index), device.type, device.name, device.platform,
                    device.driver_version, formatMemory(device.global_memory_bytes)});
  }
  std::vector<std::size_t> widths(header.size());
  for (std::size_t c = 0; c < header.size(); ++c) {
    widths[c] = header[c].size();
    for (const auto& row : rows) widths[c] = std::max(widths[c], row[c].size());
  }
  const auto printRow = [&](const std::string& mark, const std::vector<std::string>& row) {
    std::string line = mark;
    for (std::size_t c = 0; c < row.size(); ++c) {
      line += row[c];
      if (c + 1 < row.size()) line += std::string(widths[c] - row[c].size() + 2, ' ');
    }
    std::cout << line << "\n";
  };
  printRow("  ", header);
  for (std::size_t i = 0; i < rows.size(); ++i)
    printRow(devices[i].index == automatic ? "* " : "  ", rows[i]);
  if (automatic >= 0) {
    std::cout << "* = automatic selection"
              << (std::getenv("HFVIS_DEVICE")
                      ? " (HFVIS_DEVICE=" + std::string(std::getenv("HFVIS_DEVICE")) + ")"
                      : std::string(" (HFVIS_DEVICE not set)"))
              << "\n";
  } else {
    std::cerr << "hfvis: warning: automatic device selection failed: " << automatic_error << "\n";
  }
  return 0;
}

}  // namespace

const CommandSpec kDevicesCommand{
    Command::Devices,
    "devices",
    nullptr,
    "list the OpenCL devices and mark the one automatic selection picks",
    "",
    "Lists every OpenCL device of every platform: index, type, name, platform, driver\n"
    "version and global memory. '*' marks the device automatic selection picks (the\n"
    "HFVIS_DEVICE environment variable if set, else a GPU, else the first CPU). Use the\n"
    "index, a type (gpu, cpu) or part of the name with --device or HFVIS_DEVICE.\n",
    nullptr,
    0,  // no arguments
    nullptr,
    nullptr,
    runDevices,
};

}  // namespace hfvis::cli
