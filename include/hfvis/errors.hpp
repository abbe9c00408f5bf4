// hfvis/errors.hpp: the typed exceptions every hfvis operation throws.
// Library code throws; only the CLI turns these into a message and an exit status.
#pragma once

#include <stdexcept>
#include <string>

namespace hfvis {

// Base of every hfvis error; what() is a complete sentence for a user.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// An argument or option out of its valid range (K = 0, negative cell size, ...).
class InvalidArgument : public Error {
 public:
  using Error::Error;
};

// A file that could not be read or written: names the file and the reason.
class IoError : public Error {
 public:
  IoError(const std::string& path, const std::string& reason)
      : Error(path + ": " + reason), path_(path), reason_(reason) {}
  const std::string& path() const { return path_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string path_;
  std::string reason_;
};

// No OpenCL platform or no matching device; the message says how to get one.
class NoDeviceError : public Error {
 public:
  using Error::Error;
};

// An OpenCL call failed: the call's name and its error code.
class OpenClError : public Error {
 public:
  OpenClError(const std::string& call, int code)
      : Error(call + " failed with OpenCL error " + std::to_string(code)), call_(call), code_(code) {}
  const std::string& call() const { return call_; }
  int code() const { return code_; }

 private:
  std::string call_;
  int code_;
};

// A kernel program failed to build; carries the device's build log.
class KernelBuildError : public Error {
 public:
  KernelBuildError(const std::string& program, const std::string& log)
      : Error("building OpenCL program '" + program + "' failed:\n" + log), log_(log) {}
  const std::string& log() const { return log_; }

 private:
  std::string log_;
};

// The request cannot fit the memory budget even one direction at a time.
class MemoryBudgetError : public Error {
 public:
  using Error::Error;
};

}  // namespace hfvis
