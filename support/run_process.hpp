// support/run_process.hpp: run a program and wait for it (the CLI's helpers: the plot scripts, a
// sweep's runs; the learner component's trainer). Below the components (support/CMakeLists.txt);
// the namespace is dyad::tools, its first users'.
//
// RunProcess(args, log): runs `args` (child_process.hpp: args[0] a path, or a name looked up in
// PATH; our environment) and waits for it. `log` empty: the child writes to our stdout and
// stderr; else both go to that file (created 0600, or truncated). Returns how it ended (an
// ExitStatus: exited with its code, killed by a signal, never started and why). Thread-safe
// (each call waits for its own child only). A caller that signals the child meanwhile, or
// watches it, uses ChildProcess itself.
// RunDyadScript(name, args): runs share/dyad/NAME (a Python script installed beside the `dyad`
// executable's bin/, in the build tree and the installed tree alike) with Debian's python3 (which
// has python3-matplotlib), arguments `args`; returns as RunProcess (never started, ENOENT, when
// the script is not there). DyadScriptPath(name) is where it is looked for.
// ShellQuoted(args): the command line a POSIX shell turns back into exactly `args` (arguments
// with anything but [A-Za-z0-9_./=:,+@%-] in single quotes), for logs and generated scripts.
#pragma once

#include <string>
#include <vector>

#include "child_process.hpp"

namespace dyad::tools {

ExitStatus RunProcess(const std::vector<std::string>& args, const std::string& log = "");
std::string ThisExecutable();  // /proc/self/exe: the running dyad (its runs and jobs run it again); "" if unknown
std::string DyadScriptPath(const std::string& name);
ExitStatus RunDyadScript(const std::string& name, const std::vector<std::string>& args);
std::string ShellQuoted(const std::vector<std::string>& args);

}  // namespace dyad::tools
