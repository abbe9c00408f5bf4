// observers_fuzzer: libFuzzer over the observers CSV of "hfvis viewshed --observers" (the whole
// input is the file's text). Parsing must give at least one observer with a whole column and row
// and a finite height, or throw hfvis::Error: any other exception, a crash or a sanitizer
// report is a bug.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>

#include "hfvis/errors.hpp"
#include "observer_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream text(std::string(reinterpret_cast<const char*>(data), size));
  try {
    const auto observers = hfvis::cli::parseObservers("fuzz.csv", text, 2.0, (size & 1) != 0);
    if (observers.empty()) std::abort();
    for (const hfvis::Observer& o : observers)
      if (!std::isfinite(o.height)) std::abort();
  } catch (const hfvis::Error&) {
    // a clear error: what bad files get
  }
  return 0;
}
