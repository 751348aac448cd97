// OutputRelay — the launcher's view of its children's output (internal to the runtime).
//
// Each child's stdout and stderr arrive on pipes; a thread of the relay reads them all (poll)
// and passes every line on to the launcher's own stdout or stderr prefixed with the process's
// name ("[mind] ..."), and appends it, unprefixed, to the process's log file when there is one
// (a restarted process appends to the same file after a header line). Log files are private:
// created 0600 in folders created 0700, never through a symlink (dyad/private_file.hpp). The launcher's own
// messages go through Say() so lines never interleave mid-line. A partial last line is passed
// on when its pipe closes.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <ostream>
#include <string>
#include <thread>
#include <vector>

#include <dyad/status.hpp>
#include <dyad/thread_annotations.hpp>

namespace dyad {

// One process's log file, appended to with write(2). Owns the descriptor.
class LogFile {
 public:
  explicit LogFile(int fd) : fd_(fd) {}
  ~LogFile();
  LogFile(const LogFile&) = delete;
  LogFile& operator=(const LogFile&) = delete;
  void AppendLine(const std::string& line);  // a write error is ignored: the line still reached the terminal

 private:
  int fd_;
};

class OutputRelay {
 public:
  OutputRelay(std::ostream& out, std::ostream& err);
  // Reads until every pipe added so far has closed (every child exited), then stops; a pipe
  // still open kCloseGraceMs after that (held by a grandchild) is closed unread.
  static constexpr int kCloseGraceMs = 2000;
  ~OutputRelay();
  OutputRelay(const OutputRelay&) = delete;
  OutputRelay& operator=(const OutputRelay&) = delete;

  // Pipes for one child's stdout and stderr: the child dup2()s the write ends onto 1 and 2;
  // the caller closes them in the parent after fork (CloseWriteEnds). `log_path` empty: no file.
  struct Pipes {
    int out_write = -1, err_write = -1;
  };
  StatusOr<Pipes> Add(const std::string& name, const std::string& log_path, const std::string& header);
  static void CloseWriteEnds(const Pipes& pipes);

  // A line of the launcher's own, to its stderr.
  void Say(const std::string& line);

 private:
  struct Source {
    std::string name;
    bool is_err = false;
    std::string partial;
    std::shared_ptr<LogFile> log;
  };
  void Run();
  void Emit(const Source& s, const std::string& line) REQUIRES(mutex_);

  std::ostream& out_;
  std::ostream& err_;
  // Guards sources_, logs_, closing_ and the streams (out_, err_: by convention, not checked).
  Mutex mutex_;
  std::map<int, Source> sources_ GUARDED_BY(mutex_);                         // read end -> its child
  std::map<std::string, std::shared_ptr<LogFile>> logs_ GUARDED_BY(mutex_);  // log path -> open file
  int wake_[2] = {-1, -1};  // a byte here makes the thread re-read sources_
  bool closing_ GUARDED_BY(mutex_) = false;
  std::thread thread_;
};

}  // namespace dyad
