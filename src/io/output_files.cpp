// output_files.cpp: outputs that appear all together or not at all (OutputFiles), the checks a
// file must pass before hfvis replaces it, and the removal of temporary files on signals.
#include "io/output_files.hpp"

#include <fcntl.h>
#include <linux/fs.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "hfvis/errors.hpp"
#include "hfvis/image_io.hpp"

namespace hfvis {
namespace detail {
namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// The temporary files a signal handler removes: fixed slots, since a handler may neither
// allocate nor take a lock. A slot is claimed (kFilling) before its path is copied and published
// (kReady) after, so the handler never reads a half-written path.

constexpr int kSlots = 64;  // a run writes a handful of outputs (and their backups) at once
constexpr std::size_t kSlotPath = 4096;
enum SlotState : int { kFree = 0, kFilling = 1, kReady = 2 };
struct Slot {
  std::atomic<int> state{kFree};
  char path[kSlotPath];
};
Slot slots[kSlots];

// How many OutputFiles::commit() calls are renaming files into place: a signal then only records
// itself here, and the last commit to end ends the process once every file is where it belongs.
std::atomic<int> committing{0};
std::atomic<int> pending_signal{0};

void endOfSignal(int signal_number) {
  removeTemporaryFilesNow();
  ::signal(signal_number, SIG_DFL);
  ::raise(signal_number);
}

void onSignal(int signal_number) {
  if (committing.load()) {
    pending_signal.store(signal_number);
    return;
  }
  endOfSignal(signal_number);
}

// The signals held back for the length of a commit (in every thread: any may take the signal).
class CommitWindow {
 public:
  CommitWindow() { committing.fetch_add(1); }
  ~CommitWindow() {
    if (committing.fetch_sub(1) != 1) return;
    if (const int signal_number = pending_signal.exchange(0)) endOfSignal(signal_number);
  }
  CommitWindow(const CommitWindow&) = delete;
  CommitWindow& operator=(const CommitWindow&) = delete;
};

std::string directoryOf(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  return parent.empty() ? "." : parent.string();
}

const char* kindOf(mode_t mode) {
  if (S_ISREG(mode)) return "a file";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISSOCK(mode)) return "a socket";
  return "a special file";
}

std::string octalMode(mode_t mode) {
  char text[8];
  std::snprintf(text, sizeof(text), "%04o", static_cast<unsigned>(mode & 07777));
  return text;
}

// The file's immutable / append-only attributes (0 where the file system has none).
long attributeFlags(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0) return 0;
  long flags = 0;
  if (::ioctl(fd, FS_IOC_GETFLAGS, &flags) != 0) flags = 0;
  ::close(fd);
  return flags;
}

