// gdal_io.cpp: georeferenced rasters through GDAL (see gdal_io.hpp).
#include "io/gdal_io.hpp"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_minixml.h>
#include <cpl_string.h>
#include <gdal.h>
#include <ogr_srs_api.h>
#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/number_text.hpp"
#include "hfvis/errors.hpp"
#include "io/output_files.hpp"

namespace hfvis::detail {
namespace {

constexpr std::uint64_t kDefaultMaxImageBytes = std::uint64_t(64) << 30;
// GeoTIFF blocks: square tiles, what GIS tools read windows and overviews from fastest.
constexpr int kTileSize = 256;

void registerOnce() {
  static std::once_flag once;
  std::call_once(once, [] {
    GDALAllRegister();
    CPLSetErrorHandler(CPLQuietErrorHandler);  // errors are reported through IoError
  });
}

std::string lastError() {
  const char* message = CPLGetLastErrorMsg();
  return message && *message ? message : "GDAL cannot read it";
}

struct DatasetCloser {
  void operator()(void* dataset) const { GDALClose(dataset); }
};
using Dataset = std::unique_ptr<void, DatasetCloser>;

// Whether [p, end) is a plain decimal number as a whole: [+-] digits [. digits] [e [+-] digits],
// with a digit before or after the point. strtod reads such a token whole, so the check below
// asks strtod only of the others (hex, inf, nan, not numbers): strtod's full conversion of every
// value, a map look-up and a byte-by-byte copy of each token made the check cost half of GDAL's
// own read of a large grid.
bool plainDecimal(const char* p, const char* end) {
  const auto digits = [&] {
    const char* first = p;
    while (p < end && *p >= '0' && *p <= '9') ++p;
    return p > first;
  };
  if (p < end && (*p == '+' || *p == '-')) ++p;
  bool some = digits();
  if (p < end && *p == '.') {
    ++p;
    some = digits() || some;
  }
  if (!some) return false;
  if (p < end && (*p == 'e' || *p == 'E')) {
    ++p;
    if (p < end && (*p == '+' || *p == '-')) ++p;
    if (!digits()) return false;
  }
  return p == end;
}

// GDAL's ASCII grid readers (ESRI's and GRASS's) take a value that is not a number as 0 or as its
// leading digits (`abc` became ground at height 0, `1,5` at 1), and read the values in order
// whatever the lines (a missing last value became 0; 17 a row under ncols 16 sheared the grid).
// So every value after the header must be a number as a whole (strtod's forms, nan and inf
// included: those are refused later as heights) or GRASS's null token, and there must be as many
// as the header's columns times rows. The header: the lines before the first value, each led by
// one of the formats' keys ("key value", or GRASS's "key: value" and "key:value").
void requireNumbersInAsciiGrid(const std::string& path) {
  static const char* const kKeys[] = {"ncols",     "nrows",    "xllcorner", "xllcenter", "yllcorner",
                                      "yllcenter", "cellsize", "dx",        "dy",        "nodata_value",
                                      "north",     "south",    "east",      "west",      "rows",
                                      "cols",      "null",     "type",      "multiplier"};
  std::ifstream in(path, std::ios::binary);
  std::vector<char> buffer(std::size_t(1) << 20);
  std::string token, key;  // key: the header line's, until its value
  std::map<std::string, std::string> values_of;
  std::map<std::string, long long> line_of;  // each header key's line
  bool header = true, line_start = true;
  long long line = 1, count = 0;
  const auto check = [&]() {
    if (token.empty()) return;
    if (header && line_start) {
      const std::size_t colon = token.find(':');
      key = token.substr(0, colon);
      std::transform(key.begin(), key.end(), key.begin(), [](unsigned char c) { return std::tolower(c); });
      if (std::find_if(std::begin(kKeys), std::end(kKeys), [&](const char* k) { return key == k; }) ==
          std::end(kKeys)) {
        header = false;
        key.clear();
      } else if (colon != std::string::npos && colon + 1 < token.size()) {
        values_of[key] = token.substr(colon + 1);
        line_of[key] = line;
        key.clear();
      }
      if (header) {
        line_start = false;
        token.clear();
        return;
      }
    } else if (header && !key.empty()) {
      values_of[key] = token;
      line_of[key] = line;
      key.clear();
      token.clear();
      return;
    }
    line_start = false;
    if (!header) {
      const char* end = token.c_str() + token.size();
      if (!plainDecimal(token.c_str(), end)) {
        char* read_to = nullptr;
        std::strtod(token.c_str(), &read_to);
        end = read_to;
      }
      if ((token.size() > 256 || end != token.c_str() + token.size()) &&
          !(values_of.count("null") && token == values_of["null"]))
        throw IoError(
            path, "line " + std::to_string(line) + ": '" + token.substr(0, 40) +
                      "' is not a number (GDAL's ASCII grid reader would read 0 or its leading digits; write "
                      "nodata as the number the header names)");
      ++count;
    }
    token.clear();
  };
  const auto space = [](char c) {
    return c == ' ' || c == '\n' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
  };
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const char *p = buffer.data(), *end = p + in.gcount();
    while (p < end) {
      const char* q = p;
      while (q < end && !space(*q)) ++q;
      // (a token longer than 256 is cut at 257, and is no number then)
      token.append(p, std::min<std::size_t>(q - p, 257 - std::min<std::size_t>(token.size(), 257)));
      if (q == end) break;  // (the token may go on in the next block)
      check();
      if (*q == '\n') ++line, line_start = true;
      p = q + 1;
    }
  }
  check();
  // The header's values are numbers too (GDAL read `NODATA_value abc` as 0, making every height 0
  // a hole, and `xllcorner abc` as 0, exit 0), but for GRASS's type and null token.
  for (const auto& [name, value] : values_of) {
    if (name == "type" || name == "null") continue;
    char* read_to = nullptr;
    std::strtod(value.c_str(), &read_to);
    if (value.size() > 256 || read_to != value.c_str() + value.size())
      throw IoError(
          path, "line " + std::to_string(line_of[name]) + ": the header's " + name + " '" +
                    value.substr(0, 40) + "' is not a number" +
                    (value.find(',') != std::string::npos ? " (write a decimal point, not a comma)" : "") +
                    " (GDAL's ASCII grid reader would read 0 or its leading digits)");
  }
  const auto whole = [&](const char* name, const char* other) -> long long {
    const auto found = values_of.count(name) ? values_of.find(name) : values_of.find(other);
    return found == values_of.end() ? -1 : std::atoll(found->second.c_str());
  };
  const long long columns = whole("ncols", "cols"), rows = whole("nrows", "rows");
  if (columns > 0 && rows > 0 && count != columns * rows)
    throw IoError(path, "it holds " + std::to_string(count) + " values where its header says " +
                            std::to_string(columns) + " columns of " + std::to_string(rows) +
                            " rows (GDAL would read them in order, shifting every row after a missing or an "
                            "extra one)");
}

// Whether `path` is a VRT: "<VRTDataset" within its first 1024 bytes (as GDAL knows one, whatever
// its name, an XML prolog before it or not).
bool isVrt(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(1024, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  return head.find("<VRTDataset") != std::string::npos;
}

// The files a VRT's XML names as sources, depth first: every SourceFilename and SourceDataset (a
// warped VRT's), relative to the VRT where relativeToVRT says so (GDAL's own reading of it).
void vrtSourceNames(const CPLXMLNode* node, const std::filesystem::path& directory,
                    std::vector<std::string>* names) {
  for (; node; node = node->psNext) {
    if (node->eType != CXT_Element) continue;
    const std::string element = node->pszValue;
    if (element == "SourceFilename" || element == "SourceDataset") {
      const char* text = CPLGetXMLValue(node, nullptr, "");
      const bool relative = CPLTestBool(CPLGetXMLValue(node, "relativeToVRT", "0"));
      const std::string name = text ? text : "";
      if (!name.empty())
        names->push_back(relative && !std::filesystem::path(name).is_absolute() ? (directory / name).string()
                                                                                : name);
    }
    vrtSourceNames(node->psChild, directory, names);
  }
}

// A file that blocks or never ends when opened and read: a FIFO, a socket, a device.
bool blocksOnRead(mode_t mode) { return S_ISFIFO(mode) || S_ISSOCK(mode) || S_ISCHR(mode) || S_ISBLK(mode); }

// The local file a GDAL dataset name reads, through the wrappers that name one ("vrt://PATH?...",
// "GTIFF_DIR:N:PATH", "/vsisubfile/OFFSET_SIZE,PATH", "/vsigzip/PATH", an archive's
// "/vsizip/PATH/member"); "" where it names none (a network or memory file). A source spelt so had
// been no input (an output replaced it) and a FIFO behind it blocked the read.
std::string localFileOf(std::string name) {
  for (int unwrap = 0; unwrap < 8; ++unwrap) {
    if (name.rfind("vrt://", 0) == 0) {
      name = name.substr(6, name.find('?') == std::string::npos ? std::string::npos : name.find('?') - 6);
    } else if (name.rfind("GTIFF_DIR:", 0) == 0 && name.find(':', 10) != std::string::npos) {
      name = name.substr(name.find(':', 10) + 1);
    } else if (name.rfind("/vsisubfile/", 0) == 0 && name.find(',') != std::string::npos) {
      name = name.substr(name.find(',') + 1);
    } else if (name.rfind("/vsigzip/", 0) == 0) {
      name = name.substr(8);
    } else if (name.rfind("/vsizip/", 0) == 0 || name.rfind("/vsitar/", 0) == 0 ||
               name.rfind("/vsi7z/", 0) == 0 || name.rfind("/vsirar/", 0) == 0) {
      // the archive: the longest leading part of the path that is not a directory
      std::filesystem::path rest = name.substr(name.find('/', 1)), archive;
      std::string found;
      for (const auto& part : rest) {
        archive /= part;
        struct stat status {};
        if (::stat(archive.c_str(), &status) == 0 && !S_ISDIR(status.st_mode)) found = archive.string();
        if (!found.empty()) break;
      }
      return found;
    } else if (name.rfind("/vsi", 0) == 0) {
      return "";  // (/vsicurl/, /vsimem/, /vsis3/ ...: not a local file)
    } else {
      return name;
    }
  }
  return "";
}

// GDAL opens files beside a raster by its name (an overview, a mask, auxiliary metadata, a world
// file, a projection): a FIFO there blocked the read for good. Refuses (IoError naming `path`) one
// that is a FIFO, a socket or a device.
void requireRegularSidecars(const std::string& path, const std::string& file) {
  static const char* const kSuffixes[] = {".aux.xml", ".ovr",   ".msk", ".aux",    ".prj", ".tfw",
                                          ".tifw",    ".tiffw", ".wld", ".hdr",    ".rpb", ".imd",
                                          ".xml",     ".jgw",   ".pgw", "_rpc.txt"};
  const std::filesystem::path whole(file);
  std::filesystem::path stem = whole;
  stem.replace_extension();
  for (const std::string& base : {whole.string(), stem.string()})
    for (const char* suffix : kSuffixes)
      for (const bool upper : {false, true}) {
        std::string ending = suffix;
        if (upper)
          std::transform(ending.begin(), ending.end(), ending.begin(),
                         [](unsigned char c) { return std::toupper(c); });
        struct stat status {};
        const std::string sidecar = base + ending;
        if (::stat(sidecar.c_str(), &status) == 0 && blocksOnRead(status.st_mode))
          throw IoError(path, "'" + sidecar + "', a file GDAL reads beside '" + file +
                                  "', is not a regular file; hfvis reads files");
      }
}

// Every file the VRT `path` reads (its sources, and those of the VRTs among them, each file once by
// device and inode, through the wrappers that name a local file: localFileOf), into `files`. Read
// from the XML before GDAL opens the VRT, because GDAL opens a raw band's file as it opens the
// VRT: a FIFO there, or /vsistdin/, blocked for good. So a source that is a FIFO, a socket or a
// device (or has such a sidecar), or standard input, is refused (IoError), as an input of that
// kind is (a directory may be a dataset: an ESRI grid); network and memory files are GDAL's. At
// most kMostVrtSources files in all, and nested VRTs to the depth GDAL itself allows.
void collectVrtSources(const std::string& path, std::vector<std::string>* files) {
  constexpr std::size_t kMostVrtSources = 100000;
  constexpr int kMostDepth = 16;
  requireRegularSidecars(path, path);
  std::set<std::pair<dev_t, ino_t>> seen;
  std::vector<std::pair<std::string, int>> pending{{path, 0}};
  while (!pending.empty()) {
    const auto [vrt, depth] = pending.back();
    pending.pop_back();
    if (depth > kMostDepth || !isVrt(vrt)) continue;
    CPLXMLNode* root = CPLParseXMLFile(vrt.c_str());
    if (!root) continue;  // (GDAL's open says what is wrong with it)
    std::vector<std::string> names;
    vrtSourceNames(root, std::filesystem::path(vrt).parent_path(), &names);
    CPLDestroyXMLNode(root);
    for (const std::string& source : names) {
      if (source.find("/vsistdin") != std::string::npos)
        throw IoError(path, "its source '" + source + "' is standard input; hfvis reads files");
      const std::string name = localFileOf(source);
      struct stat status {};
      if (name.empty() || ::stat(name.c_str(), &status) != 0)
        continue;  // (GDAL's open names what is missing)
      if (blocksOnRead(status.st_mode))
        throw IoError(path, "its source '" + source + "' is not a regular file; hfvis reads files");
      if (!seen.insert({status.st_dev, status.st_ino}).second) continue;
      if (files->size() >= kMostVrtSources)
        throw IoError(path, "it names more than " + std::to_string(kMostVrtSources) + " source files");
      files->push_back(name);
      if (S_ISREG(status.st_mode)) {
        requireRegularSidecars(path, name);
        pending.emplace_back(name, depth + 1);
      }
    }
  }
}

Dataset openRaster(const std::string& path) {
  registerOnce();
  requireInputFile(path);
  std::vector<std::string> sources;  // (here for its checks alone: filesRead gives the list)
  collectVrtSources(path, &sources);
  Dataset dataset(GDALOpen(path.c_str(), GA_ReadOnly));
  if (!dataset) throw IoError(path, lastError());
  const std::string driver = GDALGetDriverShortName(GDALGetDatasetDriver(dataset.get()));
  if (driver == "AAIGrid" || driver == "GRASSASCIIGrid") requireNumbersInAsciiGrid(path);
  if (GDALGetRasterXSize(dataset.get()) <= 0 || GDALGetRasterYSize(dataset.get()) <= 0 ||
      GDALGetRasterCount(dataset.get()) <= 0)
    throw IoError(path, "the raster has no pixels");
  return dataset;
}

// Refuses, before reading, a raster of more than `limit` bytes as float32 (0 = 64 GiB).
void requireReadable(const std::string& path, GDALDatasetH dataset, int bands, std::uint64_t limit) {
  limit = limit ? limit : kDefaultMaxImageBytes;
  const std::uint64_t width = GDALGetRasterXSize(dataset), height = GDALGetRasterYSize(dataset);
  if (width * height * std::uint64_t(bands) * sizeof(float) > limit)
    throw IoError(path, "raster of " + std::to_string(width) + " x " + std::to_string(height) +
                            " pixels and " + std::to_string(bands) + (bands == 1 ? " band" : " bands") +
                            " is more than the " + std::to_string(limit >> 20) + " MiB read at most");
}

// What reading heights into float32 rounded: the largest rounding, and the range of the values.
struct HeightRounding {
  double rounding = 0.0, lowest = INFINITY, highest = -INFINITY;
};

// Band `band_index` (zero-based) as float32: its values times the band's scale plus its offset
// (an int16 DEM of decimetres with a scale of 0.1 is metres), NaN where the band's nodata value
// is and, with `masks` (heights), where its mask (a per-dataset mask, an alpha band, a mask band of
// its own) says no data; an image's alpha stays ignored (image_io.hpp). Read as float64 in blocks
// of rows (whole blocks of the file's), so that nodata compares in the band's own type and a
// value beyond float32's range is refused rather than made infinite (it would pass for nodata).
// `rounded`: where given, what the conversion to float32 rounded (for the caller to judge).
std::vector<float> readBand(const std::string& path, GDALDatasetH dataset, int band_index, bool masks,
                            HeightRounding* rounded = nullptr) {
  const int width = GDALGetRasterXSize(dataset), height = GDALGetRasterYSize(dataset);
  GDALRasterBandH band = GDALGetRasterBand(dataset, band_index + 1);
  // The values grow with the rows read, so that a header claiming more pixels than the file holds
  // fails at its first missing rows, not after allocating the whole claim (158 bytes of TIFF
  // claiming 20000 x 20000 had taken 6 GB before GDAL's read failed).
  std::vector<float> values;
  int has_nodata = 0, has_scale = 0, has_offset = 0;
  const double nodata = GDALGetRasterNoDataValue(band, &has_nodata);
  double scale = GDALGetRasterScale(band, &has_scale), offset = GDALGetRasterOffset(band, &has_offset);
  if (!has_scale) scale = 1.0;
  if (!has_offset) offset = 0.0;
  if (!std::isfinite(scale) || !std::isfinite(offset) || scale == 0.0)
    throw IoError(path, "band " + std::to_string(band_index + 1) + " has a scale of " + shortNumber(scale) +
                            " and an offset of " + shortNumber(offset) +
                            ": not a usable linear map to heights");
  // (GDAL would give a complex band's real part alone)
  if (GDALDataTypeIsComplex(GDALGetRasterDataType(band)))
    throw IoError(path, "band " + std::to_string(band_index + 1) + " holds complex numbers (" +
                            GDALGetDataTypeName(GDALGetRasterDataType(band)) + "); hfvis reads real values");
  const bool in_float = GDALGetRasterDataType(band) == GDT_Float32;
  // A signed-byte band before GDAL 3.7 (which has GDT_Int8): a Byte band marked so, whose values
  // GDAL hands over as 0 .. 255 (-55 was read as 201, exit 0; a probe's find).
  const char* pixel_type = GDALGetMetadataItem(band, "PIXELTYPE", "IMAGE_STRUCTURE");
  const bool signed_byte =
      GDALGetRasterDataType(band) == GDT_Byte && pixel_type && std::string(pixel_type) == "SIGNEDBYTE";
  HeightRounding seen;
  const int flags = GDALGetMaskFlags(band);
  // (the mask of the nodata value is the value itself, compared below)
  GDALRasterBandH mask = !masks || (flags & (GMF_ALL_VALID | GMF_NODATA)) ? nullptr : GDALGetMaskBand(band);
  // (about 4M values a read, in whole rows of the file's blocks where one holds fewer: a tiled
  // raster's tile row decoded once; a taller block, a strip of the whole file, read in parts)
  int block_x = 0, block_y = 0;
  GDALGetBlockSize(band, &block_x, &block_y);
  block_y = std::max(1, block_y);
  const int rows_in_budget = std::max(1, (1 << 22) / std::max(width, 1));
  const int rows_per_read =
      std::min(height, rows_in_budget >= block_y ? rows_in_budget / block_y * block_y : rows_in_budget);
  std::vector<double> raw;
  std::vector<unsigned char> valid;
  for (int y0 = 0; y0 < height; y0 += rows_per_read) {
    const int rows = std::min(rows_per_read, height - y0);
    const std::size_t count = std::size_t(width) * rows;
    raw.resize(count);
    try {
      // (grown as a vector grows, but never past the whole raster: no spare capacity kept)
      const std::size_t needed = std::size_t(width) * (y0 + rows), whole = std::size_t(width) * height;
      if (needed > values.capacity())
        values.reserve(std::min(whole, std::max(needed, 2 * values.capacity())));
      values.resize(needed);
    } catch (const std::bad_alloc&) {
      throw IoError(path, "raster is too large to hold in memory (" + std::to_string(width) + " x " +
                              std::to_string(height) + " pixels)");
    }
    if (GDALRasterIO(band, GF_Read, 0, y0, width, rows, raw.data(), width, rows, GDT_Float64, 0, 0) !=
        CE_None)
      throw IoError(path, lastError());
    if (mask) {
      valid.resize(count);
      if (GDALRasterIO(mask, GF_Read, 0, y0, width, rows, valid.data(), width, rows, GDT_Byte, 0, 0) !=
          CE_None)
        throw IoError(path, "cannot read the band's mask: " + lastError());
    }
    float* out = values.data() + std::size_t(y0) * width;
    for (std::size_t i = 0; i < count; ++i) {
      const double v = signed_byte && raw[i] >= 128.0 ? raw[i] - 256.0 : raw[i];
      const bool is_nodata =
          has_nodata && (std::isnan(nodata) ? std::isnan(v)
                                            : (in_float ? static_cast<float>(v) == static_cast<float>(nodata)
                                                        : v == nodata));
      if (is_nodata || (mask && valid[i] == 0)) {
        out[i] = std::numeric_limits<float>::quiet_NaN();
        continue;
      }
      const double height_value = v * scale + offset;
      if (std::isfinite(height_value) && std::fabs(height_value) > std::numeric_limits<float>::max())
        throw IoError(path, "the value " + shortNumber(height_value) + " at column " +
                                std::to_string(i % std::size_t(width)) + ", row " +
                                std::to_string(y0 + i / std::size_t(width)) +
                                " is beyond float32's range, in which hfvis computes");
      out[i] = static_cast<float>(height_value);
      if (rounded && std::isfinite(height_value)) {
        seen.lowest = std::min(seen.lowest, height_value),
        seen.highest = std::max(seen.highest, height_value);
        seen.rounding = std::max(seen.rounding, std::fabs(height_value - static_cast<double>(out[i])));
      }
    }
  }
  if (rounded) *rounded = seen;
  return values;
}

}  // namespace

std::optional<std::pair<std::string, double>> projectedLinearUnit(const std::string& wkt) {
  if (wkt.empty()) return std::nullopt;
  registerOnce();
  std::unique_ptr<void, void (*)(OGRSpatialReferenceH)> srs(OSRNewSpatialReference(nullptr),
                                                            OSRDestroySpatialReference);
  if (!srs || OSRSetFromUserInput(srs.get(), wkt.c_str()) != OGRERR_NONE || !OSRIsProjected(srs.get()))
    return std::nullopt;
  char* name = nullptr;
  const double metres = OSRGetLinearUnits(srs.get(), &name);
  return std::pair<std::string, double>(name ? name : "unknown", metres);
}

void requireSameGrid(const std::string& path, const Georeference& side, const std::string& input,
                     const Georeference& field) {
  if (side.geotransform && field.geotransform) {
    const std::array<double, 6>& a = *side.geotransform;
    const std::array<double, 6>& b = *field.geotransform;
    const double pixel = std::max({std::fabs(b[1]), std::fabs(b[2]), std::fabs(b[4]), std::fabs(b[5])});
    bool same = std::fabs(a[0] - b[0]) <= 1e-3 * pixel && std::fabs(a[3] - b[3]) <= 1e-3 * pixel;
    for (const int i : {1, 2, 4, 5}) same = same && std::fabs(a[i] - b[i]) <= 1e-6 * pixel;
    if (!same) {
      const auto text = [](const std::array<double, 6>& t) {
        std::string out;
        for (const double v : t) out += (out.empty() ? "" : ", ") + exactNumber(v);
        return "(" + out + ")";
      };
      throw IoError(path,
                    "lies on another grid than the height field " + input + " (geotransform " + text(a) +
                        " against " + text(b) +
                        "; a south-up raster beside a north-up field too): it is taken pixel by pixel, so "
                        "warp it onto the field's grid first (gdalwarp -te, -ts, or -tr and -tap)");
    }
  }
  if (side.crs_wkt.empty() || field.crs_wkt.empty()) return;
  registerOnce();
  using Srs = std::unique_ptr<void, void (*)(OGRSpatialReferenceH)>;
  Srs a(OSRNewSpatialReference(nullptr), OSRDestroySpatialReference);
  Srs b(OSRNewSpatialReference(nullptr), OSRDestroySpatialReference);
  if (!a || !b || OSRSetFromUserInput(a.get(), side.crs_wkt.c_str()) != OGRERR_NONE ||
      OSRSetFromUserInput(b.get(), field.crs_wkt.c_str()) != OGRERR_NONE)
    return;
  // The horizontal parts alone: a DEM's compound CRS names its heights' datum, which an albedo
  // made from imagery does not (EPSG:32633+5773 beside EPSG:32633 was refused).
  OSRStripVertical(a.get());
  OSRStripVertical(b.get());
  if (!OSRIsSame(a.get(), b.get())) {
    const char* name_a = OSRGetName(a.get());
    const char* name_b = OSRGetName(b.get());
    throw IoError(
        path, "is in another CRS (" + std::string(name_a ? name_a : "unnamed") + ") than the height field " +
                  input + " (" + (name_b ? name_b : "unnamed") +
                  "): it is taken pixel by pixel, so warp it onto the field's grid first (gdalwarp -t_srs)");
  }
}

namespace {

Georeference georeferenceOf(GDALDatasetH dataset) {
  Georeference georeference;
  std::array<double, 6> transform;
  // Without a geotransform GDAL answers CE_Failure (and fills in the identity).
  if (GDALGetGeoTransform(dataset, transform.data()) == CE_None) georeference.geotransform = transform;
  if (OGRSpatialReferenceH srs = GDALGetSpatialRef(dataset)) {
    // WKT2 keeps every detail of the CRS; WKT1 cannot hold some (datum ensembles, ...).
    const char* const options[] = {"FORMAT=WKT2_2019", nullptr};
    char* wkt = nullptr;
    if (OSRExportToWktEx(srs, &wkt, options) == OGRERR_NONE && wkt) georeference.crs_wkt = wkt;
    CPLFree(wkt);
  }
  return georeference;
}

bool isGeographic(GDALDatasetH dataset) {
  OGRSpatialReferenceH srs = GDALGetSpatialRef(dataset);
  return srs && OSRIsGeographic(srs);
}

// The conversion of a geographic grid's spacing to metres (setGeographicCellSizes) takes degrees
// on the WGS84 ellipsoid: a CRS in radians or grads, or on another body (Mars), got cells of the
// wrong size without a word. Refuses those (IoError naming `path`); an Earth ellipsoid other than
// WGS84 (within 0.1 % of its axis) is taken as it.
void requireEarthDegrees(const std::string& path, OGRSpatialReferenceH srs) {
  char* unit = nullptr;
  const double radians_per_unit = OSRGetAngularUnits(srs, &unit);
  if (std::fabs(radians_per_unit - M_PI / 180.0) > 1e-9)
    throw IoError(path, std::string("its geographic CRS counts angles in ") +
                            (unit ? unit : "an unknown unit") +
                            ", not degrees: reproject it (gdalwarp -t_srs EPSG:4326), or give --cell-size");
  OGRErr error = OGRERR_NONE;
  const double axis = OSRGetSemiMajor(srs, &error);
  if (error == OGRERR_NONE && std::fabs(axis - 6378137.0) > 6378.137)
    throw IoError(path, "its geographic CRS lies on a body of semi-major axis " + shortNumber(axis) +
                            " m, not the Earth, whose degrees hfvis converts to metres: give --cell-size, or "
                            "reproject it to a projected CRS");
}

// Metadata names: GDAL's name=value lists also split at ':', so hfvis:units is stored as
// hfvis_units (and read back as hfvis:units).
constexpr const char* kStoredPrefix = "hfvis_";
constexpr const char* kAttributePrefix = "hfvis:";

std::string storedName(std::string name) {
  std::replace(name.begin(), name.end(), ':', '_');
  return name;
}

std::string attributeName(const std::string& stored) {
  if (stored.rfind(kStoredPrefix, 0) == 0)
    return kAttributePrefix + stored.substr(std::string(kStoredPrefix).size());
  return stored;
}

// Collects the errors GDAL reports on this thread while it lives: the GeoTIFF writer reports a
// failed write (disk full, ...) only that way, and a later warning would hide it from
// CPLGetLastErrorMsg.
class ErrorCollector {
 public:
  ErrorCollector() { CPLPushErrorHandlerEx(&ErrorCollector::handle, this); }
  ~ErrorCollector() { CPLPopErrorHandler(); }
  ErrorCollector(const ErrorCollector&) = delete;
  ErrorCollector& operator=(const ErrorCollector&) = delete;

