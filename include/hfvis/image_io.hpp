// hfvis/image_io.hpp: reading height fields and writing results: GeoTIFF and the other
// georeferenced rasters through GDAL, EXR through OpenEXR, other images through OpenImageIO.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "hfvis/height_field.hpp"

namespace hfvis {

struct HeightFieldReadOptions {
  // Channel to read: "" = the only channel (an error for multi-channel images),
  // else a channel name ("Y", "R", "height") or a zero-based index ("0").
  std::string channel;
  // Ground units per pixel; <= 0 = take it from the file (a raster's geotransform, geographic
  // degrees converted to metres at each row's latitude and at the centre latitude for the
  // field's own cell size, else the hfvis:cell_size_x/y attributes that hfvis and
  // data/make_data.py write) or 1. Given cell sizes make no per-row spacing.
  double cell_size_x = 0.0;
  double cell_size_y = 0.0;
  double z_scale = 1.0;
  // The largest image (all its channels, as stored) read: a larger one is refused before
  // any of it is read, whatever its header claims. 0 = 64 GiB.
  std::uint64_t max_image_bytes = 0;
};

// Reads a height field. Georeferenced rasters (.tif/.tiff, .hgt, .asc, .vrt, .img, .bil, .dem,
// .grd, .adf, by extension in any case, and a regular file of TIFF bytes whatever its name) go
// through GDAL: the band (a zero-based index or a band
// description) is read, its values times its scale plus its offset where it declares them, its
// nodata value and where its mask (a per-dataset mask, an alpha band) says no data NaN, a value
// beyond float32's range an IoError naming its pixel, the cell size comes from the
// geotransform (geographic degrees in metres on WGS84: per row in row_cell_size_x/y, at the
// centre latitude in cell_size_x/y), the geotransform and CRS
// fill `georeference`, and a rotated or sheared geotransform is an IoError. Everything else is
// read without georeference: an EXR (known by its magic number, whatever its name; part 0 of a
// multi-part file, its data window) through OpenEXR, other images (PNG 8/16-bit, ...) through
// OpenImageIO. Integer
// pixels are converted to their stored integer values (a 16-bit PNG holds heights 0..65535), not
// normalised. Throws IoError naming the file and reason (missing, unreadable, truncated,
// zero-sized, multi-channel without a channel choice, unknown channel).
HeightField readHeightField(const std::string& path, const HeightFieldReadOptions& options = {});

// The cell sizes readHeightField gives a latitude / longitude raster of geotransform
// `geotransform` (degrees, north-up or south-up): each row's in metres on the WGS84 ellipsoid at
// its pixel centres' latitude (row_cell_size_x/y, field.height entries), and cell_size_x/y those
// at the centre latitude. For fields made in memory (the Python package's DataArrays). Throws
// InvalidArgument when the rows reach beyond the poles.
void setGeographicCellSizes(HeightField& field, const std::array<double, 6>& geotransform);

// One float32 image to write (or read by readImage): planar channels of width*height values each.
struct ImageChannels {
  int width = 0;
  int height = 0;
  std::vector<std::string> names;                               // one per channel
  std::vector<std::vector<float>> planes;                       // one per channel, row-major
  std::vector<std::pair<std::string, std::string>> attributes;  // string metadata
  // Read: whether a channel holds integers taken as their stored values (an 8- or 16-bit PNG's
  // 0 .. 255 or 0 .. 65535; a GDAL band of integers without a scale or offset), so that readers of
  // radiance can refuse them.
  bool integers = false;
  // GeoTIFF only (other formats have neither): where the image lies, and the value its NaN
  // (nodata) cells hold, declared as every band's nodata value. NaN keeps them NaN.
  Georeference georeference;
  float nodata = std::numeric_limits<float>::quiet_NaN();
};

// Reads every channel of an image as float32 planes with their names. Rasters GDAL reads (the
// extensions of readHeightField) give their bands in order, named by their descriptions
// ("channel<i>" where a band has none), scaled and offset as readHeightField's, nodata cells as
// NaN (not the mask: an alpha band is a channel, readColourImage ignores it), the dataset's metadata items as
// attributes (hfvis_NAME back as hfvis:NAME, see writeImage) and their georeference. Other
// images give their channels in the order OpenImageIO reports them; for EXR the same order
// (layers sorted; within each R, G, B, Y, A, Z and their kin first, then the others sorted by
// name). Integer pixels are read as their stored values, as
// readHeightField. Throws IoError as readHeightField.
ImageChannels readImage(const std::string& path);

// The files reading `path` opens: `path` itself, and for a raster GDAL reads, the files it reads
// beside it (a VRT's sources, nested VRTs' too; sidecars such as a world file), so that an output
// can be kept from replacing any of them. Throws IoError where a VRT names a source that is not a
// regular file (a FIFO, a device: reading it would block) or standard input.
std::vector<std::string> filesRead(const std::string& path);

// Reads a colour image (readImage): its R, G, B channels in that order (an alpha channel A beside
// them ignored), or its only channel, named "Y". Throws IoError as readImage, and naming `what`
// ("an environment map") for an image with other channels or an EXR whose data window is not its
// display window (the image covers its whole extent: a sphere, a light's rectangle). Keeps
// ImageChannels::integers (readEnvironmentMap refuses them: radiance is linear floats).
ImageChannels readColourImage(const std::string& path, const std::string& what);

// Whether writeImage writes `path` as a GeoTIFF through GDAL: its name ends in .tif or .tiff,
// in any case.
bool writesGeoTiff(const std::string& path);

// Throws IoError when no image writer handles the extension of `path` (nothing is created):
// to refuse an output before computing it.
void requireImageWriter(const std::string& path);

// Throws IoError naming `path` when hfvis must not write an output there, before anything is
// computed: its directory is missing or takes no new files for this user (a file is created there
// and removed at once to know: /proc passes the superuser's access check), or a file is there that
// is a directory or not a regular file, or that is protected: one the effective user may not
// write (access(2) with AT_EACCESS), one with no write permission for anybody (mode 0444; the
// superuser may write anything, so the mode bits are the owner's statement), or one marked
// immutable or append-only (chattr +i, +a). Replacing a file by renaming a new one over it
// would otherwise bypass every one of these. A symbolic link at `path` is followed: what it
// names is checked (and replaced; the link stays).
void requireReplaceable(const std::string& path);

// Outputs written all together or not at all. Each is written whole to a temporary file beside
// its target (the file a symbolic link names, for a link), every write, the flush to the disk
// and the close checked; commit() then checks every target again (requireReplaceable) and
// renames each file into place, keeping the mode of the file it replaces. When a rename fails,
// the files already renamed are put back as they were (the previous files restored, new ones
// removed), so a failure leaves every file that existed before exactly as it was. A GeoTIFF
// replaces the files GDAL reads beside it as part of it too, as GDAL's own drivers delete them
// with the file they belong to: its auxiliary metadata (FILE.aux.xml, FILE.aux: a nodata value,
// scale, offset, even a georeference, which GDAL prefers to the file's own), overviews
// (FILE.ovr) and mask (FILE.msk); left in place, a reader took the new file with the old one's
// nodata and scale. They are set aside as the previous file is and removed once every output is
// in place; so are a TIFF's world files (STEM.tfw, STEM.tifw, STEM.tiffw: a stale one gave a new
// file without georeferencing the old one's cells). (STEM.wld, which any image of that stem may
// own, stays.) Files named by protect() are never replaced: checked as each output is staged and
// again right before its rename, since a path may change during a long run (a link made to an
// input). Whatever is not committed is removed by the destructor, and by the signals that end
// the process where removeTemporaryOutputsOnSignals() is in force (a signal during commit() waits
// for its end).
class OutputFiles {
 public:
  OutputFiles() = default;
  OutputFiles(const OutputFiles&) = delete;
  OutputFiles& operator=(const OutputFiles&) = delete;
  ~OutputFiles();

