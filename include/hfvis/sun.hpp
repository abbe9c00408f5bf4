// hfvis/sun.hpp: where the sun stands in the sky at a time and place, and which way that is
// over a height field.
//
// The solar position is the low-accuracy algorithm of Meeus (1998, Astronomical Algorithms,
// 2nd ed., ch. 25) with Smart's equation of time, as NOAA's solar calculator computes it: the
// sun's apparent longitude within about 0.01 degree for 1800 - 2200. tests/test_sun.cpp checks
// it against the worked example of Reda & Andreas (2004, NREL's SPA: 0.0003 degree), the
// declinations at the 2026 equinox and solstice of the US Naval Observatory, and the length of
// an equinox day at the equator: within 0.003 degree in elevation and azimuth there (the tests
// allow 0.005).
#pragma once

#include <string>

#include <glm/vec3.hpp>

namespace hfvis {

// A UTC instant in seconds since 1970-01-01T00:00:00Z (POSIX time: no leap seconds) from an
// ISO 8601 date and time with a zone: "2026-06-21T12:00:00Z", "2026-06-21T14:00:00+02:00",
// "2026-06-21T12:00Z", fractional seconds allowed, 'T' or a space between date and time.
// Throws InvalidArgument for anything else (no zone, a day the month does not have, ...).
double parseUtcTime(const std::string& text);

struct SunPosition {
  double azimuth_deg = 0.0;    // compass azimuth: degrees clockwise from north, [0, 360)
  double elevation_deg = 0.0;  // above the horizontal: geometric, or apparent when asked
};

// The sun's position seen from latitude / longitude (degrees, north and east positive; the
// geocentric direction: parallax, under 0.003 degree, is left out). `apparent` adds the
// atmosphere's refraction (atmosphericRefraction) to the elevation. Throws InvalidArgument for a
// latitude outside [-90, 90], a longitude outside [-180, 360], or a time outside the years
// 1800 - 2200 (the algorithm's range).
SunPosition sunPosition(double utc_seconds, double latitude_deg, double longitude_deg, bool apparent = false);

// Refraction of the sun's elevation by the atmosphere, degrees, at geometric elevation e
// (Sæmundsson 1986, as Meeus eq. 16.4; pressure in hPa and temperature in degrees C scale it);
// 0 below -1 degree, where the sun is set whatever the refraction.
double atmosphericRefraction(double elevation_deg, double pressure_hpa = 1010.0, double temperature_c = 10.0);

// The unit vector toward a sun at `position` in a height field's frame (x along +column, y
// along +row, z up) for a field whose row 0 is north: compass azimuth A is hfvis azimuth
// A - 90 degrees (east is +column, south +row).
glm::dvec3 sunDirection(const SunPosition& position);

}  // namespace hfvis