  bool failed() const { return !first_failure_.empty(); }
  // `what`, with the cause where it can be told (a full disk, the file size limit) and GDAL's
  // first failure message, the temporary `file` in it named as the output `path`.
  std::string reason(const std::string& what, const std::string& file = "",
                     const std::string& path = "") const {
    std::string detail = first_failure_;
    for (std::size_t at; !file.empty() && (at = detail.find(file)) != std::string::npos;)
      detail.replace(at, file.size(), path);
    const int cause = file.empty() ? 0 : likelyWriteError(file);
    const std::string head = cause ? what + ": " + writeFailure(cause) : what;
    return detail.empty() ? head : head + " (" + detail + ")";
  }

 private:
  static void CPL_STDCALL handle(CPLErr level, CPLErrorNum, const char* message) {
    auto* self = static_cast<ErrorCollector*>(CPLGetErrorHandlerUserData());
    if ((level == CE_Failure || level == CE_Fatal) && self->first_failure_.empty())
      self->first_failure_ = message && *message ? message : "GDAL reported a failure";
  }
  std::string first_failure_;
};

// A GDAL configuration option set on this thread while it lives, then restored.
class ScopedThreadConfig {
 public:
  ScopedThreadConfig(const char* key, const char* value) : key_(key) {
    if (const char* old = CPLGetThreadLocalConfigOption(key, nullptr)) old_ = std::string(old);
    CPLSetThreadLocalConfigOption(key, value);
  }
  ~ScopedThreadConfig() { CPLSetThreadLocalConfigOption(key_, old_ ? old_->c_str() : nullptr); }
  ScopedThreadConfig(const ScopedThreadConfig&) = delete;
  ScopedThreadConfig& operator=(const ScopedThreadConfig&) = delete;

