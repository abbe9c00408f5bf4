// cli/commands/pvs.cpp: "hfvis pvs", the potentially visible sets of a field's view cells
// (hfvis/pvs.hpp) as JSON, optionally as a bitset file (docs/PVS.md) and a preview.
#include "hfvis/pvs.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include "../image_outputs.hpp"
#include "../pipeline.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/image_io.hpp"

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

std::string bitsetFile(const PvsResult& r) {
  std::string out("HFVPVS1", 8);  // 7 letters and a zero byte
  putU32(out, 1);                 // the format's version
  for (int v : {r.layout.view_x, r.layout.view_y, r.layout.tiles_x, r.layout.tiles_y, r.words,
                r.layout.view_cell, r.layout.tile})
    putU32(out, static_cast<std::uint32_t>(v));
  for (std::uint8_t c : r.computed) out.push_back(static_cast<char>(c ? 1 : 0));
  while (out.size() % 4) out.push_back('\0');
  for (std::uint32_t w : r.bits) putU32(out, w);
  return out;
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
  std::vector<std::string> otherInputs() const override { return {run_.pvs_mask}; }
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
  }

  void compute(Job& job) override {
    PvsOptions options = run_.pvs;
    options.seed = run_.seed;
    options.memory_budget_bytes = run_.memory_budget_bytes;
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
         << "  \"view_cells\": {\"size\": " << l.view_cell << ", \"across\": " << l.view_x
         << ", \"down\": " << l.view_y << ", \"band\": [" << jsonNumber(grid_.band_low) << ", "
         << jsonNumber(grid_.band_high) << "]},\n"
         << "  \"tiles\": {\"size\": " << l.tile << ", \"across\": " << l.tiles_x
         << ", \"down\": " << l.tiles_y << "},\n"
         << "  \"samples\": " << r.samples << ",\n"
         << "  \"rays\": " << r.rays << ",\n"
         << "  \"seconds\": " << jsonNumber(r.seconds) << ",\n"
         << "  \"estimated_pixel_error\": " << jsonNumber(r.pixel_error) << ",\n"
         << "  \"entries\": " << r.entries() << ",\n"
         << "  \"filtered_entries\": " << r.filtered << ",\n"
         << "  \"rejected_witnesses\": " << r.rejected << ",\n"
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
           << ", \"estimated_pixel_error\": " << jsonNumber(p.pixel_error) << ", \"mixture\": {";
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
    if (!run_.bitset_output.empty()) outputs.text(run_.bitset_output, bitsetFile(r));
    if (!run_.preview.empty()) {
      // PVS size per view cell, bright over a dimmed hillshade; view cells not computed, and
      // nodata, dark.
      const HeightField& input = job.input;
      const std::vector<float> shade = hillshade(input);
      float most = 1.0f;
      for (float s : sizes)
        if (s > most) most = s;
      std::vector<float> picture(input.pixelCount());
      for (int y = 0; y < input.height; ++y)
        for (int x = 0; x < input.width; ++x) {
          const std::size_t p = std::size_t(y) * input.width + x;
          const int cx = std::min(x, l.cells_x - 1), cy = std::min(y, l.cells_y - 1);
          const float s = sizes[l.viewOfCell(cy * l.cells_x + cx)];
          picture[p] = std::isfinite(input.heights[p])
                           ? 0.3f * shade[p] + (std::isnan(s) ? 0.0f : 0.15f + 0.55f * s / most)
                           : NAN;
        }
      outputs.previewPng(run_.preview, input.width, input.height, picture, 0.0f, 1.0f);
    }
    int computed = 0;
    for (std::uint8_t c : r.computed) computed += c != 0;
    return {computed,
            "; " + std::to_string(r.samples) + " samples, " + std::to_string(r.entries()) +
                " entries, estimated pixel error " + jsonNumber(r.pixel_error),
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

  PvsGrid grid_;
  PvsResult result_;
};

void checkPvs(const std::string& name, const RunArguments& run) {
  if (!hasExtension(run.output, ".json"))
    throw UsageError("-o: 'hfvis " + name + "' writes JSON; the name must end in .json, got " +
                     namedAs(run.output));
  if (!run.bitset_output.empty() && samePath(run.output, run.bitset_output))
    throw UsageError("--bitset must differ from -o, both are " + inQuotes(run.output));
  if (!run.preview.empty() && !hasExtension(run.preview, ".png"))
    throw UsageError("--preview: the preview is a PNG; the name must end in .png, got " +
                     namedAs(run.preview));
  if (run.pvs.samples == 0 && run.pvs.pixel_error == 0.0 && run.pvs.seconds == 0.0)
    throw UsageError("'hfvis " + name + "' needs a budget: --samples N, --pixel-error E or --seconds S");
  PvsOptions options = run.pvs;
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
    "[--filter K] [--seed N] [--bitset OUT.bin] [--preview P.png] [options]",
    "Potentially visible sets (Bittner, Mattausch, Wonka, Havran & Wimmer 2009): for every view\n"
    "cell, a square of C x C cells (--view-cell, default 32; a cell is the square between four\n"
    "grid points) whose volume is the points H0 .. H1 above the surface (--view-height, default\n"
    "1.7: a walker's eye), the tiles of T x T cells (--tile, default 16) some point of it sees.\n"
    "Found by sampling rays on the device: each entry is added only with a witness, an eye in\n"
    "the view cell and a point of the tile, whose segment passes the exact line-of-sight test,\n"
    "so the sets hold no false entry (they may miss some). --method agvs (default): the\n"
    "paper's adaptive mixture of five distributions; sgvs: its stationary global sampling;\n"
    "per-cell: random rays from each view cell in turn. The run stops at the first budget\n"
    "reached: --samples N, --pixel-error E (the paper's estimate, in differing rays per\n"
    "million-ray camera), --seconds S. The same seed and --samples give the same sets.\n"
    "--view-mask MASK (a raster of the field's size): only the view cells holding a non-zero\n"
    "pixel (its first channel) are computed. --filter K: Sec. 5's object-space filter, K\n"
    "times the sampling's gap.\n"
    "Writes JSON: the grids, samples, estimated pixel error, the mixture per batch and, per view\n"
    "cell, its visible tiles' row-major indices. --bitset OUT.bin: the sets as bits, laid out\n"
    "in docs/PVS.md. The preview shows the PVS size per view cell over a hillshade.\n",
    nullptr,
    kOutputGroup | kInputGroup | kImageGroup | kDeviceGroup | kPvsGroup,
    checkPvs,
    nullptr,
    pipelined<Pvs>,
};

}  // namespace hfvis::cli
