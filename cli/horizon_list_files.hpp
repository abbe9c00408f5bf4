// cli/horizon_list_files.hpp: the text formats of `hfvis horizons`: JSON (everything, with
// the conventions spelled out) and CSV (one row per horizon, for spreadsheets and pandas).
#pragma once

#include <string>
#include <vector>

#include "arguments.hpp"
#include "hfvis/height_field.hpp"
#include "hfvis/horizon_lists.hpp"

namespace hfvis::cli {

std::string horizonListsJson(const RunArguments& run, const HeightField& field,
                             const std::vector<ReceiverHorizons>& lists);

std::string horizonListsCsv(const std::vector<ReceiverHorizons>& lists);

// The CSV header line (without newline), for the help text and the tests.
const char* horizonListsCsvHeader();

}  // namespace hfvis::cli
