// cli/commands/pvs.cpp: "hfvis pvs", the potentially visible sets of a field's view cells
// (hfvis/pvs.hpp) as JSON, optionally as a bitset file (docs/PVS.md) and a preview.
#include "hfvis/pvs.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include "../image_outputs.hpp"
#include "../pipeline.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/image_io.hpp"
#include "hfvis/viewshed.hpp"
#include "io/gdal_io.hpp"
#include "io/output_files.hpp"

namespace hfvis::cli {
namespace {

const char* methodName(PvsMethod method) {
  return method == PvsMethod::Agvs ? "agvs" : method == PvsMethod::Sgvs ? "sgvs" : "per-cell";
}

// A JSON number: 10 significant digits, NaN as null.
std::string jsonNumber(double value) { return std::isfinite(value) ? formatNumber(value) : "null"; }

// The bitset file (docs/PVS.md): little-endian.
void putU32(std::string& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFFu));
}
std::uint32_t getU32(const char* at) {
  const unsigned char* b = reinterpret_cast<const unsigned char*>(at);
  return std::uint32_t(b[0]) | std::uint32_t(b[1]) << 8 | std::uint32_t(b[2]) << 16 |
         std::uint32_t(b[3]) << 24;
}

// What a bitset's sets were computed from, which a run resumed from them must share: the field
// (its heights' bits, size, cell sizes and z-scale, as a 64-bit hash), the view band, and whether
// a visibility filter (--filter, --view-filter) was asked for (whether or not it added entries).
// A bitset of another field was resumed, and its sets, seen through a wall this field has, went
// out as this field's (exit 0).
struct BitsetOrigin {
  std::uint64_t field = 0;
  float band_low = 0.0f, band_high = 0.0f;
  bool filtered = false;
  float curvature = 0.0f;     // the drop coefficient (0 in files from before it was kept: flat)
  float max_distance = 0.0f;  // 0: none (version 2 files: none)
};

// The run's PVS options as its arguments give them (the curvature from --curvature / --refraction).
PvsOptions pvsOptions(const RunArguments& run) {
  PvsOptions options = run.pvs;
  options.curvature = run.curvature ? earthCurvature(run.refraction) : 0.0;
  options.max_distance = run.max_distance;
  return options;
}

BitsetOrigin originOf(const HeightField& field, const PvsGrid& grid, const PvsOptions& options) {
  std::uint64_t hash = heightsFingerprint(field);
  const auto mix = [&](const void* data, std::size_t size) {
    for (std::size_t i = 0; i < size; ++i)
      hash = (hash ^ static_cast<const unsigned char*>(data)[i]) * 1099511628211ull;
  };
  for (const int v : {field.width, field.height}) mix(&v, sizeof v);
  for (const double v : {field.cell_size_x, field.cell_size_y, field.z_scale}) mix(&v, sizeof v);
  return {hash,
          static_cast<float>(grid.band_low),
          static_cast<float>(grid.band_high),
          options.filter > 0.0 || options.view_filter > 0,
          static_cast<float>(options.curvature),
          static_cast<float>(options.max_distance)};
}

std::uint32_t floatBits(float v) {
  std::uint32_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  return bits;
}

std::string bitsetFile(const PvsResult& r, const BitsetOrigin& origin) {
  std::string out("HFVPVS1", 8);  // 7 letters and a zero byte
  putU32(out, 3);                 // the format's version
  for (int v : {r.layout.view_x, r.layout.view_y, r.layout.tiles_x, r.layout.tiles_y, r.words,
                r.layout.view_cell, r.layout.tile})
    putU32(out, static_cast<std::uint32_t>(v));
  putU32(out, static_cast<std::uint32_t>(origin.field & 0xFFFFFFFFu));
  putU32(out, static_cast<std::uint32_t>(origin.field >> 32));
  putU32(out, floatBits(origin.band_low));
  putU32(out, floatBits(origin.band_high));
  putU32(out, origin.filtered ? 1u : 0u);
  putU32(out, floatBits(origin.curvature));
  putU32(out, floatBits(origin.max_distance));
  putU32(out, 0u);  // (reserved)
  for (std::uint8_t c : r.computed) out.push_back(static_cast<char>(c ? 1 : 0));
  while (out.size() % 4) out.push_back('\0');
  for (std::uint32_t w : r.bits) putU32(out, w);
  return out;
}

