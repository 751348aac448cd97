#include "hosts/output_relay.hpp"

#include "dyad/private_file.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/uio.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>

namespace dyad {

LogFile::~LogFile() { close(fd_); }

void LogFile::AppendLine(const std::string& line) {
  // One writev of the line and its newline (no copy per line); a short write finishes the rest.
  char newline = '\n';
  iovec parts[2] = {{const_cast<char*>(line.data()), line.size()}, {&newline, 1}};
  size_t done = 0;
  const size_t total = line.size() + 1;
  while (done < total) {
    const ssize_t n = done == 0 ? writev(fd_, parts, 2)
                                : done < line.size() ? write(fd_, line.data() + done, line.size() - done)
                                                     : write(fd_, &newline, 1);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    done += static_cast<size_t>(n);
  }
}

OutputRelay::OutputRelay(std::ostream& out, std::ostream& err) : out_(out), err_(err) {
  if (pipe2(wake_, O_CLOEXEC) != 0) wake_[0] = wake_[1] = -1;
  thread_ = std::thread([this] { Run(); });
}

OutputRelay::~OutputRelay() {
  {
    MutexLock lock(mutex_);
    closing_ = true;
  }
  if (wake_[1] >= 0) (void)!write(wake_[1], "x", 1);
  thread_.join();
  for (int fd : wake_)
    if (fd >= 0) close(fd);
}

StatusOr<OutputRelay::Pipes> OutputRelay::Add(const std::string& name, const std::string& log_path, const std::string& header) {
  int out_pipe[2], err_pipe[2];
  // Read ends close on exec: another child must not hold them (they would never see EOF).
  if (pipe2(out_pipe, O_CLOEXEC) != 0) return Status::IOError("pipe: " + std::string(std::strerror(errno)));
  if (pipe2(err_pipe, O_CLOEXEC) != 0) {
    close(out_pipe[0]);
    close(out_pipe[1]);
    return Status::IOError("pipe: " + std::string(std::strerror(errno)));
  }
  std::shared_ptr<LogFile> log;
  {
    MutexLock lock(mutex_);
    if (!log_path.empty()) {
      auto& open = logs_[log_path];
      if (!open) {
        Status folder = CreatePrivateDirectories(std::filesystem::path(log_path).parent_path().string());
        auto fd = folder.ok() ? OpenPrivateLog(log_path) : StatusOr<int>(folder);
        if (fd.ok()) open = std::make_shared<LogFile>(*fd);
        else err_ << "[" << name << "] warning: cannot write its log: " << fd.status().message() << "\n";
      }
      log = open;
      if (log) log->AppendLine(header);
    }
    sources_[out_pipe[0]] = Source{name, false, "", log};
    sources_[err_pipe[0]] = Source{name, true, "", log};
  }
  if (wake_[1] >= 0) (void)!write(wake_[1], "x", 1);
  return Pipes{out_pipe[1], err_pipe[1]};
}

void OutputRelay::CloseWriteEnds(const Pipes& pipes) {
  if (pipes.out_write >= 0) close(pipes.out_write);
  if (pipes.err_write >= 0) close(pipes.err_write);
}

void OutputRelay::Say(const std::string& line) {
  MutexLock lock(mutex_);
  err_ << line << (line.empty() || line.back() != '\n' ? "\n" : "") << std::flush;
}

void OutputRelay::Emit(const Source& s, const std::string& line) {
  (s.is_err ? err_ : out_) << "[" << s.name << "] " << line << "\n" << std::flush;
  if (s.log) s.log->AppendLine(line);
}

void OutputRelay::Run() {
  std::vector<pollfd> fds;
  char buf[4096];
  std::chrono::steady_clock::time_point give_up{};
  for (;;) {
    fds.clear();
    {
      MutexLock lock(mutex_);
      if (closing_ && sources_.empty()) return;
      // Every child has exited; a pipe still open is held by something a child left behind
      // (a process a component started): what it says after kCloseGraceMs is not waited for.
      if (closing_ && give_up == std::chrono::steady_clock::time_point{})
        give_up = std::chrono::steady_clock::now() + std::chrono::milliseconds(kCloseGraceMs);
      if (closing_ && std::chrono::steady_clock::now() >= give_up) {
        for (auto& [fd, source] : sources_) {
          if (!source.partial.empty()) Emit(source, source.partial);
          close(fd);
        }
        sources_.clear();
        return;
      }
      fds.push_back({wake_[0], POLLIN, 0});
      for (const auto& [fd, _] : sources_) fds.push_back({fd, POLLIN, 0});
    }
    if (poll(fds.data(), fds.size(), 200) < 0 && errno != EINTR) {
      // Cannot happen with valid descriptors; say so rather than let the children block on
      // full pipes unnoticed.
      MutexLock lock(mutex_);
      err_ << "dyad run: the output relay failed (poll: " << std::strerror(errno) << "); children's output is lost\n";
      return;
    }
    if (fds[0].revents & POLLIN) (void)!read(wake_[0], buf, sizeof(buf));
    for (size_t i = 1; i < fds.size(); ++i) {
      if (fds[i].revents == 0) continue;
      const ssize_t n = read(fds[i].fd, buf, sizeof(buf));
      MutexLock lock(mutex_);
      Source& s = sources_[fds[i].fd];
      if (n > 0) {
        s.partial.append(buf, static_cast<size_t>(n));
        size_t start = 0, nl;
        while ((nl = s.partial.find('\n', start)) != std::string::npos) {
          Emit(s, s.partial.substr(start, nl - start));
          start = nl + 1;
        }
        s.partial.erase(0, start);
      } else if (n == 0 || (errno != EINTR && errno != EAGAIN)) {  // the child closed it (exited)
        if (!s.partial.empty()) Emit(s, s.partial);
        close(fds[i].fd);
        sources_.erase(fds[i].fd);
      }
    }
  }
}

}  // namespace dyad
