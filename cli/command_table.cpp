// cli/command_table.cpp: the list of commands (each entry lives in its file under cli/commands/).
#include "table.hpp"

namespace hfvis::cli {

const std::vector<const CommandSpec*>& commandTable() {
  static const std::vector<const CommandSpec*> table{
      &kHorizonCommand,         &kSkyViewFactorCommand, &kAmbientOcclusionCommand,
      &kIntervisibilityCommand, &kHorizonListsCommand,  &kBounceCommand,
      &kShadeCommand,           &kInsolationCommand,    &kViewshedCommand,
      &kAreaLightCommand,       &kRegionCommand,        &kPvsCommand,
      &kSunPositionCommand,
      &kDevicesCommand,
  };
  return table;
}

const CommandSpec& commandSpec(Command command) {
  for (const CommandSpec* spec : commandTable())
    if (spec->id == command) return *spec;
  throw std::logic_error("no command table entry");  // (every Command but Help has one)
}

const CommandSpec* findCommand(const std::string& name) {
  for (const CommandSpec* spec : commandTable())
    if (name == spec->name || (spec->alias && name == spec->alias)) return spec;
  return nullptr;
}

std::string commandList() {
  const std::vector<const CommandSpec*>& table = commandTable();
  std::string list;
  for (std::size_t i = 0; i < table.size(); ++i)
    list += (i == 0 ? "" : i + 1 == table.size() ? " or " : ", ") + std::string(table[i]->name);
  return list;
}

}  // namespace hfvis::cli
