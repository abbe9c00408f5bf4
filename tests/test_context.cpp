// test_context.cpp: ContextOptions and ComputeContext: the library reads no environment
// variable itself; fromEnvironment() maps HFVIS_* onto options; a context is never empty.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <type_traits>

#include "core/opencl_context.hpp"
#include "core/sweep_framework.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/horizon.hpp"
#include "hfvis_testing/synthetic_fields.hpp"
#include "test_support.hpp"

namespace hfvis {
namespace {

// Sets the environment variables for one test and restores them after.
class ScopedEnvironment {
 public:
  void set(const char* name, const char* value) {
    const char* old = std::getenv(name);
    saved_.push_back({name, old ? std::string(old) : std::string(), old != nullptr});
    setenv(name, value, 1);
  }
  ~ScopedEnvironment() {
    for (auto it = saved_.rbegin(); it != saved_.rend(); ++it) {
      if (it->had) {
        setenv(it->name.c_str(), it->value.c_str(), 1);
      } else {
        unsetenv(it->name.c_str());
      }
    }
  }

 private:
  struct Saved {
    std::string name, value;
    bool had;
  };
  std::vector<Saved> saved_;
};

static_assert(!std::is_default_constructible_v<ComputeContext>, "a ComputeContext comes only from create()");

TEST(ContextOptions, FromEnvironmentReadsEachVariable) {
  ScopedEnvironment env;
  env.set("HFVIS_DEVICE", "cpu");
  env.set("HFVIS_PROFILE", "1");
  env.set("HFVIS_KERNEL_DIR", "/some/kernels");
  env.set("HFVIS_LINE_LAYOUT", "step");
  const ContextOptions options = ContextOptions::fromEnvironment();
  EXPECT_EQ(options.device, "cpu");
  EXPECT_TRUE(options.profile);
  EXPECT_EQ(options.kernel_dir, "/some/kernels");
  EXPECT_EQ(options.line_layout, LineLayout::StepMajor);
  env.set("HFVIS_LINE_LAYOUT", "line");
  env.set("HFVIS_PROFILE", "0");
  EXPECT_EQ(ContextOptions::fromEnvironment().line_layout, LineLayout::LineMajor);
  EXPECT_FALSE(ContextOptions::fromEnvironment().profile);
}

TEST(ContextOptions, FromEnvironmentRefusesBadValues) {
  ScopedEnvironment env;
  env.set("HFVIS_LINE_LAYOUT", "diagonal");
  EXPECT_THROW(ContextOptions::fromEnvironment(), InvalidArgument);
  env.set("HFVIS_LINE_LAYOUT", "");
  env.set("HFVIS_PROFILE", "yes");
  EXPECT_THROW(ContextOptions::fromEnvironment(), InvalidArgument);
}

// The library itself ignores the environment: a variable that would break the run changes
// nothing for a context created from explicit options.
TEST(ComputeContext, IgnoresTheEnvironment) {
  ContextOptions options;
  options.device = testing::testContext().device().name;
  ScopedEnvironment env;
  env.set("HFVIS_KERNEL_DIR", "/nonexistent/kernel/dir");
  env.set("HFVIS_LINE_LAYOUT", "diagonal");
  env.set("HFVIS_DEVICE", "no such device");
  const ComputeContext context = ComputeContext::create(options);
  EXPECT_EQ(context.options().kernel_dir, "");
  HorizonOptions horizon;
  horizon.directions = 4;
  HorizonOutputs outputs;
  outputs.sky_view_factor = true;
  const auto result = computeHorizons(context, makeSyntheticField("noise", 9, 7, 1), horizon, outputs);
  EXPECT_EQ(result.sky_view_factor.size(), 63u);
}

TEST(ComputeContext, KernelDirectoryThatLacksTheKernelsIsAnIoError) {
  ContextOptions options = ContextOptions::fromEnvironment();
  options.kernel_dir = "/nonexistent/kernel/dir";
  const ComputeContext context = ComputeContext::create(options);
  HorizonOptions horizon;
  horizon.directions = 4;
  HorizonOutputs outputs;
  outputs.sky_view_factor = true;
  EXPECT_THROW(computeHorizons(context, makeSyntheticField("noise", 9, 7, 1), horizon, outputs), IoError);
}

// A kernel directory whose kernel is a FIFO (the read blocked for good), a directory or an empty
// file (a bare OpenCL error -46): an IoError naming the file, at once.
TEST(ComputeContext, KernelFilesThatAreNotTextAreIoErrors) {
  const std::filesystem::path dir = std::filesystem::path(HFVIS_TEST_TMP_DIR) / "odd_kernels";
  HorizonOptions horizon;
  horizon.directions = 4;
  HorizonOutputs outputs;
  outputs.sky_view_factor = true;
  for (const char* kind : {"fifo", "directory", "empty"}) {
    SCOPED_TRACE(kind);
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const std::string kernel = (dir / "horizon.cl").string();
    if (std::string(kind) == "fifo") {
      ASSERT_EQ(::mkfifo(kernel.c_str(), 0600), 0);
    }
    if (std::string(kind) == "directory") std::filesystem::create_directory(kernel);
    if (std::string(kind) == "empty") std::ofstream{kernel};
    ContextOptions options = ContextOptions::fromEnvironment();
    options.kernel_dir = dir.string();
    const ComputeContext context = ComputeContext::create(options);
    try {
      computeHorizons(context, makeSyntheticField("noise", 9, 7, 1), horizon, outputs);
      ADD_FAILURE() << "a run with the kernel as a " << kind;
    } catch (const IoError& error) {
      EXPECT_EQ(error.path(), kernel);
    }
  }
  std::filesystem::remove_all(dir);
}

TEST(ComputeContext, UnknownDeviceListsTheDevices) {
  ContextOptions options;
  options.device = "no device is called this";
  try {
    ComputeContext::create(options);
    FAIL() << "a context on an unknown device";
  } catch (const NoDeviceError& error) {
    EXPECT_NE(std::string(error.what()).find(testing::testContext().device().name), std::string::npos)
        << error.what();
  }
}

// Kernel arguments go by the names the kernel source gives them: a name the kernel lacks, and a
// launch with an argument unset, are errors that name it (rather than a device error, or a
// kernel reading whatever the slot held).
TEST(NamedKernel, NamesAnUnknownOrUnsetArgument) {
  detail::ContextState& st = detail::stateOf(testing::testContext());
  const cl::Program program = st.program("insolation.cl", "");
  detail::NamedKernel kernel(st, program, "insolation_add");
  EXPECT_TRUE(kernel.has("sun_hours"));
  EXPECT_FALSE(kernel.has("sunshine"));
  try {
    kernel.set("sunshine", 1.0f);
    FAIL() << "an argument the kernel lacks was set";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("'sunshine'"), std::string::npos) << error.what();
  }
  const cl::Buffer buffer = detail::deviceBuffer(st, 4 * sizeof(float));
  kernel.set("horizon", buffer).set("normals", buffer).set("pixels", cl_uint(1)).set("steps", buffer);
  kernel.set("hours", buffer).set("n_steps", 0).set("radius", 0.1f).set("direct", buffer);
  try {
    st.launch(kernel, cl::NDRange(1), cl::NDRange(1));
    FAIL() << "a launch with an argument unset";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("'sun_hours'"), std::string::npos) << error.what();
  }
  kernel.set("sun_hours", buffer);
  EXPECT_NO_THROW(st.launch(kernel, cl::NDRange(1), cl::NDRange(1)));
  st.queue.finish();
}

}  // namespace
}  // namespace hfvis
