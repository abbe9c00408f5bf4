// oiio_images.hpp: what image_io.cpp asks of OpenImageIO, as a table of functions: reading PNG,
// TIFF bytes under another extension and the other images neither GDAL (gdal_io.hpp) nor
// OpenEXR (exr_images.hpp) takes, and writing 8-bit previews. The library links them
// (oiio_images.cpp); the CLI loads the same code as a module on its first such image
// (cli/oiio_module.cpp), so that a run on GeoTIFFs and EXRs never loads OpenImageIO and the ~250
// shared libraries it pulls in (a quarter of a second at every start, measured on the test
// machines).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "hfvis/image_io.hpp"

namespace hfvis::detail {

struct OiioImages {
  // Subimage 0 of `path` as stored values (integers not normalised): the channel `*channel`
  // names (a name or a zero-based index; empty where the image has one channel), or every
  // channel where `channel` is null. attributes: the image's hfvis:cell_size_x and
  // hfvis:cell_size_y strings where it has them. Throws IoError (unreadable, empty, a volume or
  // deep image, 2^31 pixels or more, a header claiming more than max_image_bytes, 0 = 64 GiB;
  // a channel it lacks).
  ImageChannels (*read)(const std::string& path, std::uint64_t max_image_bytes, const std::string* channel);
  // Whether OpenImageIO has a writer for the extension of `path`.
  bool (*can_write)(const std::string& path);
  // Writes width x height pixels of names.size() 8-bit channels to `file`, the rows from
  // fill_rows(y_begin, y_end, buffer) in chunks. Throws IoError naming `path`.
  void (*write)(const std::string& file, const std::string& path, int width, int height,
                const std::vector<std::string>& names,
                const std::function<void(int, int, std::uint8_t*)>& fill_rows);
};

// The table: oiio_images.cpp's own functions in the library, the module's in the CLI.
const OiioImages& oiioImages();

}  // namespace hfvis::detail

// The module's entry point (the same table).
extern "C" const hfvis::detail::OiioImages* hfvis_oiio_images();
