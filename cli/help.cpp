// cli/help.cpp: the help texts, made from the command and option tables (cli/table.hpp), so that
// the help lists exactly what each command takes. The conventions here are the contract of
// docs/CONVENTIONS.md stated for users; keep them in step with include/hfvis/horizon.hpp,
// intervisibility.hpp, horizon_lists.hpp and bounce.hpp.
#include "help.hpp"

#include <algorithm>
#include <sstream>

#include "table.hpp"

namespace hfvis::cli {
namespace {

const char* const kConventions = R"(
Conventions and units:
  Input      one band of a raster GDAL reads (GeoTIFF/COG .tif/.tiff, .hgt, .asc, .vrt, .img,
             .bil, .dem, .grd, .adf) or one channel of an EXR (OpenEXR) or of another image
             OpenImageIO reads (PNG, ...), row-major, row 0 first as stored. Pixel (col, row) lies at ground position
             (col*X, row*Y); the surface is bilinear between pixels; height = value * Z.
             Integer pixels are read as their stored values (16-bit PNG: 0..65535).
  Directions direction k of K has azimuth phi_k = 360*k/K deg + offset, measured on the
             ground from the +column axis toward +row. When row 0 is north (most DEMs),
             compass azimuth = 90 + phi_k deg: k = 0 looks east, then south, west, north.
  Horizon    the largest elevation angle atan2(dz, ground distance) of the surface along
             the ray from a pixel in direction k, in radians (-pi/2..pi/2; 0 = level);
             -pi/2 where the ray leaves the field at once (at the border).
             Horizon distance: ground distance to the point casting it, ground units
             (0 where no point casts a horizon).
  SVF        1 - mean_k sin(max(0, elevation_k)): the fraction of the sky hemisphere
             visible from a pixel (level horizon = 1, fully enclosed = 0).
  AO         outgoing radiance of a white Lambertian surface under a uniform sky of
             radiance 1, from its horizons and its surface normal (Timonen & Westerholm
             2010, Eq. 5), normalised so that a flat plane gives 1.
  Nodata     non-finite heights (NaN, +-inf) are nodata: they neither cast nor receive;
             every output is NaN there, and holes do not spread into valid neighbours.
  Outputs    float32 EXR (ZIP-compressed, through OpenEXR), with the run described in
             string attributes hfvis:*; GeoTIFF for .tif/.tiff (horizon-lists: JSON
             or CSV text). Files are written to a temporary name and renamed only once every
             output of the run is complete, so a failed run leaves no partial or mismatched
             output behind.
  GIS        A georeferenced input keeps its CRS (projected or geographic, copied as it is)
             and geotransform in GeoTIFF outputs, so they overlay it. Cell sizes come from
             the geotransform in the CRS's units; geographic degrees become metres (WGS84,
             at each row's latitude; bounce takes the centre latitude's for the whole field,
             and viewshed, arealight, region, pvs and shade --env refuse such grids: reproject
             them first); rotated geotransforms are refused. A band's nodata value reads as
             nodata. GeoTIFF outputs: one float32 band per channel,
             named by its description (h000.., svf, ao, count, visible_area), nodata declared
             on every band (NaN, or --nodata VALUE written in those cells), DEFLATE with the
             floating-point predictor, 256x256 tiles, BigTIFF when needed; the hfvis:*
             attributes become metadata items hfvis_* (GDAL splits names at ':'). EXR
             outputs keep the cell size (hfvis:cell_size_x/y) but no georeference.
)";

const char* const kExitStatus = R"(
Progress ("hfvis: 16/64 directions") goes to stderr when it is a terminal; a one-line
summary goes to stdout.

Exit status: 0 success, 1 runtime error (unreadable input, device or write failure),
2 usage error (unknown option or command, missing or invalid value).
)";

// What the overview calls each group of options (in OptionGroup's order).
const char* groupTitle(unsigned group) {
  switch (group) {
    case kOutputGroup:
      return "Output";
    case kInputGroup:
      return "Input";
    case kImageGroup:
      return "Image outputs";
    case kDeviceGroup:
      return "Device";
    case kSweepGroup:
      return "Directions";
    case kSamplingGroup:
      return "Sampling";
    case kEarthGroup:
      return "The Earth's curvature";
    case kReachGroup:
      return "Reach";
    case kSweepMethodGroup:
      return "Horizon method";
    case kHullTreeGroup:
      return "Convex hull tree";
    case kSunPlaceGroup:
      return "The sun's place";
    case kEnvironmentLightGroup:
      return "Environment light";
    case kSunShadingGroup:
      return "Sun shading";
    case kRegionSamplingGroup:
      return "Region sampling";
    case kErrorTargetGroup:
      return "Error target";
    default:
      return "";  // a command's own group
  }
}