// A --bitset file read back (--resume): its grid, computed view cells and sets.
struct BitsetFile {
  std::uint32_t view_x = 0, view_y = 0, tiles_x = 0, tiles_y = 0, words = 0, view_cell = 0, tile = 0;
  std::vector<std::uint8_t> computed;
  std::vector<std::uint32_t> bits;
};

// Bytes before the computed view cells: 72 in format version 3 (the maximum distance at 64),
// 64 in version 2 (read as no maximum distance).
constexpr int kBitsetHeader = 72, kBitsetHeader2 = 64;

// The grid is compared with this run's (`l`) from the header, before the body is read, and so is
// what the sets were computed from (`origin`).
BitsetFile readBitsetFile(const std::string& path, const PvsLayout& l, const BitsetOrigin& origin,
                          const std::string& input) {
  detail::requireInputFile(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path, std::string("cannot open: ") + std::strerror(errno));
  const auto fail = [&](const std::string& why) -> IoError {
    return IoError(path, "not a PVS bitset file of hfvis pvs --bitset (docs/PVS.md): " + why);
  };
  char head[kBitsetHeader];
  if (!in.read(head, 12)) throw fail("shorter than its header");
  if (std::memcmp(head, "HFVPVS1", 8) != 0) throw fail("it does not start with HFVPVS1");
  const auto u32 = [&](int at) { return getU32(head + at); };
  if (u32(8) == 1)
    throw UsageError("--resume: " + path +
                     " is a bitset of format version 1, which records nothing of the field its sets were "
                     "computed on: run again from the start, or resume from a file this hfvis wrote");
  if (u32(8) != 2 && u32(8) != 3)
    throw fail("format version " + std::to_string(u32(8)) + ", this hfvis reads versions 2 and 3");
  const int header = u32(8) == 2 ? kBitsetHeader2 : kBitsetHeader;
  if (!in.read(head + 12, header - 12))
    throw fail("shorter than its " + std::to_string(header) + "-byte header");
  if (header == kBitsetHeader2) std::memset(head + kBitsetHeader2, 0, kBitsetHeader - kBitsetHeader2);
  BitsetFile f;
  f.view_x = u32(12), f.view_y = u32(16), f.tiles_x = u32(20), f.tiles_y = u32(24), f.words = u32(28);
  f.view_cell = u32(32), f.tile = u32(36);
  const std::uint64_t views = std::uint64_t(f.view_x) * f.view_y,
                      tiles = std::uint64_t(f.tiles_x) * f.tiles_y;
  if (views == 0 || tiles == 0 || views > (1u << 30) || tiles > (1u << 30) || f.words != (tiles + 31) / 32 ||
      f.view_cell == 0 || f.tile == 0)
    throw fail("its header's grid does not hold together");
  if (int(f.view_cell) != l.view_cell || int(f.tile) != l.tile || int(f.view_x) != l.view_x ||
      int(f.view_y) != l.view_y || int(f.tiles_x) != l.tiles_x || int(f.tiles_y) != l.tiles_y)
    throw UsageError("--resume: " + path + " holds " + std::to_string(f.view_x) + " x " +
                     std::to_string(f.view_y) + " view cells of " + std::to_string(f.view_cell) + " and " +
                     std::to_string(f.tiles_x) + " x " + std::to_string(f.tiles_y) + " tiles of " +
                     std::to_string(f.tile) + "; this run's grid is " + std::to_string(l.view_x) + " x " +
                     std::to_string(l.view_y) + " view cells of " + std::to_string(l.view_cell) + " and " +
                     std::to_string(l.tiles_x) + " x " + std::to_string(l.tiles_y) + " tiles of " +
                     std::to_string(l.tile) + " (" + input +
                     "): give the same field, --view-cell and --tile");
  const std::uint64_t field = std::uint64_t(u32(40)) | std::uint64_t(u32(44)) << 32;
  if (field != origin.field || u32(48) != floatBits(origin.band_low) ||
      u32(52) != floatBits(origin.band_high))
    throw UsageError("--resume: " + path +
                     "'s sets were computed on another field (its heights, cell size or " +
                     "z-scale) or view band than this run's (" + input +
                     "): a resumed run adds to the sets of the same field and band");
  // A setting the sets were computed with (`kept`, the file's bits) that this run (`wanted`) must
  // share: `some` names one (with its article), `setting` the kind.
  const auto requireSame = [&](std::uint32_t kept, float wanted, const std::string& some,
                               const std::string& setting, const std::string& options) {
    if (kept == floatBits(wanted)) return;
    throw UsageError("--resume: " + path + "'s sets were computed " +
                     (kept == 0        ? "without " + some + ", which this run takes"
                      : wanted == 0.0f ? "with " + some + ", which this run has not"
                                       : "with another " + setting + " than this run's") +
                     ": give the same " + options);
  };
  requireSame(u32(64), origin.max_distance, "a maximum distance", "maximum distance", "--max-distance");
  requireSame(u32(60), origin.curvature, "curvature", "curvature", "--curvature and --refraction");
  if (u32(56) != 0)
    throw UsageError("--resume: " + path +
                     " was written with --filter or --view-filter, whose entries a resumed run "
                     "would take for sampled ones: resume only from steps run without them");
  const std::uint64_t padded = (views + 3) / 4 * 4, size = header + padded + 4 * views * f.words;
  in.seekg(0, std::ios::end);
  if (std::uint64_t(in.tellg()) != size)
    throw fail("it is " + std::to_string(std::uint64_t(in.tellg())) + " bytes, its header asks " +
               std::to_string(size));
  in.seekg(header);
  std::string body(size - header, '\0');
  if (!in.read(&body[0], std::streamsize(body.size()))) throw IoError(path, "cannot read it whole");
  f.computed.assign(body.begin(), body.begin() + std::ptrdiff_t(views));
  for (std::uint8_t& c : f.computed) {
    if (c > 1) throw fail("a view cell's computed byte is neither 0 nor 1");
  }
  f.bits.resize(views * f.words);
  for (std::size_t i = 0; i < f.bits.size(); ++i) f.bits[i] = getU32(body.data() + padded + 4 * i);
  // (the library refuses these too, without naming the file)
  const std::uint32_t last = tiles % 32 ? (1u << (tiles % 32)) - 1u : ~0u;
  for (std::uint64_t v = 0; v < views; ++v)
    if (f.bits[v * f.words + f.words - 1] & ~last)
      throw fail("view cell " + std::to_string(v) + " has bits past the last of the " +
                 std::to_string(tiles) + " tiles");
  return f;
}