 private:
  const char* key_;
  std::optional<std::string> old_;
};

}  // namespace

// Ground metres per degree on the WGS84 ellipsoid at geodetic latitude `lat_deg`:
// along a meridian (radius of curvature M) and along a parallel (N cos(lat)).
void metresPerDegree(double lat_deg, double* along_meridian, double* along_parallel) {
  const double a = 6378137.0;
  const double f = 1.0 / 298.257223563;
  const double e2 = f * (2.0 - f);
  const double lat = lat_deg * M_PI / 180.0;
  const double s = std::sin(lat);
  const double w = 1.0 - e2 * s * s;
  const double m = a * (1.0 - e2) / (w * std::sqrt(w));
  const double n = a / std::sqrt(w);
  *along_meridian = m * M_PI / 180.0;
  *along_parallel = n * std::cos(lat) * M_PI / 180.0;
}

}  // namespace hfvis::detail

namespace hfvis {

void setGeographicCellSizes(HeightField& field, const std::array<double, 6>& geotransform) {
  const double first = geotransform[3], last = geotransform[3] + geotransform[5] * field.height;
  if (!(std::fabs(first) <= 90.0 && std::fabs(last) <= 90.0))
    throw InvalidArgument("a geographic raster whose rows span latitudes " + detail::shortNumber(first) +
                          " .. " + detail::shortNumber(last) +
                          " degrees, beyond the poles: its geotransform or CRS is wrong");
  // Degrees to metres on the ellipsoid at each row's latitude (its pixel centres); the field's
  // cell sizes are those at its centre latitude.
  const double degrees_x = std::fabs(geotransform[1]), degrees_y = std::fabs(geotransform[5]);
  double per_deg_y, per_deg_x;
  field.row_cell_size_x.clear();
  field.row_cell_size_y.clear();
  for (int r = 0; r < field.height; ++r) {
    detail::metresPerDegree(geotransform[3] + geotransform[5] * (r + 0.5), &per_deg_y, &per_deg_x);
    field.row_cell_size_x.push_back(degrees_x * per_deg_x);
    field.row_cell_size_y.push_back(degrees_y * per_deg_y);
  }
  detail::metresPerDegree(geotransform[3] + geotransform[5] * 0.5 * field.height, &per_deg_y, &per_deg_x);
  field.cell_size_x = degrees_x * per_deg_x;
  field.cell_size_y = degrees_y * per_deg_y;
}

}  // namespace hfvis

