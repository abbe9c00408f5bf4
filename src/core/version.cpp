// version.cpp: the library's version, from the generated hfvis/version.hpp.
#include "hfvis/version.hpp"

namespace hfvis {

const char* versionString() { return HFVIS_VERSION_STRING; }

}  // namespace hfvis
