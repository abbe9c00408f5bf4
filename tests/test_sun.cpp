// test_sun.cpp: the solar position against published values (Reda & Andreas 2004's worked
// example of NREL's SPA; the US Naval Observatory's 2026 equinox and solstice), the length of
// an equinox day at the equator, ISO 8601 times, refraction, and the sun's direction over a
// field.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "hfvis/errors.hpp"
#include "hfvis/sun.hpp"

namespace hfvis {
namespace {

TEST(SunTime, ParsesIso8601WithAZone) {
  EXPECT_EQ(parseUtcTime("1970-01-01T00:00:00Z"), 0.0);
  EXPECT_EQ(parseUtcTime("2026-06-21T12:00:00Z"), 1782043200.0);
  EXPECT_EQ(parseUtcTime("2026-06-21T14:00:00+02:00"), 1782043200.0);
  EXPECT_EQ(parseUtcTime("2026-06-21T07:30-0430"), 1782043200.0);
  EXPECT_EQ(parseUtcTime("2026-06-21 12:00Z"), 1782043200.0);
  EXPECT_EQ(parseUtcTime("2026-06-21t12:00:00z"), 1782043200.0);  // RFC 3339's lower case
  EXPECT_DOUBLE_EQ(parseUtcTime("2026-06-21T12:00:00.25Z"), 1782043200.25);
  EXPECT_EQ(parseUtcTime("2000-02-29T00:00:00Z"), 951782400.0);  // a leap day
  EXPECT_EQ(parseUtcTime("1900-03-01T00:00:00Z"), -2203891200.0);  // 1900 has no 29 February
  for (const char* bad : {"", "2026-06-21", "2026-06-21T12:00:00", "2026-13-01T00:00Z", "2026-02-29T00:00Z",
                          "1900-02-29T00:00Z", "2026-06-21T24:00Z", "2026-06-21T12:60Z", "2026-06-21T12:00:00.Z",
                          "2026-06-21T12:00:00+15:00", "2026-06-21T12:00:00Zx", "26-06-21T12:00Z",
                          "2026-06-21T12:00:00 Z"}) {
    EXPECT_THROW(parseUtcTime(bad), InvalidArgument) << bad;
  }
}

// Reda & Andreas (2004), Table A5.1-2: 17 October 2003, 12:30:30 at UTC-7 (19:30:30 UTC),
// 39.742476 N, 105.1786 W: topocentric zenith 50.11162 degrees (refracted for 820 hPa and 11 C,
// as SPA computes it) and azimuth 194.34024. Geometric and geocentric here: undo that refraction
// (the same Sæmundsson formula SPA uses) and add the parallax, 8.794" cos(elevation).
TEST(SunPosition, MatchesTheSpaWorkedExample) {
  const double t = parseUtcTime("2003-10-17T12:30:30-07:00");
  const SunPosition p = sunPosition(t, 39.742476, -105.1786);
  const double apparent = 90.0 - 50.11162;
  // Geometric topocentric elevation e with e + refraction(e) = apparent, by fixed point.
  double e = apparent;
  for (int i = 0; i < 20; ++i) e = apparent - atmosphericRefraction(e, 820.0, 11.0);
  const double geocentric = e + 8.794 / 3600.0 * std::cos(e * M_PI / 180.0);
  EXPECT_NEAR(p.elevation_deg, geocentric, 0.005);
  EXPECT_NEAR(p.azimuth_deg, 194.34024, 0.005);
  // The figures docs/COMMAND_LINE.md quotes.
  std::printf("SPA worked example: elevation off by %.4f deg, azimuth by %.4f deg\n", p.elevation_deg - geocentric,
              p.azimuth_deg - 194.34024);
  // Asked for, the apparent elevation adds the standard atmosphere's refraction.
  const SunPosition seen = sunPosition(t, 39.742476, -105.1786, true);
  EXPECT_NEAR(seen.elevation_deg - p.elevation_deg, atmosphericRefraction(p.elevation_deg), 1e-12);
  EXPECT_EQ(seen.azimuth_deg, p.azimuth_deg);
}

// At the North Pole the sun's elevation is its declination: 0 at the March equinox (20 March
// 2026, 14:46 UTC) and the obliquity of the ecliptic, 23.436 degrees, at the June solstice
// (21 June 2026, 08:24 UTC), per the US Naval Observatory.
TEST(SunPosition, DeclinationAtTheEquinoxAndTheSolstice) {
  // (The instants are given to the minute, in which the declination moves 0.0003 degree.)
  const double equinox = sunPosition(parseUtcTime("2026-03-20T14:46:00Z"), 90.0, 0.0).elevation_deg;
  const double solstice = sunPosition(parseUtcTime("2026-06-21T08:24:00Z"), 90.0, 0.0).elevation_deg;
  EXPECT_NEAR(equinox, 0.0, 0.005);
  EXPECT_NEAR(solstice, 23.436, 0.005);
  std::printf("declination off by %.4f deg at the equinox, %.4f deg at the solstice\n", equinox, solstice - 23.436);
  EXPECT_NEAR(sunPosition(parseUtcTime("2026-06-21T08:24:00Z"), -90.0, 0.0).elevation_deg, -23.436, 0.005);
}

// On the equinox the sun's centre is above the horizon at the equator for 12 hours (the
// declination moves 0.4 degree a day: half a minute of day length), rises due east and sets
// due west, and stands almost overhead at its local noon (the equation of time then: -7.5 min).
TEST(SunPosition, AnEquinoxDayAtTheEquator) {
  const double midnight = parseUtcTime("2026-03-20T00:00:00Z");
  int minutes_up = 0;
  double highest = -90.0, rise_azimuth = 0.0, set_azimuth = 0.0;
  bool was_up = false;
  for (int minute = 0; minute < 1440; ++minute) {
    const SunPosition p = sunPosition(midnight + minute * 60.0, 0.0, 0.0);
    const bool up = p.elevation_deg > 0.0;
    minutes_up += up;
    if (up && !was_up && minute > 0) rise_azimuth = p.azimuth_deg;
    if (!up && was_up) set_azimuth = p.azimuth_deg;
    was_up = up;
    highest = std::fmax(highest, p.elevation_deg);
  }
  EXPECT_NEAR(minutes_up, 720, 2);
  EXPECT_NEAR(rise_azimuth, 90.0, 0.5);
  EXPECT_NEAR(set_azimuth, 270.0, 0.5);
  EXPECT_GT(highest, 89.5);
  const SunPosition noon = sunPosition(parseUtcTime("2026-03-20T12:07:30Z"), 0.0, 0.0);
  EXPECT_GT(noon.elevation_deg, 89.5);
}

TEST(SunPosition, RefusesPlacesAndTimesOutOfRange) {
  const double t = parseUtcTime("2026-06-21T12:00:00Z");
  EXPECT_THROW(sunPosition(t, 91.0, 0.0), InvalidArgument);
  EXPECT_THROW(sunPosition(t, std::nan(""), 0.0), InvalidArgument);
  EXPECT_THROW(sunPosition(t, 0.0, -181.0), InvalidArgument);
  EXPECT_THROW(sunPosition(parseUtcTime("1700-01-01T00:00:00Z"), 0.0, 0.0), InvalidArgument);
  EXPECT_THROW(sunPosition(parseUtcTime("2300-01-01T00:00:00Z"), 0.0, 0.0), InvalidArgument);
}

// Refraction: about 34' at the horizon and 1' at 45 degrees (the standard atmosphere), none
// below -1 degree.
TEST(SunPosition, Refraction) {
  EXPECT_NEAR(atmosphericRefraction(0.0) * 60.0, 29.0, 6.0);
  EXPECT_NEAR(atmosphericRefraction(45.0) * 60.0, 1.0, 0.05);
  EXPECT_EQ(atmosphericRefraction(-2.0), 0.0);
}

// The direction over a field whose row 0 is north: east is +column, south +row, up +z.
TEST(SunPosition, DirectionOverAField) {
  auto near = [](glm::dvec3 a, glm::dvec3 b) { return std::fabs(a.x - b.x) + std::fabs(a.y - b.y) + std::fabs(a.z - b.z) < 1e-12; };
  EXPECT_TRUE(near(sunDirection({90.0, 0.0}), {1.0, 0.0, 0.0}));
  EXPECT_TRUE(near(sunDirection({180.0, 0.0}), {0.0, 1.0, 0.0}));
  EXPECT_TRUE(near(sunDirection({0.0, 0.0}), {0.0, -1.0, 0.0}));
  EXPECT_TRUE(near(sunDirection({123.0, 90.0}), {0.0, 0.0, 1.0}));
  const glm::dvec3 d = sunDirection({225.0, 30.0});
  EXPECT_NEAR(d.z, 0.5, 1e-12);
  EXPECT_NEAR(d.x, d.y * -1.0, 1e-12);  // south-west: -column, +row
}

}  // namespace
}  // namespace hfvis
