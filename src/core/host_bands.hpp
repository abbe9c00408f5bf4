// host_bands.hpp: host-side passes over a field split into bands of rows, one per thread.
//
// The passes a call makes on the host before its kernels (prepareHeights, the region culling
// pyramid, the viewshed's slope tables) are linear in the field: at 4096^2 they were most of a
// one-shot region call and ran on one thread. Each band writes its own rows, and what a pass
// combines over bands (maxima, minima) does not depend on the split, so the result is the same
// on any number of threads.
#pragma once

#include <algorithm>
#include <functional>
#include <thread>
#include <vector>

namespace hfvis::detail {

// The threads a host pass uses: the machine's (at most 8; 1 where it does not say).
inline int hostThreads() {
  return static_cast<int>(std::max(1u, std::min(8u, std::thread::hardware_concurrency())));
}

// Runs body(band, first, last) over [0, count) split into `bands` contiguous bands, each on a
// thread of its own (the first on the calling thread). An exception thrown by a band is rethrown
// here once every band has finished.
void forEachBand(int count, int bands, const std::function<void(int band, int first, int last)>& body);

// The number of bands for a pass over `count` rows of `per_row` values each: one per thread, but
// one in all for passes too small to pay for starting threads (under about a million values).
inline int bandsFor(int count, long long per_row) {
  constexpr long long kValuesPerBand = 1 << 20;
  const long long values = static_cast<long long>(count) * std::max(1LL, per_row);
  return static_cast<int>(std::max(1LL, std::min<long long>(hostThreads(), values / kValuesPerBand)));
}

}  // namespace hfvis::detail
