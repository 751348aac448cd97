#include "file_io.hpp"

#include "dyad/private_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstring>
#include <utility>
#include <vector>

namespace dyad::mcap {
namespace {

std::string Errno(const char* what) { return std::string(what) + ": " + std::strerror(errno); }

}  // namespace

OutputFile::~OutputFile() {
  if (fd_ >= 0) ::close(fd_);
}

Status OutputFile::Open(const std::string& path, bool replace) {
  path_ = path;
  auto fd = CreatePrivateFile(path, replace ? CreateMode::kReplace : CreateMode::kNew);
  if (!fd.ok()) return fd.status();
  fd_ = *fd;
  return Status::OK();
}

Status OutputFile::Write(std::span<const iovec> buffers) {
  // Local copy: a short write advances the iovecs.
  iovec local[8];
  std::vector<iovec> heap;
  iovec* iov = local;
  if (buffers.size() > 8) {
    heap.assign(buffers.begin(), buffers.end());
    iov = heap.data();
  } else {
    std::copy(buffers.begin(), buffers.end(), local);
  }
  std::size_t count = buffers.size();
  while (count > 0) {
    int n = static_cast<int>(std::min<std::size_t>(count, IOV_MAX));
    ssize_t written = ::writev(fd_, iov, n);
    if (written < 0) {
      if (errno == EINTR) continue;
      return Status::IOError(path_, Errno("write"));
    }
    auto left = static_cast<std::size_t>(written);
    while (count > 0 && left >= iov->iov_len) {
      left -= iov->iov_len;
      ++iov;
      --count;
    }
    if (count > 0) {
      iov->iov_base = static_cast<char*>(iov->iov_base) + left;
      iov->iov_len -= left;
    }
  }
  return Status::OK();
}

Status OutputFile::Sync() {
  if (::fdatasync(fd_) != 0) return Status::IOError(path_, Errno("fdatasync"));
  return Status::OK();
}

Status OutputFile::Close() {
  int fd = std::exchange(fd_, -1);
  if (fd >= 0 && ::close(fd) != 0) return Status::IOError(path_, Errno("close"));
  return Status::OK();
}

InputFile::~InputFile() {
  if (fd_ >= 0) ::close(fd_);
}

InputFile::InputFile(InputFile&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)), size_(other.size_), path_(std::move(other.path_)) {}

InputFile& InputFile::operator=(InputFile&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
    size_ = other.size_;
    path_ = std::move(other.path_);
  }
  return *this;
}

Status InputFile::Open(const std::string& path) {
  path_ = path;
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) return Status::IOError(path_, Errno("open for reading"));
  struct stat st {};
  if (::fstat(fd_, &st) != 0) return Status::IOError(path_, Errno("stat"));
  if (!S_ISREG(st.st_mode)) return Status::InvalidArgument(path_, "not a regular file");
  size_ = static_cast<std::uint64_t>(st.st_size);
  return Status::OK();
}

Status InputFile::ReadAt(std::uint64_t offset, std::span<std::uint8_t> out) const {
  std::size_t done = 0;
  while (done < out.size()) {
    ssize_t n = ::pread(fd_, out.data() + done, out.size() - done, static_cast<off_t>(offset + done));
    if (n < 0) {
      if (errno == EINTR) continue;
      return Status::IOError(path_, Errno("read"));
    }
    if (n == 0) {
      return Status::DataLoss(path_, "unexpected end of file at offset " + std::to_string(offset + done));
    }
    done += static_cast<std::size_t>(n);
  }
  return Status::OK();
}

}  // namespace dyad::mcap
