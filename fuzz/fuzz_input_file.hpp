// fuzz_input_file.hpp: the file-reading fuzzers' input as a file. The input's first byte picks
// the file's extension from `extensions`, the rest is the file's bytes; the file lives in /tmp
// under the process id (parallel fuzzing jobs never share one) and is removed on destruction.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

class FuzzInputFile {
 public:
  template <std::size_t N>
  FuzzInputFile(const char* name, const std::uint8_t* data, std::size_t size, const char* const (&extensions)[N])
      : path_("/tmp/hfvis_fuzz_" + std::string(name) + "_" + std::to_string(::getpid()) + extensions[data[0] % N]) {
    if (std::FILE* f = std::fopen(path_.c_str(), "wb")) {
      written_ = std::fwrite(data + 1, 1, size - 1, f) == size - 1;
      written_ = std::fclose(f) == 0 && written_;
    }
  }
  FuzzInputFile(const FuzzInputFile&) = delete;
  FuzzInputFile& operator=(const FuzzInputFile&) = delete;
  ~FuzzInputFile() { std::remove(path_.c_str()); }

  // Whether the file holds the input (else the run has nothing to test).
  bool written() const { return written_; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  bool written_ = false;
};
