// cli/table.hpp: the hfvis command line as two tables, from which parsing, its messages and the
// help all come, so that they cannot disagree. Every option is declared once (optionTable(),
// cli/arguments.cpp): its flag, value, help and the field it sets; it belongs to one group.
// Every command is one entry (commandTable(), one file per command under cli/commands/): its
// name, alias, help, the groups of options it takes and its run.
#pragma once

#include <string>
#include <vector>

#include "arguments.hpp"

namespace hfvis::cli {

// The groups of options; a command takes a set of them (CommandSpec::groups), an option belongs
// to one (OptionSpec::group). The shared groups come first, then the groups of one command.
enum OptionGroup : unsigned {
  kOutputGroup = 1u << 0,       // -o, --quiet
  kInputGroup = 1u << 1,        // how the input is read: --channel, --cell-size, --z-scale
  kImageGroup = 1u << 2,        // image outputs: --preview, --nodata
  kDeviceGroup = 1u << 3,       // --device, --memory-budget
  kSweepGroup = 1u << 4,        // the sweep's directions: -k, --azimuth-offset
  kSamplingGroup = 1u << 5,     // --samples-per-unit
  kEarthGroup = 1u << 6,        // --curvature, --refraction
  kReachGroup = 1u << 7,        // --max-distance
  kSweepMethodGroup = 1u << 8,  // --method sweep|naive
  kHullTreeGroup = 1u << 9,     // --hull-tree
  kSunPlaceGroup = 1u << 10,    // --lat, --lon, --sun-size
  kHorizonGroup = 1u << 11,     // the groups of one command each, from here on
  kIntervisibilityGroup = 1u << 12,
  kHorizonListsGroup = 1u << 13,
  kBounceGroup = 1u << 14,
  kEnvironmentLightGroup = 1u << 15,
  kSunShadingGroup = 1u << 16,
  kInsolationGroup = 1u << 17,
  kViewshedGroup = 1u << 18,
  // Region visibility (hfvis/region_visibility.hpp): what arealight and region share (--samples,
  // --method exact|culled|viewsheds, --absolute, --seed), then each one's own.
  kRegionSamplingGroup = 1u << 19,
  kAreaLightGroup = 1u << 20,
  kRegionPairGroup = 1u << 21,
  kErrorTargetGroup = 1u << 22,  // svf, ao, intervisibility, shade: --max-error, --error-tile, --error-out
  kPvsGroup = 1u << 23,          // pvs's view cells, tiles, sampler and budgets
  kLastGroup = kPvsGroup,
};

// The groups every command that reads a height field and writes images takes.
constexpr unsigned kImageCommandGroups = kOutputGroup | kInputGroup | kImageGroup | kDeviceGroup;
// And those of the commands that sweep directions over the whole field.
constexpr unsigned kSweptFieldGroups =
    kImageCommandGroups | kSweepGroup | kSamplingGroup | kEarthGroup | kReachGroup;

// One option: parsed, checked and described from here alone.
struct OptionSpec {
  const char* name;        // "--output"
  const char* short_name;  // "-o", or nullptr
  const char* value;       // what the help calls its value ("FILE"); nullptr: a flag
  OptionGroup group;
  bool repeats;      // each use adds one more (--observer); else once at most
  const char* help;  // lines; the help indents the second and later ones
  // Parses `value` (typed after the flag `typed`) into the field it binds; throws UsageError.
  void (*bind)(const std::string& typed, const std::string& value, RunArguments& run);
};

// Every option, in the order the help lists them.
const std::vector<OptionSpec>& optionTable();

// One command.
struct CommandSpec {
  Command id;
  const char* name;         // canonical: the library's word, hyphenated ("sky-view-factor")
  const char* alias;        // its earlier name, which keeps working ("svf"), or nullptr
  const char* summary;      // the command list's line(s)
  const char* usage;        // what follows "hfvis NAME " on the usage line(s)
  const char* description;  // its help: what it writes, in which units
  const char* notes;        // its method and conventions, in its help and the overview; or nullptr
  unsigned groups;          // the OptionGroups it takes
  // Its checks across its options and the library's of its options, after parsing; throws
  // UsageError, naming the command as typed (`name`). nullptr: only the shared ones.
  void (*check)(const std::string& name, const RunArguments& run);
  // The lowest value its outputs hold, which a --nodata value must lie below; nullptr: 0.
  double (*lowest_value)(const RunArguments& run);
  int (*run)(const CommandLine& line);
  // The name its outputs record in hfvis:command: the name they have always recorded (the alias
  // where there is one), so that readers of earlier outputs see the same value.
  const char* recordedName() const { return alias ? alias : name; }
};

// Every command but help, in the order the help lists them.
const std::vector<const CommandSpec*>& commandTable();
const CommandSpec& commandSpec(Command command);
// The command called `name` (its name or its alias), or nullptr.
const CommandSpec* findCommand(const std::string& name);
// "horizon, sky-view-factor, ... or devices": every command's name, for messages.
std::string commandList();

// The entries, each defined in its command's file under cli/commands/.
extern const CommandSpec kHorizonCommand, kSkyViewFactorCommand, kAmbientOcclusionCommand,
    kIntervisibilityCommand, kHorizonListsCommand, kBounceCommand, kShadeCommand, kInsolationCommand,
    kViewshedCommand, kAreaLightCommand, kRegionCommand, kPvsCommand, kSunPositionCommand, kDevicesCommand;

}  // namespace hfvis::cli
