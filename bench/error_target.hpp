// bench/error_target.hpp: "ask for an error, not a direction count" (HorizonOptions::max_error)
// measured: for each content and each asked error E of the sky-view factor or ambient occlusion,
// the K it chose, its estimate, the error it achieved against an azimuthally dense run of the
// same sweep, its time, and the cheapest fixed K (a multiple of 8) that meets E on that field,
// found by search, with its time measured interleaved with the chosen run's.
#pragma once

#include <string>
#include <vector>

#include "hfvis/device.hpp"
#include "hfvis/height_field.hpp"

namespace hfvis::bench {

struct ErrorTargetField {
  std::string name;
  HeightField field;
};

// Markdown on stdout: one table per output (SVF, AO) with a row per (field, E), and the share
// of rows where the achieved error is at most E, for the whole field at one K
// (HorizonOptions::error_tile 0) and refined in tiles of `tile` pixels. `reference_directions`:
// the dense run's K.
void errorTargetReport(const ComputeContext& context, const std::vector<ErrorTargetField>& fields,
                       const std::vector<double>& errors, int reference_directions, int reps, int tile);

// The same for the visible count of intervisibility (IntervisibilityOptions::max_error,
// relative): one table, its error the 99th percentile over the pixels of the count's error (per
// direction) against the hull tree at K = reference_directions, relative to that reference's mean
// over the field; work: the tree's samples per receiver.
void viewcountTargetReport(const ComputeContext& context, const std::vector<ErrorTargetField>& fields,
                           const std::vector<double>& errors, int reference_directions, int reps);

// The same for the horizon angles (HorizonOptions::max_error with the horizon planes; `errors` in
// degrees): one table, the error the mean over the pixels and azimuths of |the K planes
// interpolated linearly in azimuth - the same sweep at K = reference_directions|
// (detail::horizonAngleErrorAgainst), the cheapest fixed K found by bisection on the ladder.
void horizonTargetReport(const ComputeContext& context, const std::vector<ErrorTargetField>& fields,
                         const std::vector<double>& errors, int reference_directions, int reps);

// Per content and fixed K up to max_directions: the horizon angles' error against the dense run,
// their estimate and its parts (the skip-one and skip-two interpolation errors, the order p).
void horizonErrorCurve(const ComputeContext& context, const std::vector<ErrorTargetField>& fields,
                       int reference_directions, int max_directions);

void errorCurve(const ComputeContext& context, const std::vector<ErrorTargetField>& fields,
                int reference_directions, int max_directions);

// Per content and K = 8 m up to max_directions: the nested set of m copies (detail::computeNestedSet,
// one run; HorizonOptions::max_error's sets) against the uniform set of K directions, both
// outputs' 99th percentile error against the uniform set at reference_directions, and their work.
void nestedCurve(const ComputeContext& context, const std::vector<ErrorTargetField>& fields,
                 int reference_directions, int max_directions);

}  // namespace hfvis::bench
