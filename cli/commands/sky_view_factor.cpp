// cli/commands/sky_view_factor.cpp: "hfvis sky-view-factor" (also "svf"): the fraction of the sky
// each pixel sees (hfvis/horizon.hpp).
#include "swept_horizons.hpp"

namespace hfvis::cli {
namespace {

const HorizonQuantity kSkyViewFactor{
    Command::SkyViewFactor,
    "svf",
    "sky-view factor",
    "sky-view factor 1 - mean_k sin(max(0, elevation_k))",
    "fraction of the sky visible, 0..1",
    &HorizonOutputs::sky_view_factor,
    &HorizonResult::sky_view_factor,
};

}  // namespace

const CommandSpec kSkyViewFactorCommand{
    Command::SkyViewFactor,
    "sky-view-factor",
    "svf",
    "one float32 channel \"svf\": sky-view factor, 0..1",
    "IN -o OUT.exr [-k K | --max-error E] [--error-out ERR.exr] [options]",
    "Writes one float32 channel \"svf\": sky-view factor 1 - mean_k sin(max(0, elevation_k)),\n"
    "the fraction of the sky visible from each pixel (a flat plane gives 1).\n"
    "The preview (--preview) stretches its 1st to 99th percentile over black..white (the\n"
    "summary line prints both ends); NaN (nodata) is black.\n",
    nullptr,
    kSweptFieldGroups | kSweepMethodGroup | kErrorTargetGroup,
    checkHorizonQuantity<kSkyViewFactor>,
    nullptr,
    runHorizonQuantity<kSkyViewFactor>,
};

}  // namespace hfvis::cli