namespace hfvis::detail {

using detail::shortNumber;

std::optional<std::pair<double, double>> storedCellSize(const std::string& path, const char* x,
                                                        const char* y) {
  if ((!x || !*x) && (!y || !*y)) return std::nullopt;
  auto number = [&](const char* name, const char* text) {
    if (!text || !*text)  // (the other one is given)
      throw IoError(path, std::string("the attribute ") + name + " is missing or empty beside " +
                              (name[16] == 'x' ? "hfvis:cell_size_y" : "hfvis:cell_size_x") +
                              "; give --cell-size");
    double v = 0.0;
    if (!decimalNumber(text, v) || !(v > 0.0) || v > 1e9)
      throw IoError(path, std::string("the attribute ") + name + " is '" + std::string(text).substr(0, 40) +
                              "', not a cell size (a number above 0, at most 1e9); give --cell-size");
    return v;
  };
  return std::make_pair(number("hfvis:cell_size_x", x), number("hfvis:cell_size_y", y));
}

std::string lowercaseExtension(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

std::vector<std::string> gdalFilesRead(const std::string& path) {
  std::vector<std::string> files{path};
  struct stat status {};
  if (::stat(path.c_str(), &status) != 0 || !S_ISREG(status.st_mode)) return files;  // (reading says why)
  registerOnce();  // (before the VRT's XML is parsed: GDAL's errors go through IoError, not stderr)
  collectVrtSources(path, &files);
  const Dataset dataset(GDALOpen(path.c_str(), GA_ReadOnly));
  if (!dataset) return files;
  char** listed = GDALGetFileList(dataset.get());
  for (char** file = listed; file && *file; ++file)
    if (std::find(files.begin(), files.end(), *file) == files.end()) files.emplace_back(*file);
  CSLDestroy(listed);
  return files;
}

bool isGdalRaster(const std::string& path) {
  const std::string extension = lowercaseExtension(path);
  for (const char* gdal : {".tif", ".tiff", ".hgt", ".asc", ".vrt", ".img", ".bil", ".dem", ".grd", ".adf"})
    if (extension == gdal) return true;
  return false;
}

bool isGdalHeightField(const std::string& path) {
  if (isGdalRaster(path)) return true;
  // TIFF bytes under another name (.gtif, .gtiff, .cog, none) are a GeoTIFF still: read through
  // OpenImageIO they lost their nodata (-9999 became a pit 10 km deep), cell size and CRS, exit 0
  // (a probe's find). Classic (II*, MM*) and BigTIFF (II+, MM+) headers; a regular file's alone
  // (opening a FIFO would wait for a writer: it is refused as an input later, at once).
  struct stat status {};
  if (::stat(path.c_str(), &status) != 0 || !S_ISREG(status.st_mode)) return false;
  unsigned char magic[4] = {};
  std::ifstream in(path, std::ios::binary);
  if (!in.read(reinterpret_cast<char*>(magic), 4)) return false;
  return (magic[0] == 'I' && magic[1] == 'I' && (magic[2] == 42 || magic[2] == 43) && magic[3] == 0) ||
         (magic[0] == 'M' && magic[1] == 'M' && magic[2] == 0 && (magic[3] == 42 || magic[3] == 43));
}

HeightField readGdalHeightField(const std::string& path, const HeightFieldReadOptions& options) {
  const Dataset dataset = openRaster(path);
  const int bands = GDALGetRasterCount(dataset.get());
  // The band: the only one, an index, or a description.
  int band_index = 0;
  if (options.channel.empty()) {
    if (bands != 1)
      throw IoError(path, "the raster has " + std::to_string(bands) + " bands: choose one with --channel");
  } else if (options.channel.size() <= 9 &&
             std::all_of(options.channel.begin(), options.channel.end(), ::isdigit)) {
    band_index = std::stoi(options.channel);
    if (band_index >= bands) throw IoError(path, "no band " + options.channel);
  } else {
    band_index = -1;
    for (int b = 0; b < bands; ++b)
      if (options.channel == GDALGetDescription(GDALGetRasterBand(dataset.get(), b + 1))) band_index = b;
    if (band_index < 0) throw IoError(path, "no band named '" + options.channel + "'");
  }
  requireReadable(path, dataset.get(), 1, options.max_image_bytes);
  HeightField field;
  field.width = GDALGetRasterXSize(dataset.get());
  field.height = GDALGetRasterYSize(dataset.get());
  HeightRounding rounded;
  field.heights = readBand(path, dataset.get(), band_index, true, &rounded);
  field.georeference = georeferenceOf(dataset.get());
  // A rotated or sheared grid is refused whatever the cell size: the outputs would keep its
  // geotransform while every direction and distance was computed on an axis-aligned one.
  if (const auto& gt = field.georeference.geotransform; gt && ((*gt)[2] != 0.0 || (*gt)[4] != 0.0))
    throw IoError(path, "rotated or sheared geotransforms are not supported (terms " + shortNumber((*gt)[2]) +
                            ", " + shortNumber((*gt)[4]) + "); warp the raster north-up first (gdalwarp)");
  // A corner of 1e309 or NaN (an ASCII grid's xllcorner): the run went on, and wrote "x": null to
  // its JSON and inf to its CSV, or failed after the work naming the output.
  if (const auto& gt = field.georeference.geotransform)
    for (const double term : *gt)
      if (!std::isfinite(term))
        throw IoError(path, "the geotransform is not finite (" + shortNumber((*gt)[0]) + ", " +
                                shortNumber((*gt)[1]) + ", " + shortNumber((*gt)[3]) + ", " +
                                shortNumber((*gt)[5]) +
                                "): fix the raster's georeference first (gdal_edit.py -a_ullr, or -unsetgt)");
  // A pixel of size 0 (an ASCII grid's `cellsize 0`, a VRT's geotransform) places every pixel at
  // one point: refused whatever the cell size, as a rotated grid is (with --cell-size the run wrote
  // GeoTIFFs with a ground control point for a georeference, and region JSON with every "x" 0).
  if (const auto& gt = field.georeference.geotransform; gt && ((*gt)[1] == 0.0 || (*gt)[5] == 0.0))
    throw IoError(path, "the geotransform's pixel size is 0 (" + shortNumber((*gt)[1]) + " by " +
                            shortNumber((*gt)[5]) +
                            "): fix the raster's georeference first (gdal_edit.py -a_ullr, or -unsetgt)");
  // Ground control points without a geotransform: no grid of known spacing (GDAL answers the
  // identity; the run went on with cells of 1 and wrote outputs without the CRS, exit 0).
  if (!field.georeference.geotransform && GDALGetGCPCount(dataset.get()) > 0)
    throw IoError(path, "georeferenced by " + std::to_string(GDALGetGCPCount(dataset.get())) +
                            " ground control points, not a geotransform: hfvis needs a regular grid; warp "
                            "it onto one first (gdalwarp IN OUT.tif)");
  // Cell sizes: given, else from the geotransform (north-up or south-up only), else as hfvis
  // stored them.
  if (options.cell_size_x > 0.0 || options.cell_size_y > 0.0) {
    field.cell_size_x = options.cell_size_x > 0.0 ? options.cell_size_x : options.cell_size_y;
    field.cell_size_y = options.cell_size_y > 0.0 ? options.cell_size_y : options.cell_size_x;
  } else if (const auto& gt = field.georeference.geotransform) {
    field.cell_size_x = std::fabs((*gt)[1]);
    field.cell_size_y = std::fabs((*gt)[5]);
    if (isGeographic(dataset.get())) {
      requireEarthDegrees(path, GDALGetSpatialRef(dataset.get()));
      try {
        setGeographicCellSizes(field, *gt);
      } catch (const InvalidArgument& error) {
        throw IoError(path, error.what());
      }
    }
  } else if (const auto stored =
                 storedCellSize(path, GDALGetMetadataItem(dataset.get(), "hfvis_cell_size_x", nullptr),
                                GDALGetMetadataItem(dataset.get(), "hfvis_cell_size_y", nullptr))) {
    field.cell_size_x = stored->first;
    field.cell_size_y = stored->second;
  } else if (isGeographic(dataset.get())) {
    // No geotransform: a geographic raster's spacing in metres cannot be known.
    throw IoError(path,
                  "a geographic raster without a geotransform (no tiepoint) has no cell size in "
                  "metres; give one with --cell-size");
  }
  try {
    requireHeightsKeptInFloat32(rounded.rounding, rounded.lowest, rounded.highest,
                                std::min(field.cell_size_x, field.cell_size_y));
  } catch (const InvalidArgument& error) {
    throw IoError(path, error.what());
  }
  field.z_scale = options.z_scale;
  return field;
}

namespace {
// A band without a description: R, G, B or A where the raster says it holds that colour (a
// standard RGB GeoTIFF), else "channel<b>".
std::string colourName(GDALRasterBandH band, int b) {
  switch (GDALGetRasterColorInterpretation(band)) {
    case GCI_RedBand:
      return "R";
    case GCI_GreenBand:
      return "G";
    case GCI_BlueBand:
      return "B";
    case GCI_AlphaBand:
      return "A";
    default:
      return "channel" + std::to_string(b);
  }
}
}  // namespace

ImageChannels readGdalImage(const std::string& path) {
  const Dataset dataset = openRaster(path);
  const int bands = GDALGetRasterCount(dataset.get());
  requireReadable(path, dataset.get(), bands, 0);
  ImageChannels image;
  image.width = GDALGetRasterXSize(dataset.get());
  image.height = GDALGetRasterYSize(dataset.get());
  for (int b = 0; b < bands; ++b) {
    GDALRasterBandH band = GDALGetRasterBand(dataset.get(), b + 1);
    const std::string description = GDALGetDescription(band);
    image.names.push_back(description.empty() ? colourName(band, b) : description);
    image.planes.push_back(readBand(path, dataset.get(), b, false));
    int has_scale = 0, has_offset = 0;
    const double scale = GDALGetRasterScale(band, &has_scale),
                 offset = GDALGetRasterOffset(band, &has_offset);
    image.integers = image.integers || (GDALDataTypeIsInteger(GDALGetRasterDataType(band)) &&
                                        !(has_scale && scale != 1.0) && !(has_offset && offset != 0.0));
  }
  for (char** item = GDALGetMetadata(dataset.get(), nullptr); item && *item; ++item) {
    char* name = nullptr;
    const char* value = CPLParseNameValue(*item, &name);
    if (name && value) image.attributes.emplace_back(attributeName(name), value);
    CPLFree(name);
  }
  image.georeference = georeferenceOf(dataset.get());
  return image;
}

bool hasGeoTiffWriter() {
  registerOnce();
  return GDALGetDriverByName("GTiff") != nullptr;
}

namespace {
// Whether every value of every plane is a whole number or NaN.
bool wholeNumbers(const ImageChannels& image) {
  for (const std::vector<float>& plane : image.planes)
    for (float v : plane)
      if (!std::isnan(v) && v != std::nearbyint(v)) return false;
  return true;
}
}  // namespace

void writeGeoTiff(const std::string& file, const std::string& path, const ImageChannels& image) {
  if (!hasGeoTiffWriter()) throw IoError(path, "this GDAL has no GTiff driver to write a GeoTIFF");
  // Everything must go into the TIFF itself: with PAM on, GDAL puts what no TIFF tag holds into
  // a side file FILE.aux.xml, which the rename into place would leave behind.
  const ScopedThreadConfig no_side_file("GDAL_PAM_ENABLED", "NO");
  const ErrorCollector errors;
  char** options = nullptr;
  options = CSLSetNameValue(options, "TILED", "YES");
  options = CSLSetNameValue(options, "BLOCKXSIZE", std::to_string(kTileSize).c_str());
  options = CSLSetNameValue(options, "BLOCKYSIZE", std::to_string(kTileSize).c_str());
  options = CSLSetNameValue(options, "COMPRESS", "DEFLATE");
  // Level 1: about half the time of the default 6 for 1-2 % more bytes (a 4096^2 float32 DEM,
  // timed once with GDAL's writer alone on the 2-core test machine: 0.46 s and 42.2 MB against
  // 1.01 s and 41.5 MB). The floating-point predictor helps continuous values and only costs
  // where every value is a whole number (visible 0 / 1, counts): 0.19 s and 0.42 MB without it,
  // 0.32 s and 0.64 MB with it, on a 4096^2 viewshed timed the same way.
  options = CSLSetNameValue(options, "ZLEVEL", "1");
  options = CSLSetNameValue(options, "PREDICTOR", wholeNumbers(image) ? "1" : "3");
  // Band by band: each plane is written whole, so each compressed tile is written once (pixel
  // interleaving would recompress every tile for every band).
  options = CSLSetNameValue(options, "INTERLEAVE", "BAND");
  options = CSLSetNameValue(options, "BIGTIFF", "IF_SAFER");
  // DEFLATE is most of the writing time of a large output; the tiles compress independently.
  options = CSLSetNameValue(options, "NUM_THREADS", "ALL_CPUS");
  const int bands = static_cast<int>(image.planes.size());
  Dataset dataset(GDALCreate(GDALGetDriverByName("GTiff"), file.c_str(), image.width, image.height, bands,
                             GDT_Float32, options));
  CSLDestroy(options);
  if (!dataset) throw IoError(path, errors.reason("cannot create the GeoTIFF", file, path));

  const Georeference& georeference = image.georeference;
  if (georeference.geotransform) {
    std::array<double, 6> transform = *georeference.geotransform;
    if (GDALSetGeoTransform(dataset.get(), transform.data()) != CE_None)
      throw IoError(path, errors.reason("cannot write the geotransform"));
  }
  if (!georeference.crs_wkt.empty() &&
      GDALSetProjection(dataset.get(), georeference.crs_wkt.c_str()) != CE_None)
    throw IoError(path, errors.reason("cannot write the CRS"));
  for (const auto& [name, value] : image.attributes) {
    if (GDALSetMetadataItem(dataset.get(), storedName(name).c_str(), value.c_str(), nullptr) != CE_None)
      throw IoError(path, errors.reason("cannot write the metadata item '" + name + "'"));
  }

  const bool replace_nan = !std::isnan(image.nodata);
  // NaN cells become the nodata value a tile row at a time, so no plane is copied whole.
  std::vector<float> rows(replace_nan ? std::size_t(image.width) * std::min(kTileSize, image.height) : 0);
  for (int b = 0; b < bands; ++b) {
    GDALRasterBandH band = GDALGetRasterBand(dataset.get(), b + 1);
    GDALSetDescription(band, image.names[b].c_str());
    if (GDALSetRasterNoDataValue(band, image.nodata) != CE_None)
      throw IoError(path, errors.reason("cannot write the nodata value"));
    const std::vector<float>& plane = image.planes[b];
    for (int y = 0; y < image.height; y += kTileSize) {
      const int count = std::min(kTileSize, image.height - y);
      const float* source = plane.data() + std::size_t(y) * image.width;
      if (replace_nan) {
        std::transform(source, source + std::size_t(count) * image.width, rows.begin(),
                       [&](float v) { return std::isnan(v) ? image.nodata : v; });
        source = rows.data();
      }
      if (GDALRasterIO(band, GF_Write, 0, y, image.width, count, const_cast<float*>(source), image.width,
                       count, GDT_Float32, 0, 0) != CE_None)
        throw IoError(path, errors.reason("cannot write the pixels", file, path));
    }
  }
  GDALFlushCache(dataset.get());
  dataset.reset();  // closing writes the last tiles and the directory
  if (errors.failed()) throw IoError(path, errors.reason("cannot write the GeoTIFF", file, path));
}

}  // namespace hfvis::detail
