// cli/commands.hpp: what each hfvis subcommand does once its arguments are valid.
#pragma once

#include "arguments.hpp"

namespace hfvis::cli {

// `hfvis devices`: prints the device table to stdout. Returns the exit status.
int runDevices();

// `hfvis horizon|svf|ao`: reads the input, computes on the device, writes every output
// (all or none). Throws hfvis::Error on failure. Returns the exit status.
int runCompute(Command command, const RunArguments& run);

}  // namespace hfvis::cli
