// kernel_args.cpp: kernel arguments by name (see kernel_args.hpp).
#include "core/kernel_args.hpp"

#include "core/opencl_context.hpp"
#include "hfvis/errors.hpp"

namespace hfvis::detail {

NamedKernel::NamedKernel(ContextState& st, const cl::Program& program, const std::string& name)
    : kernel_(program, name.c_str()), names_(st.argumentNames(program, kernel_, name)) {
  set_.assign(names_->arguments.size(), false);
}

// A linear search: a kernel has a few dozen arguments, and a launch costs far more.
bool NamedKernel::has(std::string_view arg) const {
  for (const auto& name : names_->arguments)
    if (name == arg) return true;
  return false;
}

cl_uint NamedKernel::indexOf(std::string_view arg) const {
  const auto& arguments = names_->arguments;
  for (std::size_t i = 0; i < arguments.size(); ++i)
    if (arguments[i] == arg) return static_cast<cl_uint>(i);
  throw Error("kernel " + names_->kernel + " has no argument named '" + std::string(arg) + "'");
}

const cl::Kernel& NamedKernel::ready() const {
  for (std::size_t i = 0; i < set_.size(); ++i)
    if (!set_[i])
      throw Error("kernel " + names_->kernel + " launched without its argument '" + names_->arguments[i] +
                  "'");
  return kernel_;
}

}  // namespace hfvis::detail