// The view cell holding pixel (col, row) (pixels on the last row or column: the cells before).
int viewCellOf(const PvsLayout& l, int col, int row) {
  const int cx = std::min(col, l.cells_x - 1), cy = std::min(row, l.cells_y - 1);
  return l.viewOfCell(cy * l.cells_x + cx);
}

class Pvs : public Computation {
 public:
  using Computation::Computation;

  std::vector<std::string> outputs() const override {
    std::vector<std::string> paths{run_.output};
    if (!run_.bitset_output.empty()) paths.push_back(run_.bitset_output);
    if (!run_.preview.empty()) paths.push_back(run_.preview);
    return paths;
  }
  std::vector<std::string> otherInputs() const override { return {run_.pvs_mask, run_.pvs_resume}; }
  bool writesImages() const override { return false; }
  bool usesDevice() const override { return true; }
  std::string method() const override { return methodName(run_.pvs.method); }

  // The grid against the field, and the mask (the field's size) into view cells.
  void prepare(HeightField& field) override {
    grid_ = run_.pvs_grid;
    const PvsLayout layout = layoutOf(field);
    if (!run_.pvs_mask.empty()) {
      // Its first channel: a grey mask with alpha (Y, A), or a painted RGB one, holds the mask there.
      HeightFieldReadOptions first;
      first.channel = "0";
      const HeightField mask = readHeightField(run_.pvs_mask, first);
      detail::requireSameGrid(run_.pvs_mask, mask.georeference, run_.input, field.georeference);
      if (mask.width != field.width || mask.height != field.height)
        throw UsageError("--view-mask: " + run_.pvs_mask + " is " + std::to_string(mask.width) + " x " +
                         std::to_string(mask.height) + ", the field " + std::to_string(field.width) + " x " +
                         std::to_string(field.height) + " (" + run_.input + ")");
      grid_.mask.assign(layout.viewCells(), 0);
      for (int y = 0; y < mask.height; ++y)
        for (int x = 0; x < mask.width; ++x) {
          const float m = mask.at(x, y);
          if (!(std::isfinite(m) && m != 0.0f)) continue;
          const int cx = std::min(x, layout.cells_x - 1), cy = std::min(y, layout.cells_y - 1);
          grid_.mask[layout.viewOfCell(cy * layout.cells_x + cx)] = 1;
        }
      layoutOf(field);
    }
    origin_ = originOf(field, grid_, pvsOptions(run_));
    if (!run_.pvs_resume.empty()) resumeFrom(layout);
    if (run_.pvs_preview_cell_given) {
      const ReceiverPixel& p = run_.pvs_preview_cell;
      if (p.col >= field.width || p.row >= field.height)
        throw UsageError("--preview-view-cell " + std::to_string(p.col) + "," + std::to_string(p.row) +
                         " is outside the " + std::to_string(field.width) + " x " +
                         std::to_string(field.height) + " field (" + run_.input + ")");
      const int v = viewCellOf(layout, p.col, p.row);
      if (!grid_.mask.empty() && !grid_.mask[v])
        throw UsageError("--preview-view-cell " + std::to_string(p.col) + "," + std::to_string(p.row) +
                         " lies in view cell " + std::to_string(v) + ", which the view mask leaves out");
    }
  }

