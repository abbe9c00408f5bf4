// image_reading.hpp: what the two image readers share, so that an EXR (exr_images.cpp) and a
// PNG or other image (oiio_images.cpp) are refused and named alike: the checks of a header's
// size before any pixel is read, the choice of one channel, and the form of a library's error.
// Inline: the OpenImageIO module (oiio_images.cpp) links no other part of the library.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "hfvis/errors.hpp"

namespace hfvis::detail {

// The largest image read when the caller sets no limit (max_image_bytes = 0).
constexpr std::uint64_t kDefaultMaxImageBytes = std::uint64_t(64) << 30;

// A library's error strings sometimes end in a newline; a reason reads better without it.
inline std::string withDetail(const std::string& reason, std::string detail) {
  while (!detail.empty() && (detail.back() == '\n' || detail.back() == ' ')) detail.pop_back();
  return detail.empty() ? reason : reason + " (" + detail + ")";
}

// Refuses an image without pixels or channels, and one of 2^31 pixels or more: the kernels index
// pixels with 32-bit integers (computeHorizons refuses larger fields), so it is refused before
// any of it is read.
inline void requirePixelCount(const std::string& path, std::int64_t width, std::int64_t height,
                              int channels) {
  if (width <= 0 || height <= 0 || channels <= 0) {
    throw IoError(path, "image is empty (" + std::to_string(width) + " x " + std::to_string(height) +
                            " pixels, " + std::to_string(channels) + " channels)");
  }
  if (static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height) >= (std::uint64_t(1) << 31)) {
    throw IoError(path, "image is " + std::to_string(width) + " x " + std::to_string(height) +
                            " pixels; hfvis reads fields below 2^31 pixels (split it into tiles)");
  }
}

// Refuses what a header claims before a reader allocates for it (a damaged or hostile header can
// claim terabytes in a few bytes): `rows` rows of `row_bytes` bytes, all channels as stored, where
// `rows` counts what the reader buffers at once (a TIFF's strip, a tile, an EXR chunk may claim
// more rows than the image has), against max_image_bytes (0 = kDefaultMaxImageBytes).
inline void requireClaimWithin(const std::string& path, std::uint64_t max_image_bytes, int width, int height,
                               int channels, std::uint64_t row_bytes, std::uint64_t rows) {
  const std::uint64_t limit = max_image_bytes ? max_image_bytes : kDefaultMaxImageBytes;
  std::uint64_t claim = 0;
  if (__builtin_mul_overflow(row_bytes, rows, &claim) || claim > limit) {
    throw IoError(path, "image claims " + std::to_string(width) + " x " + std::to_string(height) +
                            " pixels of " + std::to_string(channels) + " channels, more than the " +
                            std::to_string(limit >> 20) + " MiB read at most");
  }
}

// The index of the channel `choice` names among `names`: a name, or a zero-based index; "" is
// the only channel of a one-channel image. Throws IoError listing the channels otherwise.
inline int chooseChannel(const std::string& path, const std::vector<std::string>& names,
                         const std::string& choice) {
  std::string available = std::to_string(names.size()) + " channels: ";
  for (std::size_t i = 0; i < names.size(); ++i) available += (i > 0 ? ", '" : "'") + names[i] + "'";
  if (choice.empty()) {
    if (names.size() == 1) return 0;
    throw IoError(path,
                  "image has " + available + "; choose one by name or zero-based index (hfvis --channel)");
  }
  for (std::size_t c = 0; c < names.size(); ++c)
    if (names[c] == choice) return static_cast<int>(c);
  if (choice.size() <= 9 &&
      std::all_of(choice.begin(), choice.end(), [](char ch) { return ch >= '0' && ch <= '9'; })) {
    const std::size_t index = std::stoul(choice);
    if (index < names.size()) return static_cast<int>(index);
  }
  throw IoError(path, "no channel '" + choice + "' (image has " + available + ")");
}

// Refuses radiance read from an image of integers (ImageChannels::integers: an 8- or 16-bit
// image, a GDAL band of integers without a scale or offset), `what` naming it ("an environment
// map"): its stored values 0 .. 255 were taken as radiance, 256 times the float image's, exit 0.
// Radiance is linear floats; a light image's colours, in the output's units, may be integers.
inline void requireFloatRadiance(bool integers, const std::string& path, const std::string& what) {
  if (integers)
    throw IoError(path, what +
                            " holds integers (an 8- or 16-bit image), which would be taken as radiance at "
                            "their stored values (0 .. 255, 0 .. 65535): give linear floats (EXR, HDR, a "
                            "float TIFF), e.g. oiiotool IN --colorconvert sRGB linear -d float -o OUT.exr");
}

}  // namespace hfvis::detail
