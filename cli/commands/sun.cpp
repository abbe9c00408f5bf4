// cli/commands/sun.cpp: "hfvis sun-position" (also "sunpos"): the sun's compass azimuth and
// elevation at a time and place (hfvis/sun.hpp).
#include "hfvis/sun.hpp"

#include <iomanip>
#include <iostream>

#include "../table.hpp"

namespace hfvis::cli {
namespace {

// Prints "azimuth=<deg> elevation=<deg>".
int runSunPosition(const CommandLine& line) {
  const SunArguments& sun = line.sun;
  const SunPosition p = sunPosition(sun.utc_seconds, sun.latitude_deg, sun.longitude_deg, sun.apparent);
  std::cout << std::fixed << std::setprecision(4) << "azimuth=" << p.azimuth_deg
            << " elevation=" << p.elevation_deg << "\n";
  return 0;
}

}  // namespace

const CommandSpec kSunPositionCommand{
    Command::SunPosition,
    "sun-position",
    "sunpos",
    "the sun's compass azimuth and elevation at a time and place",
    "--lat LAT --lon LON --at TIME [--apparent]",
    "Prints 'azimuth=<deg> elevation=<deg>': where the sun stands seen from latitude LAT and\n"
    "longitude LON (degrees, north and east positive) at TIME (ISO 8601 with a zone, e.g.\n"
    "2026-06-21T12:00:00Z or 2026-06-21T14:00:00+02:00). The azimuth is the compass azimuth,\n"
    "degrees clockwise from north; the elevation is geometric (the sun's centre, no\n"
    "atmosphere; geocentric), or with --apparent raised by the refraction of a standard\n"
    "atmosphere (1010 hPa, 10 C). The algorithm is Meeus's (1998, ch. 25) with Smart's\n"
    "equation of time, as NOAA's solar calculator: within 0.003 degree of NREL's SPA on\n"
    "its worked example; years 1800 - 2200 (the range it accepts).\n",
    nullptr,
    0,  // its four options are its own (parseCommandLine)
    nullptr,
    nullptr,
    runSunPosition,
};

}  // namespace hfvis::cli
