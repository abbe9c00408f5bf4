// cli/commands/ambient_occlusion.cpp: "hfvis ambient-occlusion" (also "ao"): the light a uniform
// sky sends each pixel (hfvis/horizon.hpp).
#include "swept_horizons.hpp"

namespace hfvis::cli {
namespace {

const HorizonQuantity kAmbientOcclusion{
    Command::AmbientOcclusion,
    "ao",
    "ambient occlusion",
    "ambient occlusion, uniform sky of radiance 1 (Timonen & Westerholm 2010, Eq. 5)",
    "0..1, a flat unoccluded plane gives 1",
    &HorizonOutputs::ambient_occlusion,
    &HorizonResult::ambient_occlusion,
};

}  // namespace

const CommandSpec kAmbientOcclusionCommand{
    Command::AmbientOcclusion,
    "ambient-occlusion",
    "ao",
    "one float32 channel \"ao\": ambient occlusion, 0..1 (1 = unoccluded flat ground)",
    "IN -o OUT.exr [-k K | --max-error E] [--error-out ERR.exr] [options]",
    "Writes one float32 channel \"ao\": ambient occlusion under a uniform sky of radiance 1,\n"
    "normalised so a flat plane gives 1 (0 = fully occluded).\n"
    "The preview (--preview) stretches its 1st to 99th percentile over black..white (the\n"
    "summary line prints both ends); NaN (nodata) is black.\n",
    nullptr,
    kSweptFieldGroups | kSweepMethodGroup | kErrorTargetGroup,
    checkHorizonQuantity<kAmbientOcclusion>,
    nullptr,
    runHorizonQuantity<kAmbientOcclusion>,
};

}  // namespace hfvis::cli
