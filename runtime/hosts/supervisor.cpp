#include "hosts/supervisor.hpp"

#include <csignal>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "dyad/interrupt.hpp"

namespace dyad {
namespace {

// Whether the launcher caused this exit: the user's signal forwarded, or its own SIGTERM (to
// every child after a failure, to the server after the last process).
bool StoppedByLauncher(const ChildExit& exit, const LauncherState& state) {
  if (state.user_signal != 0 && exit.exit_code == ExitCodeForSignal(state.user_signal)) return true;
  const bool sent_sigterm = state.stopped_others || (exit.server && state.server_stopped);
  return sent_sigterm && exit.exit_code == ExitCodeForSignal(SIGTERM);
}

// Whether the policy restarts this exit (ignoring max_restarts). A clean exit of a run with an
// end is that end, whatever the policy: `always` restarts clean exits only in runs that go on
// until Ctrl-C.
bool PolicyRestarts(const ChildExit& exit, const ProcessConfig& config, bool run_has_end) {
  if (exit.server) return false;
  switch (config.restart) {
    case RestartPolicy::kAlways: return exit.exit_code != 0 || !run_has_end;
    case RestartPolicy::kOnFailure: return exit.exit_code != 0;
    case RestartPolicy::kNever: return false;
  }
  return false;
}

}  // namespace

std::string DescribeExit(int code) {
  if (code > 128 && code < 128 + 32) return std::to_string(code) + " (" + SignalName(code - 128) + ")";
  return std::to_string(code);
}

ExitDecision DecideExit(const ChildExit& exit, const ProcessConfig& config, const LauncherState& state) {
  ExitDecision d;
  if (state.stopping || StoppedByLauncher(exit, state)) return d;
  const std::string exited = "process '" + exit.name + "' exited with " + DescribeExit(exit.exit_code);
  const bool restarts = PolicyRestarts(exit, config, state.run_has_end);
  if (restarts && exit.restarts < config.max_restarts) {
    d.action = ExitDecision::Action::kRestart;
    d.backoff_s = std::min(kMaxBackoffS, config.backoff_s * std::pow(2.0, exit.restarts));
    d.restart = exit.restarts + 1;
    std::ostringstream line;
    line << exited << "; restarting in " << d.backoff_s << " s";
    d.message = line.str();
    return d;
  }
  if (exit.exit_code == 0) return d;
  const std::string given_up =
      restarts ? " (after " + std::to_string(exit.restarts) + (exit.restarts == 1 ? " restart)" : " restarts)") : "";
  if (!exit.server && !config.required) {
    d.action = ExitDecision::Action::kGoOn;
    d.message = exited + given_up + "; it is not required: the experiment goes on without it";
    return d;
  }
  d.action = ExitDecision::Action::kStopAll;
  d.message = exited + given_up;
  d.exit_code = exit.exit_code;
  d.announce = !exit.server;
  return d;
}

ExitDecision DecideRemoteFailure(const std::string& failure, const std::string& host) {
  ExitDecision d;
  d.action = ExitDecision::Action::kStopAll;
  d.message = failure + ": stopping the processes of host '" + host + "'";
  d.exit_code = 1;
  return d;
}

}  // namespace dyad
