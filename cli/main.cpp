// cli/main.cpp: the hfvis command line tool: dispatch, and the one place where errors
// become a message and an exit status (0 success, 1 runtime error, 2 usage error).
#include <sys/resource.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include "arguments.hpp"
#include "help.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/image_io.hpp"
#include "io/output_files.hpp"
#include "table.hpp"

namespace {

constexpr int kExitRuntimeError = 1;
constexpr int kExitUsageError = 2;

int run(const std::vector<std::string>& args) {
  using namespace hfvis::cli;
  const CommandLine line = parseCommandLine(args);
  if (line.command == Command::Help) {
    std::cout << (line.help_topic ? commandHelp(*line.help_topic) : generalHelp());
    return 0;
  }
  return commandSpec(line.command).run(line);
}

// "hfvis horizon --help" when the command is known, else "hfvis --help".
std::string helpHint(const std::vector<std::string>& args) {
  if (!args.empty() && hfvis::cli::findCommand(args[0])) return "hfvis " + args[0] + " --help";
  return "hfvis --help";
}

// Runs the command line; every error becomes a message and an exit status.
int runAndReport(const std::vector<std::string>& args) {
  try {
    return run(args);
  } catch (const hfvis::cli::UsageError& error) {
    std::cerr << "hfvis: error: " << error.what() << "\n"
              << "Run '" << helpHint(args) << "' for usage.\n";
    return kExitUsageError;
  } catch (const hfvis::Error& error) {
    std::cerr << "hfvis: error: " << error.what() << "\n";
    return kExitRuntimeError;
  } catch (const std::bad_alloc&) {
    std::cerr << "hfvis: error: out of host memory (try a smaller field or fewer directions)\n";
    return kExitRuntimeError;
  } catch (const std::exception& error) {
    std::cerr << "hfvis: error: " << error.what() << "\n";
    return kExitRuntimeError;
  }
}

// Set as main returns. An exit before that came from inside a library: LLVM, under PoCL, ends the
// process on a write it cannot make (its kernel cache past `ulimit -f`) with one line of its own,
// which names neither hfvis nor a cause the user can act on.
std::atomic<bool> g_returning{false};

void explainAnExitFromALibrary() {
  if (g_returning.load()) return;
  hfvis::detail::removeTemporaryFilesNow();
  std::string why =
      "a library (such as the OpenCL driver) ended the run (its message above); no output was written";
  rlimit limit{};
  if (::getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
    why += ". The file size limit (ulimit -f) is " + std::to_string(limit.rlim_cur) +
           " bytes: the driver writes its compiled kernels to files, which may need more (raise "
           "the limit)";
  std::fprintf(stderr, "hfvis: error: %s\n", why.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  // An interrupted run leaves no temporary files; and a write past the file size limit (ulimit
  // -f) fails with EFBIG and is reported like a full disk, instead of killing the process.
  hfvis::removeTemporaryOutputsOnSignals();
  std::signal(SIGXFSZ, SIG_IGN);
  std::atexit(explainAnExitFromALibrary);
  const int status = runAndReport(args);
  g_returning.store(true);
  return status;
}
