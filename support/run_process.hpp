// support/run_process.hpp: run a program and wait for it (the CLI's helpers: the plot scripts, a
// sweep's runs; the learner component's trainer). Below the components (support/CMakeLists.txt);
// the namespace is dyad::tools, its first users'.
//
// Contract of RunProcess(args, log):
//   - args[0] is a path, or a name looked up in PATH; the child inherits the environment.
//   - `log` empty: the child writes to our stdout and stderr; else both go to that file
//     (created 0600, or truncated).
//   - Returns the child's exit status, 128 + N when signal N ended it, 127 when it could not be
//     started. Thread-safe (each call waits for its own child only).
// StartProcess(args, log, own_group) and WaitProcess(pid): the same in two halves, for a caller
// that signals the child meanwhile; own_group puts the child in a process group of its own, so a
// terminal's Ctrl-C reaches only the caller (which decides what the child gets), and the child
// gets SIGINT when the caller dies (a graph is never left running unsupervised). StartProcess
// returns -1 when no child could be made (127 from WaitProcess when the program could not be
// started); WaitProcess returns as RunProcess does.
// RunDyadScript(name, args): runs share/dyad/NAME (a Python script installed beside the `dyad`
// executable's bin/, in the build tree and the installed tree alike) with Debian's python3 (which
// has python3-matplotlib), arguments `args`; returns as RunProcess, 127 when the script is not
// there. DyadScriptPath(name) is where it is looked for.
// ShellQuoted(args): the command line a POSIX shell turns back into exactly `args` (arguments
// with anything but [A-Za-z0-9_./=:,+@%-] in single quotes), for logs and generated scripts.
#pragma once

#include <string>
#include <vector>

namespace dyad::tools {

int RunProcess(const std::vector<std::string>& args, const std::string& log = "");
int StartProcess(const std::vector<std::string>& args, const std::string& log, bool own_group);
int WaitProcess(int pid);
bool ProcessEnded(int pid, int* status);  // without waiting: true (and *status as above) once it has
std::string ThisExecutable();  // /proc/self/exe: the running dyad (its runs and jobs run it again); "" if unknown
std::string DyadScriptPath(const std::string& name);
int RunDyadScript(const std::string& name, const std::vector<std::string>& args);
std::string ShellQuoted(const std::vector<std::string>& args);

}  // namespace dyad::tools
