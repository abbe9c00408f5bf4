// exr_images.hpp: EXR files through OpenEXR's own library (exr_images.cpp), which image_io.cpp
// uses for every EXR input (found by its magic number) and .exr output. OpenEXR's few libraries
// load in milliseconds, so the library and the CLI link them directly; OpenImageIO
// (oiio_images.hpp) is left to PNG previews and the other images.
#pragma once

#include <cstdint>
#include <string>

#include "hfvis/image_io.hpp"

namespace hfvis::detail {

// Whether the file at `path` begins with OpenEXR's magic number (0x762f3101, "v/1\x01"); false
// for a file that cannot be read.
bool isExrFile(const std::string& path);

// One part of the EXR `path` (the first; in a multi-part file, the one part that holds the
// channel `*channel` names, where another does) as float32 planes (half and float channels as they are,
// unsigned integer channels as their values, not normalised; the data window's pixels, wherever it lies): the
// channel `*channel` names (a name or a zero-based index; "" where the image has one channel), or every
// channel where `channel` is null, in the order OpenImageIO gave them before (see channelOrder in
// exr_images.cpp). attributes: hfvis:cell_size_x and hfvis:cell_size_y where the part has them (strings, or
// numbers as text; another type is refused), and exr:windows where its data window is not its display window
// (a note of both). Throws IoError (unreadable, empty, a deep image, a subsampled channel, 2^31 pixels or
// more, a header claiming more than max_image_bytes, 0 = 64 GiB, or attributes larger than the file; a
// channel it lacks; truncated or corrupt pixels). `rounding`, where given and one channel is read: the most
// float32 may have rounded its values by (a UINT channel's beyond 2^24; 0 for half and float).
ImageChannels readExr(const std::string& path, std::uint64_t max_image_bytes, const std::string* channel,
                      double* rounding = nullptr);

// Writes `image` (checked by the caller: consistent, unique channel names) to `file` as a
// one-part scanline EXR: float32 channels, ZIP compression, the data window at (0, 0), the
// attributes as string attributes. Every write, the flush to the disk and the close are checked.
// Throws IoError naming `path`.
void writeExr(const std::string& file, const std::string& path, const ImageChannels& image);

}  // namespace hfvis::detail
