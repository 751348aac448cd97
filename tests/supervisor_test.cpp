// The launcher's decisions on a child's exit (hosts/supervisor.hpp): every branch, with the
// lines the launcher says.
#include "hosts/supervisor.hpp"

#include <gtest/gtest.h>

#include <csignal>

namespace dyad {
namespace {

using Action = ExitDecision::Action;

ProcessConfig Config(RestartPolicy restart, int max_restarts = 3, double backoff_s = 0.5, bool required = true) {
  ProcessConfig pc;
  pc.name = "mind";
  pc.restart = restart;
  pc.max_restarts = max_restarts;
  pc.backoff_s = backoff_s;
  pc.required = required;
  return pc;
}

ChildExit Exit(int code, int restarts = 0) { return ChildExit{"mind", restarts, code, false}; }
ChildExit ServerExit(int code) { return ChildExit{"discovery-server", 0, code, true}; }

TEST(Supervisor, OnFailureRestartsAFailureAfterTheBackoff) {
  const ExitDecision d = DecideExit(Exit(1), Config(RestartPolicy::kOnFailure), {});
  EXPECT_EQ(d.action, Action::kRestart);
  EXPECT_EQ(d.backoff_s, 0.5);
  EXPECT_EQ(d.restart, 1);
  EXPECT_EQ(d.message, "process 'mind' exited with 1; restarting in 0.5 s");
}

TEST(Supervisor, TheBackoffDoublesAfterEachRestartUpToTenSeconds) {
  const ProcessConfig pc = Config(RestartPolicy::kOnFailure, 10, 0.5);
  const double expected[] = {0.5, 1, 2, 4, 8, 10, 10};
  for (int restarts = 0; restarts < 7; ++restarts) {
    const ExitDecision d = DecideExit(Exit(1, restarts), pc, {});
    ASSERT_EQ(d.action, Action::kRestart) << restarts;
    EXPECT_EQ(d.backoff_s, expected[restarts]) << restarts;
    EXPECT_EQ(d.restart, restarts + 1);
  }
  EXPECT_EQ(DecideExit(Exit(1, 5), pc, {}).message, "process 'mind' exited with 1; restarting in 10 s");
}

TEST(Supervisor, OnFailureDoesNotRestartACleanExit) {
  const ExitDecision d = DecideExit(Exit(0), Config(RestartPolicy::kOnFailure), {});
  EXPECT_EQ(d.action, Action::kIgnore);
  EXPECT_EQ(d.message, "");
}

TEST(Supervisor, AKillIsDescribedByItsSignal) {
  const ExitDecision d = DecideExit(Exit(128 + SIGKILL), Config(RestartPolicy::kOnFailure), {});
  EXPECT_EQ(d.message, "process 'mind' exited with 137 (SIGKILL); restarting in 0.5 s");
}

TEST(Supervisor, AlwaysRestartsACleanExitInARunWithoutAnEnd) {
  const ExitDecision d = DecideExit(Exit(0), Config(RestartPolicy::kAlways), {});
  EXPECT_EQ(d.action, Action::kRestart);
  EXPECT_EQ(d.message, "process 'mind' exited with 0; restarting in 0.5 s");
}

TEST(Supervisor, AlwaysTakesACleanExitOfARunWithAnEndAsThatEnd) {
  LauncherState state;
  state.run_has_end = true;
  EXPECT_EQ(DecideExit(Exit(0), Config(RestartPolicy::kAlways), state).action, Action::kIgnore);
  EXPECT_EQ(DecideExit(Exit(2), Config(RestartPolicy::kAlways), state).action, Action::kRestart);
}

TEST(Supervisor, NeverStopsEveryoneWhenARequiredProcessFails) {
  const ExitDecision d = DecideExit(Exit(3), Config(RestartPolicy::kNever), {});
  EXPECT_EQ(d.action, Action::kStopAll);
  EXPECT_EQ(d.exit_code, 3);
  EXPECT_TRUE(d.announce);
  EXPECT_EQ(d.message, "process 'mind' exited with 3");
}

TEST(Supervisor, ExhaustedRestartsSayHowMany) {
  const ExitDecision d = DecideExit(Exit(1, 3), Config(RestartPolicy::kOnFailure, 3), {});
  EXPECT_EQ(d.action, Action::kStopAll);
  EXPECT_EQ(d.exit_code, 1);
  EXPECT_EQ(d.message, "process 'mind' exited with 1 (after 3 restarts)");
  EXPECT_EQ(DecideExit(Exit(1, 1), Config(RestartPolicy::kOnFailure, 1), {}).message,
            "process 'mind' exited with 1 (after 1 restart)");
  EXPECT_EQ(DecideExit(Exit(1, 0), Config(RestartPolicy::kOnFailure, 0), {}).message,
            "process 'mind' exited with 1 (after 0 restarts)");
}

TEST(Supervisor, ACleanExitAfterItsRestartsIsNoFailure) {
  const ExitDecision d = DecideExit(Exit(0, 3), Config(RestartPolicy::kAlways, 3), {});
  EXPECT_EQ(d.action, Action::kIgnore);
  EXPECT_EQ(d.message, "");
}

TEST(Supervisor, AProcessThatIsNotRequiredIsLeftOut) {
  const ProcessConfig pc = Config(RestartPolicy::kOnFailure, 2, 0.5, /*required=*/false);
  const ExitDecision d = DecideExit(Exit(1, 2), pc, {});
  EXPECT_EQ(d.action, Action::kGoOn);
  EXPECT_EQ(d.message,
            "process 'mind' exited with 1 (after 2 restarts); it is not required: the experiment goes on without it");
  EXPECT_EQ(DecideExit(Exit(1), Config(RestartPolicy::kNever, 3, 0.5, false), {}).message,
            "process 'mind' exited with 1; it is not required: the experiment goes on without it");
  EXPECT_EQ(DecideExit(Exit(1), pc, {}).action, Action::kRestart);  // not required: still restarted first
}

TEST(Supervisor, TheDiscoveryServerIsNeverRestartedAndItsFailureStopsAllUnannounced) {
  const ExitDecision d = DecideExit(ServerExit(1), Config(RestartPolicy::kAlways, 3, 0.5, false), {});
  EXPECT_EQ(d.action, Action::kStopAll);
  EXPECT_EQ(d.exit_code, 1);
  EXPECT_FALSE(d.announce);
  EXPECT_EQ(d.message, "process 'discovery-server' exited with 1");
  EXPECT_EQ(DecideExit(ServerExit(0), ProcessConfig{}, {}).action, Action::kIgnore);
}

TEST(Supervisor, TheServerStoppedAfterTheLastProcessIsNoFailure) {
  LauncherState state;
  state.server_stopped = true;
  EXPECT_EQ(DecideExit(ServerExit(128 + SIGTERM), ProcessConfig{}, state).action, Action::kIgnore);
  // That SIGTERM was the server's only: a process's SIGTERM is still its own failure.
  EXPECT_EQ(DecideExit(Exit(128 + SIGTERM), Config(RestartPolicy::kNever), state).action, Action::kStopAll);
}

TEST(Supervisor, AChildStoppedByOurSigtermIsNoFailure) {
  LauncherState state;
  state.stopped_others = true;
  EXPECT_EQ(DecideExit(Exit(128 + SIGTERM), Config(RestartPolicy::kOnFailure), state).action, Action::kIgnore);
  // Another code is a failure, unless the launcher is stopping anyway.
  EXPECT_EQ(DecideExit(Exit(1), Config(RestartPolicy::kNever), state).action, Action::kStopAll);
  state.stopping = true;
  EXPECT_EQ(DecideExit(Exit(1), Config(RestartPolicy::kNever), state).action, Action::kIgnore);
}

TEST(Supervisor, AChildStoppedByTheUsersSignalIsNoFailure) {
  LauncherState state;
  state.user_signal = SIGINT;
  const ExitDecision d = DecideExit(Exit(128 + SIGINT), Config(RestartPolicy::kAlways), state);
  EXPECT_EQ(d.action, Action::kIgnore);
  EXPECT_EQ(d.message, "");
  EXPECT_EQ(DecideExit(Exit(128 + SIGTERM), Config(RestartPolicy::kNever), state).action, Action::kStopAll);
}

TEST(Supervisor, NothingIsDecidedWhileStopping) {
  LauncherState state;
  state.stopping = true;
  for (int code : {0, 1, 128 + SIGKILL})
    EXPECT_EQ(DecideExit(Exit(code), Config(RestartPolicy::kAlways), state).action, Action::kIgnore) << code;
  EXPECT_EQ(DecideExit(ServerExit(1), ProcessConfig{}, state).action, Action::kIgnore);
}

TEST(Supervisor, ARemoteFailureStopsThisHostWithExitOne) {
  const ExitDecision d = DecideRemoteFailure("process 'mind' on host 'h2' failed for good (after 1 restart)", "lab");
  EXPECT_EQ(d.action, Action::kStopAll);
  EXPECT_EQ(d.exit_code, 1);
  EXPECT_FALSE(d.announce);
  EXPECT_EQ(d.message, "process 'mind' on host 'h2' failed for good (after 1 restart): stopping the processes of host 'lab'");
}

TEST(Supervisor, DefaultProcessConfigNeverRestartsAndIsRequired) {
  const ExitDecision d = DecideExit(Exit(1), ProcessConfig{}, {});
  EXPECT_EQ(d.action, Action::kStopAll);
  EXPECT_EQ(d.message, "process 'mind' exited with 1");
}

}  // namespace
}  // namespace dyad
