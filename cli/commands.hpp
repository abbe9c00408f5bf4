// cli/commands.hpp: what each hfvis subcommand does once its arguments are valid.
#pragma once

#include "arguments.hpp"

namespace hfvis::cli {

// `hfvis devices`: prints the device table to stdout. Returns the exit status.
int runDevices();
// "hfvis sunpos": prints "azimuth=<deg> elevation=<deg>".
int runSunPosition(const SunArguments& sun);
// "hfvis shade": the part of the sun's disc each pixel sees and the direct irradiance.
int runShade(const RunArguments& run);

// "hfvis insolation": sunshine hours and direct irradiation over a span of time.
int runInsolation(const RunArguments& run);
int runViewshed(const RunArguments& run);

// `hfvis horizon|svf|ao`: reads the input, computes on the device, writes every output
// (all or none). Throws hfvis::Error on failure. Returns the exit status.
int runCompute(Command command, const RunArguments& run);

// `hfvis viewcount`: visible counts and areas (and --stats), as runCompute.
int runViewCount(const RunArguments& run);

// `hfvis horizons`: the horizon lists of the --at receivers, as JSON or CSV by the
// extension of -o. Throws UsageError for a receiver outside the field.
int runHorizonLists(const RunArguments& run);

// `hfvis bounce`: the irradiance of one diffuse bounce of the --radiance image.
int runBounce(const RunArguments& run);

}  // namespace hfvis::cli
