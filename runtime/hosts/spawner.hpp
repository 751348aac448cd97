// Spawner — starts the launcher's children (internal to the runtime; the launcher is
// launcher.cpp).
//
// Each child is the dyad executable (RunOptions::executable: this program unless told otherwise)
// run with the arguments given (`dyad run GRAPH --process P ...`, `dyad discovery-server ...`):
//   - in its own process group: a terminal's Ctrl-C reaches the launcher only, which forwards it
//     once (a child hit by both would take the second as "exit now" and skip its clean shutdown);
//   - ended with SIGTERM if the launcher dies (SIGKILL) rather than running on unwatched;
//   - with its stdout and stderr on pipes of the launcher's OutputRelay (and in its log file,
//     after a header line), every other descriptor of the launcher closed (its DDS sockets, the
//     other children's pipes), no signal blocked, the launcher's environment.
#pragma once

#include <sys/types.h>

#include <string>
#include <vector>

#include <dyad/status.hpp>

#include "hosts/output_relay.hpp"

namespace dyad {

class Spawner {
 public:
  // `executable`: the dyad binary to exec. `relay` (not owned) outlives the spawner. `host`: this
  // machine's name in the graph, for the log's header line.
  Spawner(std::string executable, OutputRelay* relay, std::string host);

  // Starts the child `name` with `args` (argv, "dyad" first), its `restarts`-th restart (0: the
  // first start). Its output goes to the relay and to `log_path` ("" none), after the header
  // "=== NAME started (restart N) at YYYY-MM-DD HH:MM:SS on host 'HOST'" ("(restart N) " only
  // for a restart). Returns its pid, or an error saying "cannot start process 'NAME'[: why]".
  StatusOr<pid_t> Start(const std::string& name, std::vector<std::string> args, int restarts,
                        const std::string& log_path) const;

 private:
  std::string executable_;
  OutputRelay* relay_;
  std::string host_;
};

}  // namespace dyad
