// oiio_module.cpp: the CLI's OpenImageIO (src/io/oiio_images.hpp), loaded on its first PNG preview
// or other image that neither GDAL nor OpenEXR takes: the module libhfvis_oiio.so beside the
// program (the build tree) or in the installed library directory. A run on GeoTIFFs and EXRs
// never loads it.
#include <dlfcn.h>
#include <unistd.h>

#include <climits>
#include <string>

#include "hfvis/errors.hpp"
#include "io/oiio_images.hpp"

#ifndef HFVIS_OIIO_MODULE_DIR
#define HFVIS_OIIO_MODULE_DIR "../lib/hfvis"
#endif

namespace hfvis::detail {
namespace {

// The directory of the running program.
std::string programDirectory() {
  char path[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", path, sizeof(path) - 1);
  if (n <= 0) return ".";
  const std::string program(path, static_cast<std::size_t>(n));
  const std::size_t slash = program.rfind('/');
  return slash == std::string::npos ? "." : program.substr(0, slash);
}

const OiioImages* loadModule() {
  const std::string dir = programDirectory();
  std::string reasons;
  for (const std::string& candidate :
       {dir + "/libhfvis_oiio.so", dir + "/" HFVIS_OIIO_MODULE_DIR "/libhfvis_oiio.so"}) {
    void* module = ::dlopen(candidate.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!module) {
      reasons += std::string(reasons.empty() ? "" : "; ") + ::dlerror();
      continue;
    }
    using Entry = const OiioImages* (*)();
    if (const auto entry = reinterpret_cast<Entry>(::dlsym(module, "hfvis_oiio_images"))) return entry();
    reasons += std::string(reasons.empty() ? "" : "; ") + candidate + " has no hfvis_oiio_images";
  }
  throw Error(
      "PNG previews and the images neither GDAL nor OpenEXR reads need OpenImageIO through the "
      "module libhfvis_oiio.so, beside the hfvis program or in " HFVIS_OIIO_MODULE_DIR
      " from it, which could not be loaded (" +
      reasons + ")");
}

}  // namespace

const OiioImages& oiioImages() {
  static const OiioImages* const table = loadModule();  // tried again after a failure
  return *table;
}

}  // namespace hfvis::detail
