// opencl_context.hpp: the OpenCL plumbing every operation shares: context, queue, the
// program cache and OpenCL error translation. Internal to the library.
#pragma once

#include <CL/opencl.hpp>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

#include "hfvis/device.hpp"
#include "hfvis/errors.hpp"
#include "core/kernel_args.hpp"

namespace hfvis::detail {

struct ContextState {
  ContextOptions options;  // as the context was created
  DeviceInfo info;
  cl::Device device;
  cl::Context context;
  cl::CommandQueue queue;

  // The program built from kernels/<file> with `defines` (e.g. "-DHFVIS_WANT_AO=1"),
  // built once per (device, options, source) and cached. Throws KernelBuildError with the
  // device's build log. Built with -cl-kernel-arg-info, for NamedKernel.
  cl::Program program(const std::string& file, const std::string& defines);
  // The same for a source of the caller's (the benchmark's own kernels), named `name` in errors;
  // `include_dir` is passed as -I when not empty.
  cl::Program programFromSource(const std::string& name, const std::string& source, const std::string& include_dir,
                                const std::string& defines);

  // The argument names of `kernel`, kernel `name` of `program`: read once per program and
  // kernel (a cached program lives as long as the context, so its handle identifies it).
  std::shared_ptr<const NamedKernel::Names> argumentNames(const cl::Program& program,
                                                          const cl::Kernel& kernel, const std::string& name);

  // Enqueues `kernel` (throws Error naming an argument not set). With options.profile (queue
  // created with profiling), waits for it and adds its device time to kernel_seconds, which
  // is printed to stderr when the context is destroyed: per-kernel statistics of a run.
  void launch(const NamedKernel& kernel, const cl::NDRange& global, const cl::NDRange& local);

  // A device buffer of at least `bytes` (at most twice that) for `role` ("lattice
  // stacks", ...), kept between calls: large scratch buffers are allocated (and, on CPUs,
  // their pages first touched) once rather than per batch or per call, as long as calls
  // need about the same. A context runs one operation at a time (see ComputeContext), so
  // one buffer per role suffices.
  cl::Buffer reusableBuffer(const std::string& role, std::size_t bytes);
  std::map<std::string, std::pair<double, int>> kernel_seconds;  // name -> (seconds, launches)
  ~ContextState();

 private:
  std::mutex mutex_;
  std::map<std::string, cl::Program> programs_;
  std::map<std::pair<cl_program, std::string>, std::shared_ptr<const NamedKernel::Names>> argument_names_;
  std::map<std::string, std::pair<cl::Buffer, std::size_t>> buffers_;
};

// Kernel source by file name: embedded at build time, or read from `kernel_dir` when it is
// not empty (ContextOptions::kernel_dir; development: edit kernels without rebuilding).
std::string kernelSource(const std::string& file, const std::string& kernel_dir, std::string* include_dir);

// Runs `body`, turning cl::Error into OpenClError.
template <typename Body>
auto translateOpenClErrors(Body&& body) -> decltype(body()) {
  try {
    return body();
  } catch (const cl::Error& e) {
    throw OpenClError(e.what(), e.err());
  }
}

}  // namespace hfvis::detail

namespace hfvis {

// A context's opaque state (include/hfvis/device.hpp) is the library's ContextState.
struct ComputeContext::State : detail::ContextState {};

// The library's access to a context's OpenCL state, kept out of the public header.
class ContextAccess {
 public:
  static detail::ContextState& state(const ComputeContext& context) { return *context.state_; }
};

namespace detail {
inline ContextState& stateOf(const ComputeContext& context) { return ContextAccess::state(context); }
}  // namespace detail

}  // namespace hfvis