  void compute(Job& job) override {
    PvsOptions options = pvsOptions(run_);
    options.seed = run_.seed;
    options.memory_budget_bytes = run_.memory_budget_bytes;
    options.start = start_;
    result_ = computePvs(*job.context, job.input, grid_, options);
  }

  Summary write(Job& job, OutputFiles& outputs) override {
    const PvsResult& r = result_;
    const PvsLayout& l = r.layout;
    if (r.bits.size() != std::size_t(l.viewCells()) * r.words ||
        r.computed.size() != std::size_t(l.viewCells()))
      throw Error("internal error: the PVS bitsets are not of the grid's size");
    std::ostringstream json;
    json << "{\n"
         << "  \"command\": \"pvs\",\n"
         << "  \"input\": " << jsonString(run_.input) << ",\n"
         << "  \"method\": " << jsonString(job.method) << ",\n"
         << "  \"seed\": " << run_.seed << ",\n"
         << "  \"curvature\": " << jsonNumber(pvsOptions(run_).curvature) << ",\n"
         << "  \"max_distance\": " << jsonNumber(pvsOptions(run_).max_distance) << ",\n"
         << "  \"resumed_from\": " << resumedFrom() << ",\n"
         << "  \"view_cells\": {\"size\": " << l.view_cell << ", \"across\": " << l.view_x
         << ", \"down\": " << l.view_y << ", \"band\": [" << jsonNumber(grid_.band_low) << ", "
         << jsonNumber(grid_.band_high) << "]},\n"
         << "  \"tiles\": {\"size\": " << l.tile << ", \"across\": " << l.tiles_x
         << ", \"down\": " << l.tiles_y << "},\n"
         << "  \"samples\": " << r.samples << ",\n"
         << "  \"estimate_samples\": " << r.estimate_samples << ",\n"
         << "  \"rays\": " << r.rays << ",\n"
         << "  \"seconds\": " << jsonNumber(r.seconds) << ",\n"
         << "  \"estimated_pixel_error\": " << jsonNumber(r.pixel_error) << ",\n"
         << "  \"entries\": " << r.entries() << ",\n"
         << "  \"filtered_entries\": " << r.filtered << ",\n"
         << "  \"rejected_witnesses\": " << r.rejected << ",\n"
         << "  \"discontinuities\": " << r.discontinuities << ",\n"
         << "  \"conventions\": "
         << jsonString(
                "cells are the squares between grid points (column, row of their lower corner); view cell "
                "(a, b) covers cells a*size .. a*size+size-1 across and b*size .. down, row-major index "
                "b*across+a, its volume the points band[0] .. band[1] above the surface; tiles likewise; "
                "pvs[v]: the row-major indices of the tiles seen from view cell v (null: not computed); "
                "estimated_pixel_error: differing rays per million-ray camera (Bittner et al. 2009, Sec. "
                "4.5)")
         << ",\n"
         << "  \"progress\": [";
    for (std::size_t i = 0; i < r.history.size(); ++i) {
      const PvsProgress& p = r.history[i];
      json << (i ? "," : "") << "\n    {\"samples\": " << p.samples << ", \"rays\": " << p.rays
           << ", \"entries\": " << p.entries << ", \"seconds\": " << jsonNumber(p.seconds)
           << ", \"estimated_pixel_error\": " << jsonNumber(p.pixel_error)
           << ", \"settling\": " << (p.settling ? "true" : "false") << ", \"mixture\": {";
      for (int d = 0; d < kPvsDistributions; ++d)
        json << (d ? ", " : "") << jsonString(pvsDistributionName(d)) << ": " << jsonNumber(p.probability[d]);
      json << "}}";
    }
    json << "\n  ],\n  \"pvs\": [";
    std::vector<float> sizes(l.viewCells(), NAN);
    for (int v = 0; v < l.viewCells(); ++v) {
      json << (v ? "," : "") << "\n    ";
      if (!r.computed[v]) {
        json << "null";
        continue;
      }
      json << "[";
      int n = 0;
      for (int t = 0; t < l.tiles(); ++t)
        if (r.visible(v, t)) json << (n++ ? "," : "") << t;
      json << "]";
      sizes[v] = static_cast<float>(n);
    }
    json << "\n  ]\n}\n";
    outputs.text(run_.output, json.str());
    if (!run_.bitset_output.empty()) outputs.text(run_.bitset_output, bitsetFile(r, origin_));
    if (!run_.preview.empty()) {
      // PVS size per view cell, bright over a dimmed hillshade; view cells not computed, and
      // nodata, dark. With --preview-view-cell: that view cell (its outline brightest) and the
      // tiles it sees, bright over the hillshade.
      const HeightField& input = job.input;
      const std::vector<float> shade = hillshade(input);
      float most = 1.0f;
      for (float s : sizes)
        if (s > most) most = s;
      const int chosen = run_.pvs_preview_cell_given
                             ? viewCellOf(l, run_.pvs_preview_cell.col, run_.pvs_preview_cell.row)
                             : -1;
      std::vector<float> picture(input.pixelCount());
      for (int y = 0; y < input.height; ++y)
        for (int x = 0; x < input.width; ++x) {
          const std::size_t p = std::size_t(y) * input.width + x;
          const int cx = std::min(x, l.cells_x - 1), cy = std::min(y, l.cells_y - 1);
          const float s = sizes[l.viewOfCell(cy * l.cells_x + cx)];
          float glow = std::isnan(s) ? 0.0f : 0.15f + 0.55f * s / most;
          if (chosen >= 0) {
            const int v = l.viewOfCell(cy * l.cells_x + cx);
            // (the outline: the view cell's first and last pixels across and down; the last view
            // cell of a row or column also holds the field's last pixels)
            const int x0 = v % l.view_x * l.view_cell, y0 = v / l.view_x * l.view_cell;
            const int x1 = x0 + l.view_cell >= l.cells_x ? input.width - 1 : x0 + l.view_cell - 1;
            const int y1 = y0 + l.view_cell >= l.cells_y ? input.height - 1 : y0 + l.view_cell - 1;
            const bool edge = x == x0 || y == y0 || x == x1 || y == y1;
            glow = v == chosen ? (edge ? 0.7f : 0.45f)
                               : (r.visible(chosen, l.tileOfCell(cy * l.cells_x + cx)) ? 0.35f : 0.0f);
          }
          picture[p] = std::isfinite(input.heights[p]) ? 0.3f * shade[p] + glow : NAN;
        }
      outputs.previewPng(run_.preview, input.width, input.height, picture, 0.0f, 1.0f);
    }
    int computed = 0;
    for (std::uint8_t c : r.computed) computed += c != 0;
    return {computed,
            "; " + std::to_string(r.samples) + " samples" +
                (r.estimate_samples ? " (" + std::to_string(r.estimate_samples) + " settling the estimate)" : "") +
                ", " + std::to_string(r.entries()) +
                " entries, estimated pixel error " +
                (std::isfinite(r.pixel_error) ? formatNumber(r.pixel_error)
                                              : std::string("none (no uniform view rays were cast to estimate it)")),
            "view cell"};
  }