  // Each stages one file, and throws as writeImage does (and InvalidArgument for a file staged
  // twice). image: what writeImage writes.
  void image(const std::string& path, const ImageChannels& image);
  // An 8-bit PNG preview of one plane, linearly mapped from [lo, hi] to [0, 255] (lo == hi: the
  // plane's finite min and max); NaN pixels are drawn black.
  void previewPng(const std::string& path, int width, int height, const std::vector<float>& plane,
                  float lo = 0.0f, float hi = 0.0f);
  // An 8-bit PNG preview of HDR planes (one grey, or three R, G, B of width*height values):
  // exposed so that the log-average luminance (Reinhard et al. 2002's key) maps to 0.3 (`exposure`
  // stops more or less), through the ACES filmic curve per channel (Narkowicz's 2015 fit), then
  // the sRGB transfer curve. NaN pixels are drawn black.
  void toneMappedPng(const std::string& path, int width, int height,
                     const std::vector<std::vector<float>>& planes, double exposure = 0.0);
  // The bytes as they are.
  void text(const std::string& path, const std::string& text);

  // The files at `inputs` as they are now (those that exist; links followed), which no output
  // may replace, whatever path comes to name them later.
  void protect(const std::vector<std::string>& inputs);
  // The paths staged so far, in order.
  std::vector<std::string> paths() const;
  // Moves every staged file into place, or none (see above); throws IoError naming the output
  // that could not be.
  void commit();

