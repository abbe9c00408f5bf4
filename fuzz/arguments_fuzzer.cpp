// arguments_fuzzer: libFuzzer over the CLI's argument parser. The input is split at newlines
// into argv (without argv[0]). Parsing must either succeed, giving options the library
// accepts, or throw the parser's UsageError: any other exception, a crash or a sanitizer
// report is a bug.
#include <cstdint>
#include <string>
#include <vector>

#include "arguments.hpp"
#include "hfvis/errors.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string> args(1);
  for (std::size_t i = 0; i < size; ++i) {
    if (data[i] == '\n') {
      args.emplace_back();
    } else {
      args.back() += static_cast<char>(data[i]);
    }
  }
  try {
    const hfvis::cli::CommandLine command = hfvis::cli::parseCommandLine(args);
    const hfvis::cli::RunArguments& run = command.run;
    // What the parser accepts, the library must accept as options too (validated again
    // there: a disagreement is an error the user would meet only after reading the input).
    switch (command.command) {
      case hfvis::cli::Command::Horizon:
      case hfvis::cli::Command::SkyViewFactor:
      case hfvis::cli::Command::AmbientOcclusion:
        hfvis::validate(hfvis::cli::horizonOptions(run), hfvis::cli::horizonOutputs(command.command, run));
        break;
      case hfvis::cli::Command::Intervisibility:
        hfvis::validate(hfvis::cli::intervisibilityOptions(run), hfvis::cli::intervisibilityOutputs(run));
        break;
      default:
        break;
    }
  } catch (const hfvis::cli::UsageError&) {
  }
  return 0;
}
