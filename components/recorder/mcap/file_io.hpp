// Thin RAII wrappers over POSIX files, returning Status that names the path. Private to dyad_mcap.
//
// The writer uses write(2) directly rather than stdio: every completed chunk reaches the kernel in
// one writev(2), so a SIGKILL loses at most the chunk still being filled in memory.
#pragma once

#include <sys/uio.h>

#include <cstdint>
#include <span>
#include <string>

#include "dyad/status.hpp"

namespace dyad::mcap {

class OutputFile {
 public:
  OutputFile() = default;
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  // Creates `path` private (dyad/private_file.hpp): a new file, or with `replace` one renamed
  // onto an existing entry.
  Status Open(const std::string& path, bool replace);
  // Writes every byte of every buffer (retrying short writes and EINTR).
  Status Write(std::span<const iovec> buffers);
  // fdatasync(2): survives power loss, not only process death.
  Status Sync();
  Status Close();
  bool is_open() const { return fd_ >= 0; }
  const std::string& path() const { return path_; }

 private:
  int fd_ = -1;
  std::string path_;
};

class InputFile {
 public:
  InputFile() = default;
  ~InputFile();
  InputFile(InputFile&& other) noexcept;
  InputFile& operator=(InputFile&& other) noexcept;
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  Status Open(const std::string& path);
  std::uint64_t size() const { return size_; }
  const std::string& path() const { return path_; }
  // Reads exactly out.size() bytes at `offset`; fails (DataLoss) when the file is shorter.
  Status ReadAt(std::uint64_t offset, std::span<std::uint8_t> out) const;

 private:
  int fd_ = -1;
  std::uint64_t size_ = 0;
  std::string path_;
};

}  // namespace dyad::mcap