// Flushes a directory's entries (the renames into it) to the disk; best effort, since some
// file systems refuse fsync on directories and the files themselves are already safe.
void syncDirectory(const std::string& directory) {
  const int fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

std::string resolvedTarget(const std::string& path) {
  fs::path target(path);
  // Every link in turn (40, the kernel's own limit; a loop then fails at the write).
  for (int links = 0; links < 40; ++links) {
    std::error_code error;
    if (!fs::is_symlink(fs::symlink_status(target, error))) break;
    const fs::path next = fs::read_symlink(target, error);
    if (error) break;
    target = next.is_absolute() ? next : target.parent_path() / next;
  }
  return target.string();
}

std::string temporaryPathFor(const std::string& target) {
  static std::atomic<unsigned> counter{0};
  const fs::path path(target);
  // A stem and extension cut short keep the name within NAME_MAX (255) for any target name.
  std::string stem = path.stem().string(), extension = path.extension().string();
  if (stem.size() > 120) stem.resize(120);
  if (extension.size() > 32) extension.clear();
  const std::string name = "." + stem + ".hfvis-tmp-" + std::to_string(::getpid()) + "-" +
                           std::to_string(counter.fetch_add(1)) + extension;
  return (path.parent_path() / name).string();
}

void rememberTemporary(const std::string& path) {
  if (path.size() >= kSlotPath) return;  // not removed on a signal; the destructor still removes it
  for (Slot& slot : slots) {
    int expected = kFree;
    if (!slot.state.compare_exchange_strong(expected, kFilling)) continue;
    std::memcpy(slot.path, path.c_str(), path.size() + 1);
    slot.state.store(kReady);
    return;
  }
}

void forgetTemporary(const std::string& path) {
  for (Slot& slot : slots) {
    if (slot.state.load() == kReady && path == slot.path) {
      slot.state.store(kFree);
      return;
    }
  }
}

void removeTemporaryFilesNow() {
  for (Slot& slot : slots)
    if (slot.state.load() == kReady) ::unlink(slot.path);
}

void requireReplaceableTarget(const std::string& path, const std::string& target, bool probe) {
  const std::string directory = directoryOf(target);
  struct stat status {};
  if (::stat(directory.c_str(), &status) != 0)
    throw IoError(path, "cannot write here: the directory '" + directory + "' does not exist");
  if (!S_ISDIR(status.st_mode))
    throw IoError(
        path, "cannot write here: '" + directory + "' is " + kindOf(status.st_mode) + ", not a directory");
  const struct stat directory_status = status;
  if (::lstat(target.c_str(), &status) == 0) {
    if (S_ISDIR(status.st_mode)) throw IoError(path, "cannot write here: it is a directory");
    // (resolvedTarget follows 40 links: a link still after them is a loop, or a chain too long)
    if (S_ISLNK(status.st_mode))
      throw IoError(
          path, "cannot write here: its symbolic links lead round in a loop (or through more than 40 links)");
    if (!S_ISREG(status.st_mode))
      throw IoError(
          path, std::string("cannot write here: it is ") + kindOf(status.st_mode) + ", not a regular file");
    const long flags = attributeFlags(target);
    if (flags & FS_IMMUTABLE_FL)
      throw IoError(path, "the file is immutable (chattr +i); hfvis does not replace it");
    if (flags & FS_APPEND_FL)
      throw IoError(path, "the file is append-only (chattr +a); hfvis does not replace it");
    // A sticky directory (mode 1777, as /tmp) lets only the file's owner, the directory's or the
    // superuser replace or remove a file: the rename into place failed after the work, and the
    // second name kept for the previous file (a hard link to it, another user's) could not be
    // removed either, so it stayed.
    const uid_t user = ::geteuid();
    if ((directory_status.st_mode & S_ISVTX) && user != 0 && status.st_uid != user &&
        directory_status.st_uid != user)
      throw IoError(path, "cannot replace it: the directory '" + directory + "' is sticky (mode " +
                              octalMode(directory_status.st_mode) +
                              ") and the file belongs to another user; write to another name or directory");
    const bool writable = ::faccessat(AT_FDCWD, target.c_str(), W_OK, AT_EACCESS) == 0;
    // (a read-only file system first: its files' modes allow writing, and chmod would not help)
    if (!writable && errno == EROFS)
      throw IoError(path, "cannot write here: the file system is mounted read-only");
    if (!writable || (status.st_mode & 0222) == 0)
      throw IoError(path, "the file is write-protected (mode " + octalMode(status.st_mode) +
                              "); hfvis replaces only a file that could be written in place (chmod u+w "
                              "to allow it)");
  }
  if (::faccessat(AT_FDCWD, directory.c_str(), W_OK | X_OK, AT_EACCESS) != 0)
    throw IoError(path, errno == EROFS
                            ? "cannot write here: the file system is mounted read-only"
                            : "cannot write here: no permission to create files in '" + directory + "'");
  // The permission bits do not tell it all: root passes them in /proc and /sys, whose directories
  // take no new files, and an immutable directory refuses them whatever its mode. A file created
  // and removed at once shows that the write will be taken, before any work. Its name is no
  // output's temporary one (a staged output is known by that), and it is remembered for the
  // signal handlers before it exists (a name a killed run left is passed over).
  if (!probe) return;
  static std::atomic<unsigned> probes{0};
  for (int attempt = 0;; ++attempt) {
    const std::string name = (fs::path(target).parent_path() / (".hfvis-probe-" + std::to_string(::getpid()) +
                                                                "-" + std::to_string(probes.fetch_add(1))))
                                 .string();
    rememberTemporary(name);
    const int fd = ::open(name.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    const int error = errno;
    if (fd >= 0) {
      ::close(fd);
      ::unlink(name.c_str());
    }
    forgetTemporary(name);
    if (fd >= 0) return;
    if (error == EEXIST && attempt < 8) continue;
    throw IoError(path, "cannot write here: creating a file in '" + directory + "' fails (" +
                            writeFailure(error) + ")");
  }
}

void requireInputFile(const std::string& path) {
  struct stat status {};
  if (::stat(path.c_str(), &status) != 0) {
    if (errno == ENOENT || errno == ENOTDIR) throw IoError(path, "no such file");
    throw IoError(path, std::string("cannot read: ") + std::strerror(errno));
  }
  if (S_ISDIR(status.st_mode)) throw IoError(path, "is a directory, not a file");
  if (!S_ISREG(status.st_mode))
    throw IoError(path,
                  std::string("is ") + kindOf(status.st_mode) + ", not a regular file; hfvis reads files");
  if (status.st_size == 0) throw IoError(path, "file is empty (0 bytes)");
}

void writeFileChecked(const std::string& file, const std::string& path, const void* data, std::size_t size) {
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) throw IoError(path, "cannot create the file: " + writeFailure(errno));
  const char* bytes = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t written = ::write(fd, bytes, size);
    if (written < 0 && errno == EINTR) continue;
    if (written <= 0) {
      const int error = written < 0 ? errno : ENOSPC;
      ::close(fd);
      throw IoError(path, "cannot write: " + writeFailure(error));
    }
    bytes += written;
    size -= static_cast<std::size_t>(written);
  }
  if (::fsync(fd) != 0) {
    const int error = errno;
    ::close(fd);
    throw IoError(path, "cannot write: " + writeFailure(error));
  }
  if (::close(fd) != 0) throw IoError(path, "cannot write: " + writeFailure(errno));
}