// `text`'s lines, each after `indent` (the first after `first` instead, when given).
std::string indented(const std::string& text, const std::string& indent, const std::string& first) {
  std::istringstream lines(text);
  std::string out, line;
  for (bool at_first = true; std::getline(lines, line); at_first = false)
    out += (at_first ? first : indent) + line + "\n";
  return out;
}

// "  -o, --output FILE        output image ..." and its further lines aligned under the first.
std::string optionHelp(const OptionSpec& option) {
  std::string flags = option.short_name ? std::string(option.short_name) + ", " + option.name : option.name;
  if (option.value) flags += std::string(" ") + option.value;
  const std::string column(27, ' ');
  return indented(option.help, column,
                  "  " + flags + std::string(flags.size() < 23 ? 25 - flags.size() : 2, ' '));
}

// The options of the groups in `groups`, under a heading per group (naming the commands that take it
// where `name_takers`).
std::string optionsHelp(unsigned groups, bool name_takers) {
  std::string out;
  for (unsigned group = 1; group <= kLastGroup; group <<= 1) {
    if (!(groups & group)) continue;
    // The commands that take it, or those of the commands with options that do not (shorter).
    std::vector<std::string> takers, others;
    for (const CommandSpec* command : commandTable())
      if (command->groups) ((command->groups & group) ? takers : others).push_back(command->name);
    const bool by_others = others.size() < 4;
    std::string named;
    for (const std::string& name : by_others ? others : takers) named += (named.empty() ? "" : ", ") + name;
    if (by_others) named = others.empty() ? "every command that reads a height field" : "all but " + named;
    const std::string title = groupTitle(group);
    if (title.empty())  // a command's own group
      out += "\nOptions of " + named + ":\n";
    else
      out += "\n" + title + (name_takers ? " (" + named + ")" : "") + ":\n";
    for (const OptionSpec& option : optionTable())
      if (option.group == group) out += optionHelp(option);
  }
  return out;
}

// "hfvis NAME USAGE", its further lines aligned under the first.
std::string usageLine(const CommandSpec& command, std::size_t name_width) {
  std::string name = command.name;
  if (!*command.usage) return "hfvis " + name + "\n";
  name += std::string(name_width > name.size() ? name_width - name.size() : 0, ' ');
  return indented(command.usage, std::string(6 + name.size() + 1, ' '), "hfvis " + name + " ");
}

std::string aliasLine(const CommandSpec& command) {
  return command.alias ? std::string("(also 'hfvis ") + command.alias + "', its earlier name)\n" : "";
}

}  // namespace

std::string generalHelp() {
  // The names, and the names with their aliases, in columns.
  const auto named = [](const CommandSpec& command) {
    return command.alias ? std::string(command.name) + " (" + command.alias + ")" : std::string(command.name);
  };
  std::size_t width = 0, named_width = 0;
  for (const CommandSpec* command : commandTable()) {
    width = std::max(width, std::string(command->name).size());
    named_width = std::max(named_width, named(*command).size());
  }
  std::string usage = "Usage:\n", commands = "\nCommands (earlier names in brackets, which keep working):\n",
              notes;
  unsigned groups = 0;
  for (const CommandSpec* command : commandTable()) {
    usage += indented(usageLine(*command, width), "  ", "  ");
    const std::string name = named(*command);
    commands += indented(command->summary, std::string(named_width + 4, ' '),
                         "  " + name + std::string(named_width + 2 - name.size(), ' '));
    if (command->notes)
      notes += "\n" + std::string(command->name) + ":\n" + indented(command->notes, "  ", "  ");
    groups |= command->groups;
  }
  usage += "  hfvis --help | hfvis COMMAND --help\n";
  return std::string(
             "hfvis: horizons, sky-view factor, ambient occlusion, intervisibility, one-bounce light, and "
             "lighting by "
             "HDR environments and the sun on height fields (OpenCL)\n\n") +
         usage + commands + "\nOptions, by group (the commands that take each in brackets):\n" +
         optionsHelp(groups, true) + "\n  -h, --help               show help\n" + notes + kConventions +
         kExitStatus;
}

std::string commandHelp(Command id) {
  const CommandSpec& command = commandSpec(id);
  std::string help = usageLine(command, 0) + aliasLine(command) + "\n" + command.description;
  if (!command.groups) return help;  // (devices, sun-position: no options of the table, no outputs)
  help += optionsHelp(command.groups, false) + "\n  -h, --help               show help\n";
  if (command.notes) help += "\n" + std::string(command.notes);
  return help + kConventions + kExitStatus;
}

}  // namespace hfvis::cli
