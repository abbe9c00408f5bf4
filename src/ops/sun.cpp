// sun.cpp: the solar position (see hfvis/sun.hpp) and ISO 8601 times.
#include "hfvis/sun.hpp"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <string>

#include <glm/geometric.hpp>

#include "hfvis/errors.hpp"

namespace hfvis {
namespace {

constexpr double kDegree = M_PI / 180.0;

double sinDeg(double x) { return std::sin(x * kDegree); }
double cosDeg(double x) { return std::cos(x * kDegree); }

// Days from 1970-01-01 to year-month-day in the proleptic Gregorian calendar (Hinnant's
// days_from_civil).
long long daysFromCivil(long long y, unsigned m, unsigned d) {
  y -= m <= 2;
  const long long era = (y >= 0 ? y : y - 399) / 400;
  const unsigned yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m > 2 ? m - 3 : m + 9) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<long long>(doe) - 719468;
}

bool leapYear(long long y) { return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0; }

unsigned daysInMonth(long long y, unsigned m) {
  static const unsigned days[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  return m == 2 && leapYear(y) ? 29 : days[m - 1];
}

// Reads exactly `digits` decimal digits at text[*at] into *value.
bool readDigits(const std::string& text, std::size_t* at, int digits, int* value) {
  if (*at + digits > text.size()) return false;
  int v = 0;
  for (int i = 0; i < digits; ++i) {
    const char c = text[*at + i];
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
    v = v * 10 + (c - '0');
  }
  *at += digits;
  *value = v;
  return true;
}

}  // namespace

double parseUtcTime(const std::string& text) {
  auto bad = [&](const std::string& why) {
    return InvalidArgument("time '" + text + "': " + why +
                           " (expected ISO 8601 with a zone, e.g. 2026-06-21T12:00:00Z or 2026-06-21T14:00:00+02:00)");
  };
  std::size_t at = 0;
  int year = 0, month = 0, day = 0, hour = 0, minute = 0, second = 0;
  if (!readDigits(text, &at, 4, &year) || at >= text.size() || text[at++] != '-' ||
      !readDigits(text, &at, 2, &month) || at >= text.size() || text[at++] != '-' || !readDigits(text, &at, 2, &day))
    throw bad("no date YYYY-MM-DD");
  if (month < 1 || month > 12 || day < 1 || day > static_cast<int>(daysInMonth(year, month)))
    throw bad("no such day");
  // (RFC 3339 allows 't' and 'z' in lower case)
  if (at >= text.size() || (text[at] != 'T' && text[at] != 't' && text[at] != ' '))
    throw bad("no time after the date");
  ++at;
  if (!readDigits(text, &at, 2, &hour) || at >= text.size() || text[at++] != ':' ||
      !readDigits(text, &at, 2, &minute))
    throw bad("no time hh:mm");
  double fraction = 0.0;
  if (at < text.size() && text[at] == ':') {
    ++at;
    if (!readDigits(text, &at, 2, &second)) throw bad("no seconds after hh:mm:");
    if (at < text.size() && (text[at] == '.' || text[at] == ',')) {
      ++at;
      double scale = 0.1;
      const std::size_t first = at;
      for (; at < text.size() && std::isdigit(static_cast<unsigned char>(text[at])); ++at, scale /= 10)
        fraction += (text[at] - '0') * scale;
      if (at == first) throw bad("no digits after the decimal point");
    }
  }
  if (hour > 23 || minute > 59 || second > 59) throw bad("hours, minutes or seconds out of range");
  int offset_minutes = 0;
  if (at < text.size() && (text[at] == 'Z' || text[at] == 'z')) {
    ++at;
  } else if (at < text.size() && (text[at] == '+' || text[at] == '-')) {
    const int sign = text[at++] == '-' ? -1 : 1;
    int zone_hours = 0, zone_minutes = 0;
    if (!readDigits(text, &at, 2, &zone_hours)) throw bad("no zone hours");
    if (at < text.size() && text[at] == ':') ++at;
    if (!readDigits(text, &at, 2, &zone_minutes)) throw bad("no zone minutes");
    if (zone_hours > 14 || zone_minutes > 59) throw bad("zone out of range");
    offset_minutes = sign * (zone_hours * 60 + zone_minutes);
  } else {
    throw bad("no zone (Z or +hh:mm)");
  }
  if (at != text.size()) throw bad("unexpected '" + text.substr(at) + "' at the end");
  const long long days = daysFromCivil(year, static_cast<unsigned>(month), static_cast<unsigned>(day));
  return static_cast<double>(days) * 86400.0 + hour * 3600.0 + minute * 60.0 + second + fraction -
         offset_minutes * 60.0;
}

double atmosphericRefraction(double elevation_deg, double pressure_hpa, double temperature_c) {
  if (elevation_deg < -1.0) return 0.0;
  // Sæmundsson: R = 1.02 / tan(h + 10.3 / (h + 5.11)) arc minutes, for 1010 hPa and 10 C.
  const double minutes = 1.02 / std::tan((elevation_deg + 10.3 / (elevation_deg + 5.11)) * kDegree);
  return minutes / 60.0 * (pressure_hpa / 1010.0) * (283.0 / (273.0 + temperature_c));
}

SunPosition sunPosition(double utc_seconds, double latitude_deg, double longitude_deg, bool apparent) {
  if (!(latitude_deg >= -90.0 && latitude_deg <= 90.0))
    throw InvalidArgument("latitude " + std::to_string(latitude_deg) + " is outside -90 .. 90 degrees");
  if (!(longitude_deg >= -180.0 && longitude_deg <= 360.0))
    throw InvalidArgument("longitude " + std::to_string(longitude_deg) + " is outside -180 .. 360 degrees");
  // 1800-01-01 and 2201-01-01.
  if (!(utc_seconds >= -5364662400.0 && utc_seconds < 7289654400.0))
    throw InvalidArgument("the solar position is computed for the years 1800 to 2200 only");
  const double jd = utc_seconds / 86400.0 + 2440587.5;
  const double t = (jd - 2451545.0) / 36525.0;  // Julian centuries from J2000 (UT for TT: 0.001 degree)
  const double l0 = std::fmod(280.46646 + t * (36000.76983 + t * 0.0003032), 360.0);  // mean longitude
  const double m = 357.52911 + t * (35999.05029 - 0.0001537 * t);                     // mean anomaly
  const double e = 0.016708634 - t * (0.000042037 + 0.0000001267 * t);               // eccentricity
  const double centre = sinDeg(m) * (1.914602 - t * (0.004817 + 0.000014 * t)) +
                        sinDeg(2 * m) * (0.019993 - 0.000101 * t) + sinDeg(3 * m) * 0.000289;
  const double omega = 125.04 - 1934.136 * t;
  const double longitude = l0 + centre - 0.00569 - 0.00478 * sinDeg(omega);  // apparent longitude
  const double mean_obliquity = 23.0 + (26.0 + (21.448 - t * (46.815 + t * (0.00059 - t * 0.001813))) / 60.0) / 60.0;
  const double obliquity = mean_obliquity + 0.00256 * cosDeg(omega);
  const double declination = std::asin(sinDeg(obliquity) * sinDeg(longitude)) / kDegree;
  // Equation of time (minutes).
  const double y = std::pow(std::tan(obliquity / 2.0 * kDegree), 2.0);
  const double equation = 4.0 / kDegree *
                          (y * sinDeg(2 * l0) - 2.0 * e * sinDeg(m) + 4.0 * e * y * sinDeg(m) * cosDeg(2 * l0) -
                           0.5 * y * y * sinDeg(4 * l0) - 1.25 * e * e * sinDeg(2 * m));
  double day_minutes = std::fmod(utc_seconds / 60.0, 1440.0);
  if (day_minutes < 0.0) day_minutes += 1440.0;
  const double solar_minutes = day_minutes + equation + 4.0 * longitude_deg;
  const double hour_angle = std::remainder(solar_minutes / 4.0 - 180.0, 360.0);  // degrees, west positive
  const double sin_elevation =
      sinDeg(latitude_deg) * sinDeg(declination) + cosDeg(latitude_deg) * cosDeg(declination) * cosDeg(hour_angle);
  SunPosition p;
  p.elevation_deg = std::asin(std::fmax(-1.0, std::fmin(1.0, sin_elevation))) / kDegree;
  // Meeus eq. 13.5: the azimuth from the south, westward; + 180 from the north, eastward.
  const double from_south = std::atan2(sinDeg(hour_angle), cosDeg(hour_angle) * sinDeg(latitude_deg) -
                                                               std::tan(declination * kDegree) * cosDeg(latitude_deg));
  p.azimuth_deg = std::fmod(from_south / kDegree + 180.0 + 360.0, 360.0);
  if (apparent) p.elevation_deg += atmosphericRefraction(p.elevation_deg);
  return p;
}

glm::dvec3 sunDirection(const SunPosition& position) {
  const double a = position.azimuth_deg * kDegree, e = position.elevation_deg * kDegree;
  return glm::normalize(glm::dvec3(std::sin(a) * std::cos(e), -std::cos(a) * std::cos(e), std::sin(e)));
}

}  // namespace hfvis