 private:
  // The grid on the field; its refusal a usage error naming the input.
  PvsLayout layoutOf(const HeightField& field) const {
    try {
      return pvsLayout(field, grid_);
    } catch (const InvalidArgument& error) {
      throw UsageError(std::string(error.what()) + " (" + run_.input + ")");
    }
  }

  // --resume: the earlier run's sets, on this run's grid and view mask (the file's, unless
  // --view-mask gives one, which must then be the same).
  void resumeFrom(const PvsLayout& l) {
    const std::string& path = run_.pvs_resume;
    BitsetFile f = readBitsetFile(path, l, origin_, run_.input);
    if (std::count(f.computed.begin(), f.computed.end(), 1) == 0)
      throw UsageError("--resume: " + path + " computed no view cell");
    if (run_.pvs_mask.empty()) {
      if (std::count(f.computed.begin(), f.computed.end(), 0) > 0) grid_.mask = f.computed;
    } else if (f.computed != grid_.mask) {
      throw UsageError("--resume: " + path + " computed other view cells than --view-mask " + run_.pvs_mask +
                       " selects; leave --view-mask out to take the file's");
    }
    start_ = std::move(f.bits);
  }

  // The JSON's resumed_from: the file and the entries it held, or null.
  std::string resumedFrom() const {
    if (run_.pvs_resume.empty()) return "null";
    std::size_t entries = 0;
    for (std::uint32_t w : start_) entries += static_cast<std::size_t>(__builtin_popcount(w));
    return "{\"file\": " + jsonString(run_.pvs_resume) + ", \"entries\": " + std::to_string(entries) + "}";
  }

