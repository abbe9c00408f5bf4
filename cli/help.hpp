// cli/help.hpp: the texts of `hfvis --help` and `hfvis COMMAND --help`.
#pragma once

#include <string>

#include "arguments.hpp"

namespace hfvis::cli {

// The overview: commands, options, conventions and units, exit status.
std::string generalHelp();

// One command's usage, options and the meaning and units of its output.
std::string commandHelp(Command command);

}  // namespace hfvis::cli
