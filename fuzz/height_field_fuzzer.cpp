// height_field_fuzzer: libFuzzer over the height-field loader. The input's first byte picks
// the file's extension (.exr, .png, .tif through GDAL, or .hdr), the rest is the file: TIFF bytes
// go to GDAL and EXR bytes to OpenEXR under any of the others, the rest to OpenImageIO, which
// guesses the format from the bytes. Reading must either give a valid field or throw hfvis::Error: any other
// exception, a crash or a sanitizer report is a bug.
#include <cstdint>

#include "fuzz_input_file.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/height_field.hpp"
#include "hfvis/image_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const char* const kExtensions[] = {".exr", ".png", ".tif", ".hdr"};
  const FuzzInputFile file("height_field", data, size, kExtensions);
  if (!file.written()) return 0;
  try {
    // Images up to 64 MiB as stored: larger claims are refused before reading, as the
    // default 64 GiB limit does for a real run (the fuzzer's memory limit is 4 GiB).
    hfvis::HeightFieldReadOptions options;
    options.max_image_bytes = std::uint64_t(64) << 20;
    const hfvis::HeightField field = hfvis::readHeightField(file.path(), options);
    hfvis::validate(field);  // what the loader returns must pass the library's own checks
  } catch (const hfvis::Error&) {
    // a clear error: what bad files get
  }
  return 0;
}
