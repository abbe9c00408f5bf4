// output_files.hpp: the file-system side of writing outputs (output_files.cpp): temporary files
// beside their targets that a signal handler can remove, the checks a target must pass before
// hfvis replaces it, and durable writes whose every error is reported.
#pragma once

#include <sys/resource.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <vector>

namespace hfvis::detail {

// Where a write to `path` lands: `path` itself, or the file a symbolic link at `path` points to
// (followed through every link), so that replacing it keeps the link and updates what it names.
std::string resolvedTarget(const std::string& path);

// A temporary file name beside `target` (same directory, same extension, so that the same
// writer takes it), unique to this process and call, and short enough for any file name.
std::string temporaryPathFor(const std::string& target);

// Records `path` as a temporary file for removeTemporaryFilesNow(); forgetTemporary() removes
// the record. Both are cheap and safe against a signal arriving while they run.
void rememberTemporary(const std::string& path);
void forgetTemporary(const std::string& path);

// Removes every remembered temporary file: async-signal-safe (only unlink(2)).
void removeTemporaryFilesNow();

// Throws IoError naming `path` when hfvis must not replace the file at `target` (the resolved
// path): see requireReplaceable in hfvis/image_io.hpp. `probe`: also create a file in its
// directory and remove it (the check before any work: whether the directory takes files at all;
// staging and committing need no such probe, their temporary files show it).
void requireReplaceableTarget(const std::string& path, const std::string& target, bool probe = false);

// Throws IoError naming `path` unless it is a regular file with something in it: a directory,
// a device (/dev/zero would be read forever), a FIFO or a socket is refused before it is opened.
void requireInputFile(const std::string& path);

// Writes `size` bytes to the file `file` (created or truncated), flushes them to the disk and
// closes it, every step checked: an IoError naming `path` with the system's reason otherwise.
void writeFileChecked(const std::string& file, const std::string& path, const void* data, std::size_t size);

// Why a write to `file` that a library reported in its own words failed, where that can be told
// afterwards: ENOSPC when its file system has less than 1 MiB left, EFBIG when the file reached
// the file size limit; 0 otherwise.
int likelyWriteError(const std::string& file);

// The files GDAL reads beside a GeoTIFF at `path` as part of it that exist, regular files or links
// (each file once): PATH.aux.xml, PATH.aux, PATH.ovr and PATH.msk, in lower or upper case, beside
// `path` and beside the file a link there names. Writing a GeoTIFF there takes them away
// (OutputFiles in hfvis/image_io.hpp).
std::vector<std::string> geoTiffSideFiles(const std::string& path);

// Flushes an already written file to the disk (fsync), or throws IoError naming `path`.
void syncFile(const std::string& file, const std::string& path);

// The reason for a failed write with the error number `error`, in words for a user. Inline:
// the OpenImageIO module (oiio_images.cpp) has no other part of the library to call.
inline std::string writeFailure(int error) {
  switch (error) {
    case ENOSPC:
      return "no space left on device";
    case EDQUOT:
      return "disk quota exceeded";
    case EROFS:
      return "read-only file system";
    case EFBIG: {
      rlimit limit{};
      if (::getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
        return "the file would exceed the file size limit (ulimit -f) of " + std::to_string(limit.rlim_cur) +
               " bytes";
      return "the file is too large for this file system";
    }
    default:
      return std::strerror(error);
  }
}

}  // namespace hfvis::detail