 private:
  struct Entry {
    std::string path, target, temp;
    bool geotiff = false;  // its side files go with the file it replaces (see above)
  };
  // Stages `path`: write(temp) writes the file's contents to the temporary path.
  void stage(const std::string& path, const std::function<void(const std::string&)>& write,
             bool geotiff = false);
  void discard() noexcept;
  // Throws IoError naming `path` where `file` is now one of the protected inputs.
  void requireNotAnInput(const std::string& path, const std::string& file) const;
  std::vector<Entry> entries_;
  struct Protected {
    std::string path;
    dev_t device;
    ino_t inode;
  };
  std::vector<Protected> inputs_;
};

// Installs handlers of SIGINT, SIGTERM, SIGHUP and the other signals that end a process by default
// (SIGXCPU, SIGALRM, SIGUSR1, SIGPIPE, ...; those whose default is in force: nohup's ignored
// SIGHUP and a program's own handlers stay)
// that remove the temporary files of unfinished outputs, then end the process of the same
// signal as before. For programs (the hfvis CLI installs them); a library never sets handlers.
void removeTemporaryOutputsOnSignals();

// Writes `image` as a single OutputFiles output: to a temporary file beside `path`, renamed
// into place only when complete (a failure leaves nothing behind and an existing `path` as it
// was; a protected `path` is refused, as requireReplaceable).
// - .tif/.tiff: a GeoTIFF through GDAL: one float32 band per channel, its description the
//   channel's name; the georeference's geotransform and CRS where it has them; every band's
//   nodata value `image.nodata`, written into the NaN cells; DEFLATE with the floating-point
//   predictor, 256 x 256 tiles, bands stored one after another, BigTIFF when the size needs
//   it. Attributes become the dataset's metadata items, each ':' of a name written as '_'
//   (GDAL's name=value lists take ':' for a separator): hfvis:units becomes hfvis_units.
// - .exr: an EXR through OpenEXR: float32 channels, ZIP compression, the attributes as string
//   attributes; no georeference, NaN in nodata cells.
// Throws InvalidArgument for an inconsistent image, IoError when writing fails.
void writeImage(const std::string& path, const ImageChannels& image);

}  // namespace hfvis
