// environment_fuzzer: libFuzzer over the environment-map reader of "hfvis shade --env". The
// input's first byte picks the file type (EXR, Radiance HDR, PNG, TIFF through GDAL), the rest is
// the file. Reading must give a map that passes validate() or throw hfvis::Error: any other
// exception, a crash or a sanitizer report is a bug.
#include <cstdint>

#include "fuzz_input_file.hpp"
#include "hfvis/environment_map.hpp"
#include "hfvis/errors.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const char* const kExtensions[] = {".exr", ".hdr", ".png", ".tif"};
  const FuzzInputFile file("env", data, size, kExtensions);
  if (!file.written()) return 0;
  try {
    const hfvis::EnvironmentMap map = hfvis::readEnvironmentMap(file.path());
    hfvis::validate(map);  // what the reader returns must pass the library's own checks
  } catch (const hfvis::Error&) {
    // a clear error: what bad files get
  }
  return 0;
}
