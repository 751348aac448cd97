// dyad/private_file.hpp — files of human subjects' data (recordings, logs, study data) created
// private and never through a planted link.
//
// Contract:
//   - CreatePrivateFile(path, kNew): the file must not exist; created O_EXCL | O_NOFOLLOW, mode
//     0600 (or 0640 with `group_readable`). The existence check and the creation are one step:
//     a file or symlink that appeared at `path` since anyone looked is an error
//     (FailedPrecondition naming the path: "exists"), and a link's target is never touched.
//   - CreatePrivateFile(path, kReplace): as kNew under a temporary name in the same folder, then
//     renamed onto `path`: an existing file (or symlink) is replaced as a directory entry, never
//     truncated or followed, so a link planted at `path` cannot make us overwrite its target.
//   - OpenPrivateLog(path): append (a restarted process continues its log); created 0600 if
//     absent; a symlink at `path` is refused (O_NOFOLLOW). An existing file keeps its mode.
//   - CreatePrivateDirectories(dir): creates each missing folder of `dir` with mode 0700 (0750
//     with `group_readable`); folders that exist are left as they are. The functions above
//     create no folder: call this first for a path whose folder may be missing.
//   - WritePrivateFile(path, text, mode): CreatePrivateFile, then all of `text` written and the
//     file closed (small files: keys, tokens, documents).
//   - SyncDirectory(dir): fsync of the folder itself, so a file created, renamed or removed in it
//     stays so after a power cut (the file's own data needs its own fdatasync).
//   - WhatIsAt(path): what a refusal should name: "nothing", "a symbolic link to '<target>'", "a
//     folder", "a file of N bytes", or "a special file (not a regular file)". The refusals above
//     say it ("exists: a symbolic link to '/etc/passwd' (...)").
// Every function returns a Status naming the path and the system's reason; the returned file
// descriptor is O_CLOEXEC and owned by the caller. The umask still applies (it can only remove
// permissions).
#pragma once

#include <string>

#include "dyad/status.hpp"

namespace dyad {

enum class CreateMode { kNew, kReplace };

struct PrivateFileOptions {
  bool group_readable = false;  // 0640 files and 0750 folders: a lab group may read them
};

StatusOr<int> CreatePrivateFile(const std::string& path, CreateMode mode, const PrivateFileOptions& options = {});
Status WritePrivateFile(const std::string& path, const std::string& text, CreateMode mode,
                        const PrivateFileOptions& options = {});
StatusOr<int> OpenPrivateLog(const std::string& path, const PrivateFileOptions& options = {});
Status CreatePrivateDirectories(const std::string& dir, const PrivateFileOptions& options = {});
Status SyncDirectory(const std::string& dir);
std::string WhatIsAt(const std::string& path);

}  // namespace dyad
