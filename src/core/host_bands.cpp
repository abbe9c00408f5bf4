// host_bands.cpp: forEachBand (host_bands.hpp).
#include "core/host_bands.hpp"

#include <exception>

namespace hfvis::detail {

void forEachBand(int count, int bands, const std::function<void(int band, int first, int last)>& body) {
  bands = std::max(1, std::min(bands, count));
  if (bands <= 1) {
    if (count > 0) body(0, 0, count);
    return;
  }
  std::vector<std::exception_ptr> failed(bands);
  const auto run = [&](int b) {
    try {
      body(b, static_cast<int>(static_cast<long long>(count) * b / bands),
           static_cast<int>(static_cast<long long>(count) * (b + 1) / bands));
    } catch (...) {
      failed[b] = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(bands - 1);
  int started = 1;
  try {
    for (; started < bands; ++started) pool.emplace_back(run, started);
  } catch (...) {
    // (no thread to be had, or no memory for one: the bands not started run here)
  }
  run(0);
  for (int b = started; b < bands; ++b) run(b);
  for (std::thread& t : pool) t.join();
  for (const std::exception_ptr& e : failed)
    if (e) std::rethrow_exception(e);
}

}  // namespace hfvis::detail
