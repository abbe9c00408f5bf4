// kernel_args.hpp: kernels whose arguments are set by the names the .cl source gives them, not
// by counting positions: a kernel's signature can change without every call site's indices
// shifting, and a launch with an argument left unset names it instead of failing on the device.
#pragma once

#include <CL/opencl.hpp>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace hfvis::detail {

struct ContextState;

class NamedKernel {
 public:
  NamedKernel() = default;
  // Kernel `name` of `program` (built by ContextState::program, with -cl-kernel-arg-info);
  // its argument names are read once per program and kernel and cached in `st`.
  NamedKernel(ContextState& st, const cl::Program& program, const std::string& name);

  // Sets argument `arg`; throws Error when the kernel has no argument of that name.
  template <typename T>
  NamedKernel& set(std::string_view arg, const T& value) {
    const cl_uint index = indexOf(arg);
    kernel_.setArg(index, value);
    set_[index] = true;
    return *this;
  }

  // Whether the kernel takes an argument named `arg`.
  bool has(std::string_view arg) const;

  // The kernel to enqueue; throws Error naming the first argument not yet set.
  const cl::Kernel& ready() const;
  const std::string& name() const { return names_->kernel; }

  // A kernel's argument names in order (the cache's entry).
  struct Names {
    std::string kernel;
    std::vector<std::string> arguments;
  };

 private:
  cl_uint indexOf(std::string_view arg) const;

  cl::Kernel kernel_;
  std::shared_ptr<const Names> names_;
  std::vector<bool> set_;
};

}  // namespace hfvis::detail
