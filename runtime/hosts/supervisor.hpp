// Supervisor — what the launcher does when one of its children exits (internal to the runtime).
//
// A pure function of the exit, the process's `processes:` entry and what the launcher is doing:
// no system calls, no clock (a restart's back-off is returned in seconds; the launcher adds it to
// its own clock), so every branch has a unit test (tests/supervisor_test.cpp). The decision is
// data, as in dora's node_exit.rs; the launcher (launcher.cpp) carries it out.
//
//   ExitDecision d = DecideExit({"mind", 0, 1, false}, mind_config, {});
//   // on-failure, backoff_s 0.5: d.action == kRestart, d.backoff_s == 0.5, d.restart == 1,
//   // d.message == "process 'mind' exited with 1; restarting in 0.5 s"
//
// The rules (run.hpp, docs/distributed.md "Supervision"):
//   - an exit the launcher caused (the user's signal forwarded to the children, SIGTERM to stop
//     them after a failure, SIGTERM to the discovery server after the last process) or any exit
//     once it is stopping is not a failure: ignored;
//   - `restart: on-failure` restarts a non-zero exit, `always` any exit, except that a clean exit
//     of a run with an end (--steps, --duration) is that end; at most `max_restarts` times, after
//     `backoff_s` doubled after each restart, at most kMaxBackoffS; the discovery server is never
//     restarted;
//   - otherwise a clean exit is the process's end: ignored, said nothing;
//   - a failure for good of a process that is not required is said, and the others go on;
//   - a failure for good of a required process, or of the discovery server, stops every other
//     child; the run exits with its code; a required process's failure is first announced to the
//     other hosts' launchers (LauncherLink), the server's is not (it is this host's).
#pragma once

#include <string>

#include <dyad/graph.hpp>

namespace dyad {

// A restart waits backoff_s * 2^restarts, never longer than this.
constexpr double kMaxBackoffS = 10.0;

// One child of the launcher that exited.
struct ChildExit {
  std::string name;       // the process's name ("discovery-server" for the server)
  int restarts = 0;       // how often it had been restarted before this exit
  int exit_code = 0;      // its exit status, or 128 + signal when a signal ended it
  bool server = false;    // the graph's discovery server, not a process of the graph
};

// What the launcher is doing when the child exits.
struct LauncherState {
  bool run_has_end = false;     // --steps or --duration was given
  bool stopping = false;        // the user's signal was forwarded, or every child was told to stop
  int user_signal = 0;          // the signal the user sent the launcher (SIGINT, SIGTERM); 0: none
  bool stopped_others = false;  // the children were sent SIGTERM after a failure
  bool server_stopped = false;  // the discovery server was sent SIGTERM
};

struct ExitDecision {
  enum class Action {
    kIgnore,   // nothing to do (a clean end, or an exit the launcher caused)
    kRestart,  // start the process again in backoff_s seconds, as its restart number `restart`
    kGoOn,     // a process that is not required failed for good: said; the others go on
    kStopAll,  // a required process (or the server) failed for good: stop the others, exit_code
  };
  Action action = Action::kIgnore;
  std::string message;    // the launcher's line; empty: say nothing
  double backoff_s = 0;   // kRestart
  int restart = 0;        // kRestart: the restart count the new start announces
  int exit_code = 0;      // kStopAll: the run's exit code, unless an earlier failure set it
  bool announce = false;  // kStopAll: tell the other hosts' launchers first (LauncherLink)
};

// See the rules above. `config`: the process's `processes:` entry (the defaults for the server
// or a process the graph does not list).
ExitDecision DecideExit(const ChildExit& exit, const ProcessConfig& config, const LauncherState& state);

// A required process of another host failed for good (`failure`: LauncherLink's line): stop the
// processes of `host` (this one); the run exits 1. Says "<failure>: stopping the processes of
// host '<host>'".
ExitDecision DecideRemoteFailure(const std::string& failure, const std::string& host);

// "1", or "143 (SIGTERM)" for 128 + a signal.
std::string DescribeExit(int code);

}  // namespace dyad