int likelyWriteError(const std::string& file) {
  struct statvfs space {};
  // (a write that failed for want of space may still leave a few blocks that a smaller write took)
  if (::statvfs(directoryOf(file).c_str(), &space) == 0 &&
      static_cast<double>(space.f_bavail) * static_cast<double>(space.f_frsize) < 1048576.0)
    return ENOSPC;
  rlimit limit{};
  struct stat status {};
  if (::getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY &&
      ::stat(file.c_str(), &status) == 0 && static_cast<rlim_t>(status.st_size) >= limit.rlim_cur)
    return EFBIG;
  return 0;
}

std::vector<std::string> geoTiffSideFiles(const std::string& path) {
  std::vector<std::string> found;
  std::vector<std::pair<dev_t, ino_t>> seen;  // (a directory that ignores case finds one file twice)
  // PATH + suffix; and a TIFF's world files, STEM + ending (no other image's: a PNG's is .pgw).
  // A world file goes only where no other TIFF of the stem may own it (STEM.tif beside STEM.tiff).
  constexpr const char* kEndings[] = {".aux.xml", ".aux", ".ovr", ".msk", "+.tfw", "+.tifw", "+.tiffw"};
  const auto shared_stem = [](const std::string& base) {
    struct stat own {};
    const bool exists = ::stat(base.c_str(), &own) == 0;
    for (const char* extension : {".tif", ".tiff", ".TIF", ".TIFF"}) {
      struct stat other {};
      const std::string name = fs::path(base).replace_extension(extension).string();
      if (name != base && ::stat(name.c_str(), &other) == 0 &&
          !(exists && other.st_dev == own.st_dev && other.st_ino == own.st_ino))
        return true;
    }
    return false;
  };
  for (const std::string& base : {path, resolvedTarget(path)}) {
    const bool stem_shared = shared_stem(base);
    for (const char* suffix : kEndings)
      for (const bool upper : {false, true}) {
        const bool of_stem = suffix[0] == '+';
        if (of_stem && stem_shared) continue;
        std::string ending = suffix + (of_stem ? 1 : 0);
        if (upper)
          std::transform(ending.begin(), ending.end(), ending.begin(),
                         [](unsigned char c) { return std::toupper(c); });
        const std::string side =
            of_stem ? fs::path(base).replace_extension().string() + ending : base + ending;
        struct stat status {};
        if (::lstat(side.c_str(), &status) != 0 || !(S_ISREG(status.st_mode) || S_ISLNK(status.st_mode)))
          continue;
        const std::pair<dev_t, ino_t> id{status.st_dev, status.st_ino};
        if (std::find(seen.begin(), seen.end(), id) != seen.end()) continue;
        seen.push_back(id);
        found.push_back(side);
      }
  }
  return found;
}