  PvsGrid grid_;
  PvsResult result_;
  std::vector<std::uint32_t> start_;
  BitsetOrigin origin_;  // what the sets are computed from: the --bitset header's, and --resume's check
};

void checkPvs(const std::string& name, const RunArguments& run) {
  if (!hasExtension(run.output, ".json"))
    throw UsageError("-o: 'hfvis " + name + "' writes JSON; the name must end in .json, got " +
                     namedAs(run.output));
  if (!run.bitset_output.empty() && samePath(run.output, run.bitset_output))
    throw UsageError("--bitset must differ from -o, both are " + inQuotes(run.output));
  // (a bitset named .exr or .tif was written as raw bits, and read back as a broken image)
  if (!run.bitset_output.empty() && !hasExtension(run.bitset_output, ".bin"))
    throw UsageError("--bitset: the sets are a binary file of bits; the name must end in .bin, got " +
                     namedAs(run.bitset_output));
  if (!run.preview.empty() && !hasExtension(run.preview, ".png"))
    throw UsageError("--preview: the preview is a PNG; the name must end in .png, got " +
                     namedAs(run.preview));
  if (run.pvs_preview_cell_given && run.preview.empty())
    throw UsageError("--preview-view-cell draws the preview: give --preview P.png as well");
  if (!run.pvs_resume.empty() && run.pvs.filter > 0.0)
    throw UsageError(
        "--filter with --resume: the filter's width follows a run's samples, and a resumed "
        "step knows only its own; filter a run from the start, and resume only from steps "
        "run without --filter");
  if (!run.pvs_resume.empty() && !run.seed_given)
    throw UsageError("--resume needs --seed: a seed the runs that made " + inQuotes(run.pvs_resume) +
                     " did not use (the same seed casts their samples again)");
  if (run.pvs.samples == 0 && run.pvs.pixel_error == 0.0 && run.pvs.seconds == 0.0)
    throw UsageError("'hfvis " + name + "' needs a budget: --samples N, --pixel-error E or --seconds S");
  const PvsOptions options = pvsOptions(run);
  asUsageError([&] { validate(options); });
}

}  // namespace

