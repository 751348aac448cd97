#include "dyad/private_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <random>

namespace dyad {
namespace {

mode_t FileMode(const PrivateFileOptions& o) { return o.group_readable ? 0640 : 0600; }
mode_t DirMode(const PrivateFileOptions& o) { return o.group_readable ? 0750 : 0700; }

Status Errno(const std::string& path, const char* what, int err) {
  if (err == EEXIST)
    return Status::FailedPrecondition(path, "exists: " + WhatIsAt(path) +
                                                " (a private file is never opened through an existing entry)");
  if (err == ELOOP) return Status::FailedPrecondition(path, "is " + WhatIsAt(path) + ": refused (it could point anywhere)");
  return Status::IOError(path, std::string(what) + ": " + std::strerror(err));
}

StatusOr<int> CreateExclusive(const std::string& path, const PrivateFileOptions& options) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, FileMode(options));
  if (fd < 0) return Errno(path, "create", errno);
  return fd;
}

}  // namespace

std::string WhatIsAt(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) return "nothing";
  if (S_ISLNK(st.st_mode)) {
    std::error_code ec;
    const std::filesystem::path target = std::filesystem::read_symlink(path, ec);
    return ec ? "a symbolic link" : "a symbolic link to '" + target.string() + "'";
  }
  if (S_ISDIR(st.st_mode)) return "a folder";
  if (S_ISREG(st.st_mode)) return "a file of " + std::to_string(st.st_size) + " bytes";
  return "a special file (not a regular file)";
}

Status CreatePrivateDirectories(const std::string& dir, const PrivateFileOptions& options) {
  if (dir.empty()) return Status::OK();
  std::filesystem::path partial;
  for (const auto& part : std::filesystem::path(dir)) {
    partial /= part;
    if (::mkdir(partial.c_str(), DirMode(options)) == 0 || errno == EEXIST) continue;
    return Errno(partial.string(), "create folder", errno);
  }
  struct stat st {};
  if (::stat(dir.c_str(), &st) != 0) return Errno(dir, "stat", errno);
  if (!S_ISDIR(st.st_mode)) return Status::FailedPrecondition(dir, "is not a folder");
  return Status::OK();
}

StatusOr<int> CreatePrivateFile(const std::string& path, CreateMode mode, const PrivateFileOptions& options) {
  if (mode == CreateMode::kNew) return CreateExclusive(path, options);
  // Replace: a new file of our own under a name nobody can have planted (O_EXCL), renamed onto
  // `path` (rename replaces the entry itself, a symlink included, never its target).
  std::random_device random;
  for (int attempt = 0; attempt < 8; ++attempt) {
    const std::string tmp = path + ".tmp-" + std::to_string(random());
    auto fd = CreateExclusive(tmp, options);
    if (!fd.ok() && fd.status().code() == Status::Code::kFailedPrecondition) continue;  // taken: another name
    if (!fd.ok()) return fd.status();
    if (::rename(tmp.c_str(), path.c_str()) != 0) {
      const int err = errno;
      ::close(*fd);
      ::unlink(tmp.c_str());
      return Errno(path, "replace", err);
    }
    return fd;
  }
  return Status::IOError(path, "replace: no free temporary name");
}

Status WritePrivateFile(const std::string& path, const std::string& text, CreateMode mode, const PrivateFileOptions& options) {
  auto fd = CreatePrivateFile(path, mode, options);
  if (!fd.ok()) return fd.status();
  for (size_t done = 0; done < text.size();) {
    const ssize_t n = ::write(*fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int err = errno;
      ::close(*fd);
      return Errno(path, "write", err);
    }
    done += static_cast<size_t>(n);
  }
  if (::close(*fd) != 0) return Errno(path, "close", errno);
  return Status::OK();
}

StatusOr<int> OpenPrivateLog(const std::string& path, const PrivateFileOptions& options) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_NOFOLLOW | O_CLOEXEC, FileMode(options));
  if (fd < 0) return Errno(path, "open for appending", errno);
  return fd;
}

Status SyncDirectory(const std::string& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return Errno(dir, "open the folder", errno);
  const bool ok = ::fsync(fd) == 0;
  const int err = errno;
  ::close(fd);
  return ok ? Status::OK() : Errno(dir, "fsync the folder", err);
}

}  // namespace dyad