void syncFile(const std::string& file, const std::string& path) {
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw IoError(path, "cannot write: " + writeFailure(errno));
  const int result = ::fsync(fd), error = errno;
  ::close(fd);
  if (result != 0) throw IoError(path, "cannot write: " + writeFailure(error));
}

}  // namespace detail

void requireReplaceable(const std::string& path) {
  detail::requireReplaceableTarget(path, detail::resolvedTarget(path), true);
}

OutputFiles::~OutputFiles() { discard(); }

void OutputFiles::discard() noexcept {
  for (const Entry& entry : entries_) {
    ::unlink(entry.temp.c_str());
    detail::forgetTemporary(entry.temp);
  }
  entries_.clear();
}

void OutputFiles::protect(const std::vector<std::string>& inputs) {
  for (const std::string& input : inputs) {
    struct stat status {};
    if (!input.empty() && ::stat(input.c_str(), &status) == 0)
      inputs_.push_back({input, status.st_dev, status.st_ino});
  }
}

void OutputFiles::requireNotAnInput(const std::string& path, const std::string& file) const {
  struct stat status {};
  if (inputs_.empty() || ::stat(file.c_str(), &status) != 0) return;
  for (const Protected& input : inputs_)
    if (input.device == status.st_dev && input.inode == status.st_ino)
      throw IoError(path, "names the input '" + input.path +
                              "' now (a link or directory changed during the run): outputs never replace an "
                              "input; nothing was written");
}

std::vector<std::string> OutputFiles::paths() const {
  std::vector<std::string> paths;
  for (const Entry& entry : entries_) paths.push_back(entry.path);
  return paths;
}

void OutputFiles::stage(const std::string& path, const std::function<void(const std::string&)>& write,
                        bool geotiff) {
  const std::string target = detail::resolvedTarget(path);
  for (const Entry& entry : entries_)
    if (std::filesystem::path(entry.target).lexically_normal() ==
        std::filesystem::path(target).lexically_normal())
      throw InvalidArgument("'" + path + "' is staged twice (as '" + entry.path + "')");
  detail::requireReplaceableTarget(path, target);
  requireNotAnInput(path, target);
  const std::string temp = detail::temporaryPathFor(target);
  detail::rememberTemporary(temp);
  entries_.push_back({path, target, temp, geotiff});
  write(temp);
}