const CommandSpec kPvsCommand{
    Command::Pvs,
    "pvs",
    nullptr,
    "potentially visible sets: the tiles each view cell can see, as JSON",
    "IN -o OUT.json (--samples N | --pixel-error E | --seconds S) [--view-cell C]\n"
    "[--view-height H0[,H1]] [--view-mask MASK] [--tile T] [--method agvs|sgvs|per-cell]\n"
    "[--estimate-entries N] [--filter K] [--view-filter N] [--seed N] [--bitset OUT.bin]\n"
    "[--resume PREV.bin] [--curvature] [--refraction K] [--max-distance D]\n"
    "[--preview P.png] [--preview-view-cell COL,ROW] [options]",
    "Potentially visible sets (Bittner, Mattausch, Wonka, Havran & Wimmer 2009): for every view\n"
    "cell, a square of C x C cells (--view-cell, default 32; a cell is the square between four\n"
    "grid points) whose volume is the points H0 .. H1 above the surface (--view-height, default\n"
    "1.7: a walker's eye), the tiles of T x T cells (--tile, default 16) some point of it sees.\n"
    "Found by sampling rays on the device: each sampled entry is added only with a witness, an\n"
    "eye in the view cell and a point of the tile, whose segment passes the exact line-of-sight\n"
    "test, so the sampled sets hold no false entry (they may miss some; the filters below add\n"
    "entries without a witness). --method agvs (default): the\n"
    "paper's adaptive mixture of five distributions; sgvs: its stationary global sampling;\n"
    "per-cell: random rays from each view cell in turn. The run stops at the first budget\n"
    "reached: --samples N, --pixel-error E (the paper's estimate, in differing rays per\n"
    "million-ray camera), --seconds S; or at once when every view cell holds every tile\n"
    "(nodata and --max-distance aside: a view cell or a tile with no valid cell pairs\n"
    "with nothing, nor does a view cell with a tile D or more away).\n"
    "--curvature (--refraction K): sight lines over the curved Earth, as the viewshed's;\n"
    "--max-distance D: an eye and the point it sees at most D ground units apart.\n"
    "The same seed and --samples give the same sets.\n"
    "When a budget leaves the estimate on fewer than 20 entries found once (a count too\n"
    "small to hold within 2x) but one at least, uniform view rays go on until 20 carry\n"
    "it, at most as many samples (and seconds) as the run took before them\n"
    "(--estimate-entries N, 0: off; estimate_samples in the JSON).\n"
    "--view-mask MASK (a raster of the field's size): only the view cells holding a non-zero\n"
    "pixel (its first channel) are computed. --filter K: Sec. 5's object-space filter, K\n"
    "times the sampling's gap. --view-filter N: Sec. 5's view-space filter, each view cell\n"
    "taking the sampled sets of its N most similar neighbours (of 8).\n"
    "Writes JSON: the grids, samples, estimated pixel error, the mixture per batch and, per view\n"
    "cell, its visible tiles' row-major indices. --bitset OUT.bin: the sets as bits, laid out\n"
    "in docs/PVS.md. The preview shows the PVS size per view cell over a hillshade, or with\n"
    "--preview-view-cell COL,ROW the tiles the view cell holding that pixel sees.\n"
    "--resume PREV.bin --seed S: go on from an earlier run's --bitset file (same field,\n"
    "grid, band, curvature and maximum distance) with a seed it did not use: runs of a\n"
    "few seconds each, resumed in turn, give the sets written at every step (no filter in\n"
    "them). samples and the estimate are this run's; resumed_from names the file and its\n"
    "entries.\n",
    nullptr,
    kOutputGroup | kInputGroup | kImageGroup | kDeviceGroup | kEarthGroup | kReachGroup | kPvsGroup,
    checkPvs,
    nullptr,
    pipelined<Pvs>,
};

}  // namespace hfvis::cli
