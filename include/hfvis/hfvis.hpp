// hfvis/hfvis.hpp: everything a user of the library calls, in one include.
//
//   hfvis/version.hpp          HFVIS_VERSION_STRING, versionString()
//   hfvis/errors.hpp           the exceptions every call may throw
//   hfvis/device.hpp           listDevices(), ComputeContext
//   hfvis/height_field.hpp     HeightField (heights, cell size, nodata)
//   hfvis/sweep_options.hpp    directions, samples per unit, memory budget, progress
//   hfvis/horizon.hpp          computeHorizons: horizon angles and distances (and any of the
//                              outputs below that share the sweep, in one run)
//   hfvis/sky_view_factor.hpp  computeSkyViewFactor: the share of the sky each point sees
//   hfvis/ambient_occlusion.hpp computeAmbientOcclusion: the light of a uniform sky
//   hfvis/horizon_lists.hpp    the visibility horizons of chosen receivers
//   hfvis/intervisibility.hpp  computeIntervisibility: visible counts and areas (hull tree)
//   hfvis/bounce.hpp           one diffuse bounce over the visible surface
//   hfvis/environment_map.hpp  EnvironmentMap: an HDR sky as an equirectangular image
//   hfvis/environment_light.hpp computeEnvironmentLight: the irradiance from an HDR sky
//   hfvis/sun_shading.hpp      computeSunShading: the sun's light with cast shadows
//   hfvis/insolation.hpp       computeInsolation: sunshine hours and irradiation over a span of time
//   hfvis/sun.hpp              where the sun stands at a time and place
//   hfvis/region_visibility.hpp computeRegionVisibility: which samples of a region each point sees
//   hfvis/pvs.hpp              computePvs: the tiles each view cell can see (potentially visible sets)
//   hfvis/viewshed.hpp         computeViewshed, computeCumulativeViewshed: what observers see
//   hfvis/image_io.hpp         reading height fields, writing float EXRs and PNG previews
//
// The scalar references of the kernels and the synthetic test fields are in the test support
// library (testing/, hfvis_testing), which is not installed.
#pragma once

#include "hfvis/ambient_occlusion.hpp"
#include "hfvis/bounce.hpp"
#include "hfvis/device.hpp"
#include "hfvis/environment_light.hpp"
#include "hfvis/environment_map.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/height_field.hpp"
#include "hfvis/horizon.hpp"
#include "hfvis/horizon_lists.hpp"
#include "hfvis/image_io.hpp"
#include "hfvis/insolation.hpp"
#include "hfvis/intervisibility.hpp"
#include "hfvis/region_visibility.hpp"
#include "hfvis/pvs.hpp"
#include "hfvis/sky_view_factor.hpp"
#include "hfvis/sun_shading.hpp"
#include "hfvis/sun.hpp"
#include "hfvis/sweep_options.hpp"
#include "hfvis/viewshed.hpp"
#include "hfvis/version.hpp"