void OutputFiles::commit() {
  const detail::CommitWindow window;
  // A long run gives time for a target to change: each is checked again right before.
  try {
    for (const Entry& entry : entries_) {
      detail::requireReplaceableTarget(entry.path, entry.target);
      requireNotAnInput(entry.path, entry.target);
      if (entry.geotiff)
        for (const std::string& side : detail::geoTiffSideFiles(entry.path))
          requireNotAnInput(entry.path, side);
    }
  } catch (...) {
    discard();
    throw;
  }
  // Each file in place keeps what it replaced (`backup`: a second name for the previous file)
  // until every rename has succeeded, so that a failure can put all of them back.
  struct Placed {
    const Entry* entry;
    std::string backup;  // "" where no file was there
    std::vector<std::pair<std::string, std::string>> sides;  // side files set aside: (name, aside)
  };
  std::vector<Placed> placed;
  const auto restore = [](const Placed& p) {
    const Entry& entry = *p.entry;
    if (p.backup.empty()) {
      ::unlink(entry.target.c_str());
    } else {
      ::rename(p.backup.c_str(), entry.target.c_str());
      ::unlink(p.backup.c_str());  // a hard link to the target itself: rename(2) left it
    }
    for (const auto& [name, aside] : p.sides) ::rename(aside.c_str(), name.c_str());
  };
  // (`current`: the entry being placed, its side files set aside so far)
  Placed current{nullptr, "", {}};
  const auto fail = [&](const Entry& entry, const std::string& reason) {
    const std::string path = entry.path;  // (discard() takes the entries)
    for (const auto& [name, aside] : current.sides) ::rename(aside.c_str(), name.c_str());
    for (auto it = placed.rbegin(); it != placed.rend(); ++it) restore(*it);
    discard();
    throw IoError(path, reason);
  };
  for (const Entry& entry : entries_) {
    current = {&entry, "", {}};
    if (entry.geotiff)
      for (const std::string& side : detail::geoTiffSideFiles(entry.path)) {
        // (an output of this commit at such a name is what the caller asked for)
        if (std::any_of(entries_.begin(), entries_.end(), [&](const Entry& other) {
              return std::filesystem::path(other.target).lexically_normal() ==
                     std::filesystem::path(detail::resolvedTarget(side)).lexically_normal();
            }))
          continue;
        const std::string aside = detail::temporaryPathFor(side);
        if (::rename(side.c_str(), aside.c_str()) != 0)
          fail(entry, "cannot set aside '" + side +
                          "', which GDAL would read with the new file: " + detail::writeFailure(errno));
        current.sides.emplace_back(side, aside);
      }
    std::string backup;
    struct stat previous {};
    if (::lstat(entry.target.c_str(), &previous) == 0) {
      // The replaced file's owner (where this user may give it, as the superuser may; else the
      // new file is this user's, as any file it writes) and permissions stay, as they would for
      // a write in place.
      [[maybe_unused]] const int owned = ::chown(entry.temp.c_str(), previous.st_uid, previous.st_gid);
      ::chmod(entry.temp.c_str(), previous.st_mode & 07777);
      backup = detail::temporaryPathFor(entry.target);
      // A hard link keeps the previous file at its name until the rename replaces it; where the
      // file system has none, it is moved aside instead.
      if (::link(entry.target.c_str(), backup.c_str()) != 0 &&
          ::rename(entry.target.c_str(), backup.c_str()) != 0)
        fail(entry, "cannot set the previous file aside: " + detail::writeFailure(errno));
    }
    if (::rename(entry.temp.c_str(), entry.target.c_str()) != 0) {
      const int error = errno;
      if (!backup.empty()) {
        ::rename(backup.c_str(), entry.target.c_str());
        ::unlink(backup.c_str());
      }
      fail(entry, std::string("cannot move the finished file into place: ") +
                      (error == EISDIR ? "a directory is there now" : detail::writeFailure(error)));
    }
    detail::forgetTemporary(entry.temp);
    current.backup = backup;
    placed.push_back(current);
    current = {nullptr, "", {}};
  }
  for (const Placed& p : placed) {
    if (!p.backup.empty()) ::unlink(p.backup.c_str());
    for (const auto& side : p.sides) {
      ::unlink(side.second.c_str());
      detail::syncDirectory(detail::directoryOf(side.first));
    }
    detail::syncDirectory(detail::directoryOf(p.entry->target));
  }
  entries_.clear();
}

void removeTemporaryOutputsOnSignals() {
  // The signals that end a process by default, bar a fault's: a CPU time limit (SIGXCPU, ulimit
  // -t) and an alarm left the temporary files behind (a probe's find). Only where the default is
  // in force: a handler of the program's own (a profiler's SIGPROF) or an ignored signal (nohup's
  // SIGHUP) stays as it is.
  for (const int signal_number :
       {SIGINT, SIGTERM, SIGHUP, SIGXCPU, SIGALRM, SIGVTALRM, SIGPROF, SIGUSR1, SIGUSR2, SIGPIPE}) {
    struct sigaction current {};
    if (::sigaction(signal_number, nullptr, &current) != 0 || (current.sa_flags & SA_SIGINFO) ||
        current.sa_handler != SIG_DFL)
      continue;
    struct sigaction action {};
    action.sa_handler = detail::onSignal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;
    ::sigaction(signal_number, &action, nullptr);
  }
}

}  // namespace hfvis
