// bench/pvs_bench.hpp: the potentially visible sets (hfvis/pvs.hpp) measured: the ray caster's
// rays per second, and per sampler the recall against the dense reference and the pixel error
// (estimated, and measured with random view rays) against samples and time.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hfvis/device.hpp"
#include "hfvis/height_field.hpp"
#include "hfvis/pvs.hpp"

namespace hfvis::bench {

// The benchmark surfaces, `size` x `size`: "city" and "noise" (hfvis_testing's synthetic city DSM
// and rough terrain) and "dem" (the bundled Jacksboro DEM, its top-left corner; `dem_path`).
HeightField pvsBenchField(const std::string& name, int size, const std::string& dem_path);

// Markdown on stdout: rays per second of castHeightFieldRays on each field, `rays` random rays
// from the view band in uniform directions, with and without the view-cell lists (the fastest of
// `reps` calls, the two interleaved).
void pvsRaysReport(const ComputeContext& context, const std::vector<std::string>& fields, int size,
                   const std::string& dem_path, int rays, int reps);

// Markdown on stdout: the caster's shared source compiled as C++ (kernels/shared/heightfield_ray.cl,
// the scalar reference) on one core, on pvsRaysReport's rays in the caster's order (by the 16 x
// 16-cell block of their origin): microseconds of the thread's CPU time per ray with and without
// the view-cell lists (the fastest of `reps`), and a checksum of every result (t's bits, cell,
// list entries and their t's bits), which two builds of the caster agree on where they give the
// same results bit for bit.
void pvsScalarReport(const std::vector<std::string>& fields, int size, const std::string& dem_path, int rays,
                     int reps);

// Markdown on stdout: per field, the dense reference's size and time, then for each sampler and
// budget in `samples` (and seed in `seeds`: the sampler's name gives it where there are several) the recall,
// the estimated and measured pixel error (`check_rays` random view rays), entries and seconds; and AGVS's
// mixture over its last run. Only the samplers in `methods`; without `reference` no dense reference and no
// recall (fields too large for it). `estimate_entries`: PvsOptions::estimate_entries (0: each run ends at
// its budget, so that the samples compared are the samplers' own). `inside`: recall against the dense
// reference inside the tiles too (DenseTargets::InsideTiles), and how many entries only a border sees.
void pvsRecallReport(const ComputeContext& context, const std::vector<std::string>& fields, int size,
                     const std::string& dem_path, int view_cell, int tile,
                     const std::vector<std::uint64_t>& samples, int check_rays,
                     const std::vector<PvsMethod>& methods, bool reference,
                     const std::vector<std::uint32_t>& seeds, std::size_t estimate_entries, bool inside);

}  // namespace hfvis::bench
