// environment_swaths.hpp: what an environment's tables need from a run's directions (the horizon
// routine, which computes environment light in its sweep, and the scalar reference share it):
// per direction, the swaths of azimuth it integrates, relative to its own azimuth, and where
// they fall among the map's columns.
#pragma once

#include <array>
#include <vector>

#include "hfvis/environment_map.hpp"
#include "core/lattice_geometry.hpp"

namespace hfvis::detail {

// Floats per band and channel of a table (HFVIS_ENV_TERMS in kernels/environment_light.cl).
constexpr int kEnvTerms = 6;

// As environment_tables in kernels/environment_light.cl takes them: bins (lo, hi, edge, column) as
// float4, spans (first bin, bins) as int2 per direction.
struct EnvironmentSwaths {
  std::vector<std::array<float, 4>> bins;
  std::vector<std::array<int, 2>> spans;
};

// Direction k (hfvis azimuth directions[k].azimuth, the one its normals' components are taken
// along) integrates the azimuths from halfway to the previous direction to halfway to the next
// (halfGapWeights), and those of every direction merged into its step (weight 0, its sweep
// skipped: setQuadratureWeights).
EnvironmentSwaths environmentSwaths(const EnvironmentMap& map, const std::vector<LatticeDirection>& directions);

}  // namespace hfvis::detail
