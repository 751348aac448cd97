// Process-level tests of graphs placed on hosts (two "hosts" on loopback): launchers that start
// only their host's processes, processes started apart that start together in every discovery
// mode, the discovery server, supervision (restarts, required processes) and failures that end
// the run on every host.
#include "process_fixture.hpp"

#include <signal.h>
#include <sys/wait.h>

namespace {

using namespace dyad::testing;

TEST_F(ProcessTest, LauncherStartsOnlyThisHostsProcessesAndNamesTheOnesItWaitedFor) {
  const fs::path out = dir_ / "sink.txt";
  const fs::path g = Write("g.yaml", "graph: hosts\ndomain_id: " + std::to_string(domain_) +
                                         "\nnetwork: {start_timeout_s: 2}"
                                         "\nprocesses: {here: {host: lab}, robot: {host: robot-pc-elsewhere}}\ncomponents:\n"
                                         "  src: {type: counter_source, rate_hz: 50, process: here, params: {limit: 20}, outputs: {out: count}}\n"
                                         "  sink: {type: counter_sink, trigger: in, process: robot, params: {file: " +
                                         out.string() + "}, inputs: {in: count}}\n");
  Child c(Dyad({"run", g.string(), "--host", "lab"}), dir_, "hosts");
  // The process here waits for the robot's, which nobody starts: it gives up and says why.
  ASSERT_EQ(c.Wait(30), 1) << c.err();
  EXPECT_NE(c.err().find("process 'robot' runs on host 'robot-pc-elsewhere': start it there with `dyad run " + g.string() +
                         " --host robot-pc-elsewhere`"),
            std::string::npos)
      << c.err();
  EXPECT_NE(c.err().find("process 'here' waited 2 s (network.start_timeout_s) for the graph to start together: "
                         "processes not ready: 'robot' (not seen); here: the writer of 'count' matched 0 of 1 readers"),
            std::string::npos)
      << c.err();
  EXPECT_EQ(c.err().find("the graph is local"), std::string::npos) << c.err();  // it names hosts: scope lan
  EXPECT_FALSE(fs::exists(out));  // the robot's process was not started here
}

// Issue #40: a graph that names no host is local (loopback only: the safe default, kept). Started
// with --process on several machines, each process waits for the others in vain: its message says
// the graph is local and how to open it, not only "'mind' (not seen)".
TEST_F(ProcessTest, AProcessOfALocalGraphThatWaitsInVainSaysTheGraphIsLocalAndHowToOpenIt) {
  const fs::path g = Write("g.yaml", "graph: alone\nclock: wall\ndomain_id: " + std::to_string(domain_) +
                                         "\nnetwork: {start_timeout_s: 1}\nprocesses: {here: {}, mind: {}}\ncomponents:\n"
                                         "  src: {type: counter_source, rate_hz: 50, process: here, outputs: {out: count}}\n"
                                         "  sink: {type: counter_sink, trigger: in, process: mind, inputs: {in: count}}\n");
  Child c(Dyad({"run", g.string(), "--process", "here"}), dir_, "alone");
  ASSERT_EQ(c.Wait(30), 1) << c.err();
  EXPECT_NE(c.err().find("processes not ready: 'mind' (not seen)"), std::string::npos) << c.err();
  EXPECT_NE(c.err().find("the graph is local (network.scope: local"), std::string::npos) << c.err();
  EXPECT_NE(c.err().find("set `network.scope: lan` (or --set network.scope=lan) or name the hosts"), std::string::npos) << c.err();
}

// Two launchers started 3 s apart, as on two machines, in each discovery mode (on loopback):
// nothing runs before both are up, so the sink has every sample from the first.
class DiscoveryModeTest : public ProcessTest, public ::testing::WithParamInterface<const char*> {
 protected:
  // Two "hosts" on loopback, in this test's discovery mode: a (h1) counts at 50 Hz into b's (h2)
  // sink, which writes `out`; the discovery server, used in mode "server", on `server_host` at
  // `server_port`.
  fs::path TwoHostGraph(const std::string& name, const std::string& server_host, int server_port, const fs::path& out) {
    return Write("g.yaml", "graph: " + name + "\nclock: wall\ndomain_id: " + std::to_string(domain_) +
                               "\nnetwork:\n  discovery: " + GetParam() + "\n  hosts: {h1: 127.0.0.1, h2: 127.0.0.1}\n  server: " +
                               server_host + ":" + std::to_string(server_port) + "\n  start_timeout_s: 20\n"
                               "processes: {a: {host: h1}, b: {host: h2}}\ncomponents:\n"
                               "  src: {type: counter_source, rate_hz: 50, process: a, outputs: {out: count}}\n"
                               "  sink: {type: counter_sink, trigger: in, process: b, params: {file: " + out.string() +
                               "}, inputs: {in: count}}\n");
  }
};

TEST_P(DiscoveryModeTest, ProcessesStartedApartStartTogetherAndLoseNothing) {
  const fs::path out = dir_ / "sink.txt";
  const int server_port = FreeUdpPort();
  const fs::path g = TwoHostGraph("apart", "h1", server_port, out);
  Child a(Dyad({"run", g.string(), "--host", "h1", "--steps", "40"}), dir_, "a");
  std::this_thread::sleep_for(std::chrono::seconds(3));
  Child b(Dyad({"run", g.string(), "--host", "h2", "--steps", "40"}), dir_, "b");
  ASSERT_EQ(a.Wait(60), 0) << a.err();
  ASSERT_EQ(b.Wait(60), 0) << b.err();
  // Every sample the source wrote, from its first: as many as its steps. On the wall clock a
  // loaded machine (the sanitizer suite) may skip a late period at the end (a deadline miss,
  // counted), so the count is the source's own, not 40.
  const size_t written = StepsOf(a.out(), "src");
  EXPECT_GE(written, 35u) << a.out();
  const auto received = ReadSink(out);
  ASSERT_EQ(received.size(), written) << a.out() << a.err() << b.err();
  for (size_t i = 0; i < received.size(); ++i) EXPECT_EQ(received[i].sequence, i + 1);
  if (std::string(GetParam()) == "server") {
    EXPECT_NE(a.out().find("dyad discovery-server: listening on 127.0.0.1:" + std::to_string(server_port)), std::string::npos)
        << a.out();
  }
}

INSTANTIATE_TEST_SUITE_P(Modes, DiscoveryModeTest, ::testing::Values("multicast", "peers", "server"),
                         [](const auto& info) { return std::string(info.param); });

// `dyad discovery-server` refuses what it cannot listen on, naming --listen, with a non-zero exit;
// a second server on a taken port fails and says so, and the first keeps running.
TEST_F(ProcessTest, DiscoveryServerRefusesABadListenAddress) {
  struct Case {
    const char* listen;
    const char* says;
  };
  for (const Case& c : {Case{"11811", "expected ADDRESS:PORT"}, Case{"127.0.0.1:0", "expected ADDRESS:PORT"},
                        Case{"127.0.0.1:70000", "expected ADDRESS:PORT"}, Case{"127.0.0.1:x", "expected ADDRESS:PORT"},
                        Case{"no-such-host.invalid:11811", "--listen no-such-host.invalid:11811"},
                        Case{"192.0.2.1:11811", "cannot listen on 192.0.2.1:11811"}}) {
    Child d(Dyad({"discovery-server", "--listen", c.listen}), dir_, "bad");
    EXPECT_NE(d.Wait(30), 0) << c.listen;
    EXPECT_NE(d.err().find(c.says), std::string::npos) << c.listen << ": " << d.err();
  }
  const int port = FreeUdpPort();
  ASSERT_GT(port, 0);
  const std::string listen = "127.0.0.1:" + std::to_string(port);
  Child first(Dyad({"discovery-server", "--listen", listen}), dir_, "first");
  ASSERT_TRUE(first.WaitForOutput("listening on " + listen, 10)) << first.err();
  Child second(Dyad({"discovery-server", "--listen", listen}), dir_, "second");
  EXPECT_EQ(second.Wait(30), 1) << second.out() << second.err();
  EXPECT_NE(second.err().find("cannot listen on " + listen), std::string::npos) << second.err();
  first.Signal(SIGINT);
  EXPECT_EQ(first.Wait(30), 128 + SIGINT) << first.err();  // dyad's exit code for a signal
}

// A required process killed on one host, with no restart left, ends the run on every host: its
// launcher announces the failure on dyad/launchers, the other host's launcher stops its own
// processes (cleanly: SIGTERM) and exits 1 naming the process and its host. In each discovery
// mode; with a server, the failing host runs it (it must outlive the announcement).
TEST_P(DiscoveryModeTest, ARequiredProcessFailingOnOneHostEndsTheRunOnEveryHost) {
  const fs::path out = dir_ / "sink.txt";
  const fs::path g = TwoHostGraph("hosts", "h2", FreeUdpPort(), out);
  Child h1(Dyad({"run", g.string(), "--host", "h1"}), dir_, "h1");  // runs until told otherwise
  Child h2(Dyad({"run", g.string(), "--host", "h2"}), dir_, "h2");
  for (int i = 0; i < 400 && ReadSink(out).size() < 10; ++i) usleep(50'000);
  ASSERT_GE(ReadSink(out).size(), 10u) << h1.err() << h2.err();
  const pid_t b = AwaitChildPid(g, "b");
  ASSERT_GT(b, 0);
  ASSERT_EQ(kill(b, SIGKILL), 0);
  EXPECT_EQ(h2.Wait(30), 137) << h2.err();
  EXPECT_NE(h2.err().find("process 'b' exited with 137 (SIGKILL)"), std::string::npos) << h2.err();
  EXPECT_EQ(h1.Wait(30), 1) << h1.err();
  EXPECT_NE(h1.err().find("process 'b' on host 'h2' failed for good: stopping the processes of host 'h1'"), std::string::npos)
      << h1.err();
  EXPECT_EQ(h1.err().find("process 'a' exited"), std::string::npos) << "a was stopped, not failed: " << h1.err();
}

// A restart is never silent: the restarting launcher and the other host's say which process
// restarted and what that reset.
TEST_F(ProcessTest, EveryLauncherSaysWhenAProcessOfAnotherHostRestarted) {
  const fs::path g = Write("g.yaml", "graph: restarts\nclock: wall\ndomain_id: " + std::to_string(domain_) +
                                         "\nnetwork: {discovery: peers, hosts: {h1: 127.0.0.1, h2: 127.0.0.1}}\n"
                                         "processes: {a: {host: h1}, b: {host: h2, restart: on-failure, backoff_s: 0.2}}\n"
                                         "components:\n"
                                         "  src: {type: counter_source, rate_hz: 20, process: a, outputs: {out: count}}\n"
                                         "  sink: {type: counter_sink, trigger: in, process: b, inputs: {in: count}}\n");
  Child h1(Dyad({"run", g.string(), "--host", "h1", "--steps", "140"}), dir_, "h1");  // 7 s
  Child h2(Dyad({"run", g.string(), "--host", "h2", "--steps", "140"}), dir_, "h2");
  const pid_t b = AwaitChildPid(g, "b");
  ASSERT_GT(b, 0);
  std::this_thread::sleep_for(std::chrono::seconds(2));
  ASSERT_EQ(kill(b, SIGKILL), 0);
  EXPECT_EQ(h2.Wait(60), 0) << h2.err();
  EXPECT_EQ(h1.Wait(60), 0) << h1.err();
  EXPECT_NE(h2.err().find("process 'b': restarting (restart 1 of 3): its components' state is reset (sink: counter_sink)"),
            std::string::npos) << h2.err();
  EXPECT_NE(h1.err().find("process 'b' on host 'h2' restarted (restart 1): its components' state is reset (sink: counter_sink)"),
            std::string::npos) << h1.err();
}

TEST_F(ProcessTest, SupervisorRestartsAKilledProcessAndItRejoinsTheRunningGraph) {
  const fs::path out = dir_ / "sink.txt";
  const fs::path g = Write("g.yaml", "graph: restart\nclock: wall\ndomain_id: " + std::to_string(domain_) +
                                         "\nprocesses: {a: {}, b: {restart: on-failure, backoff_s: 0.2}}\ncomponents:\n"
                                         "  src: {type: counter_source, rate_hz: 20, process: a, outputs: {out: count}}\n"
                                         "  sink: {type: counter_sink, trigger: in, process: b, params: {file: " +
                                         out.string() + "}, inputs: {in: count}}\n");
  Child c(Dyad({"run", g.string(), "--steps", "200", "--logs", (dir_ / "logs").string()}), dir_, "restart");  // 10 s
  const pid_t b = AwaitChildPid(g, "b");
  ASSERT_NE(b, 0);
  std::this_thread::sleep_for(std::chrono::seconds(3));
  ASSERT_EQ(kill(b, SIGKILL), 0);
  ASSERT_EQ(c.Wait(60), 0) << c.err();
  EXPECT_NE(c.err().find("process 'b' exited with 137 (SIGKILL); restarting in 0.2 s"), std::string::npos) << c.err();
  EXPECT_NE(c.err().find("process 'b': restarting (restart 1 of 3): its components' state is reset (sink: counter_sink)"),
            std::string::npos) << c.err();
  // The restarted sink joined the running graph at once and received what the source sent then:
  // the source's run was not restarted (its numbers go on), the sink's file is its new one.
  const auto received = ReadSink(out);
  ASSERT_GT(received.size(), 20u) << c.err() << c.out();
  EXPECT_GT(received.front().sequence, 1u);  // the source ran on: its numbers did not start again
  for (size_t i = 1; i < received.size(); ++i) EXPECT_EQ(received[i].sequence, received[i - 1].sequence + 1);
  EXPECT_EQ(received.back().sequence, 200u);  // and it ended with the graph, not 200 steps after its restart
  // Each process's output: relayed with its name, and in its own log, one header per start.
  EXPECT_NE(c.out().find("[a] timing (process a):"), std::string::npos) << c.out();
  const std::string log_b = dyad::testing::ReadFile(dir_ / "logs" / "b.log");
  EXPECT_NE(log_b.find("=== b started at "), std::string::npos) << log_b;
  EXPECT_NE(log_b.find("=== b started (restart 1) at "), std::string::npos) << log_b;
  EXPECT_NE(log_b.find("timing (process b):"), std::string::npos) << log_b;
  EXPECT_EQ(dyad::testing::ReadFile(dir_ / "logs" / "a.log").find("[a]"), std::string::npos);  // unprefixed
}

// Input health across processes: the sink's input counts the source's writer alive while its
// process runs, and not once it is killed (liveliness_ms: 300), without the sink's own timeout.
TEST_F(ProcessTest, AnInputSeesItsWriterGoWhenTheWritersProcessIsKilled) {
  const fs::path g = Write("g.yaml", "graph: health\nclock: wall\ndomain_id: " + std::to_string(domain_) +
                                         "\nprocesses: {a: {required: false}, b: {}}\n"
                                         "topics: {count: {liveliness_ms: 300}}\ncomponents:\n"
                                         "  src: {type: counter_source, rate_hz: 20, process: a, outputs: {out: count}}\n"
                                         "  sink: {type: counter_sink, rate_hz: 20, process: b, inputs: {in: count}}\n");
  Child c(Dyad({"run", g.string(), "--duration", "6"}), dir_, "health");
  const pid_t a = AwaitChildPid(g, "a");
  ASSERT_NE(a, 0);
  std::this_thread::sleep_for(std::chrono::seconds(3));
  ASSERT_EQ(kill(a, SIGKILL), 0);
  ASSERT_EQ(c.Wait(60), 0) << c.err();
  EXPECT_NE(c.err().find("[b] [info] sink: writers of 'count' alive: 0 -> 1"), std::string::npos) << c.err();
  EXPECT_NE(c.err().find("[b] [info] sink: writers of 'count' alive: 1 -> 0"), std::string::npos) << c.err();
  EXPECT_NE(c.err().find("process 'a' exited with 137 (SIGKILL); it is not required"), std::string::npos) << c.err();
}

// restart: always restarts a clean exit only in a run without an end: with --steps, the clean
// exit is the end of the run.
TEST_F(ProcessTest, AlwaysDoesNotRestartTheCleanEndOfARunWithSteps) {
  const fs::path g = Write("g.yaml", "graph: always\nclock: wall\ndomain_id: " + std::to_string(domain_) +
                                         "\nprocesses: {a: {restart: always}, b: {restart: always}}\ncomponents:\n"
                                         "  src: {type: counter_source, rate_hz: 20, process: a, outputs: {out: count}}\n"
                                         "  sink: {type: counter_sink, trigger: in, process: b, inputs: {in: count}}\n");
  Child c(Dyad({"run", g.string(), "--steps", "20"}), dir_, "always");
  ASSERT_EQ(c.Wait(60), 0) << c.err();
  EXPECT_EQ(c.err().find("restarting"), std::string::npos) << c.err();
}

TEST_F(ProcessTest, ARequiredProcessThatKeepsFailingEndsTheRunAndIsNamed) {
  const fs::path g = Write("g.yaml", "graph: crashy\nclock: wall\ndomain_id: " + std::to_string(domain_) +
                                         "\nprocesses: {a: {}, b: {restart: on-failure, max_restarts: 2, backoff_s: 0.1}}\n"
                                         "components:\n"
                                         "  src: {type: counter_source, rate_hz: 20, process: a, outputs: {out: count}}\n"
                                         "  sink: {type: counter_sink, trigger: in, process: b, params: {file: " +
                                         (dir_ / "no/such/dir/sink.txt").string() + "}, inputs: {in: count}}\n");
  Child c(Dyad({"run", g.string()}), dir_, "crashy");  // a alone would run forever
  ASSERT_EQ(c.Wait(60), 1) << c.err();
  EXPECT_NE(c.err().find("process 'b': restarting (restart 2 of 2)"), std::string::npos) << c.err();
  EXPECT_NE(c.err().find("process 'b' exited with 1 (after 2 restarts)"), std::string::npos) << c.err();
}

TEST_F(ProcessTest, AProcessThatIsNotRequiredMayFailWithoutEndingTheRun) {
  const fs::path out = dir_ / "sink.txt";
  const fs::path g = Write("g.yaml", "graph: optional\nclock: wall\ndomain_id: " + std::to_string(domain_) +
                                         "\nnetwork: {start_timeout_s: 20}\nprocesses: {a: {}, b: {}, c: {required: false}}\n"
                                         "components:\n"
                                         "  src: {type: counter_source, rate_hz: 20, process: a, outputs: {out: count}}\n"
                                         "  sink: {type: counter_sink, trigger: in, process: b, params: {file: " + out.string() +
                                         "}, inputs: {in: count}}\n"
                                         "  bad: {type: counter_sink, trigger: in, process: c, params: {file: " +
                                         (dir_ / "no/such/dir/sink.txt").string() + "}, inputs: {in: count}}\n");
  Child c(Dyad({"run", g.string(), "--steps", "20"}), dir_, "optional");
  // Nobody waits for a process that is not required: a and b start together without c.
  ASSERT_EQ(c.Wait(60), 0) << c.err();
  EXPECT_NE(c.err().find("process 'c' exited with 1; it is not required: the experiment goes on without it"), std::string::npos)
      << c.err();
  const auto received = ReadSink(out);
  ASSERT_EQ(received.size(), 20u) << c.err();
  EXPECT_EQ(received.front().sequence, 1u);
}

TEST_F(ProcessTest, OneFailingProcessEndsTheWholeExperiment) {
  const fs::path g = Write("g.yaml", "graph: fail\ndomain_id: " + std::to_string(domain_) +
                                         "\nprocesses: {a: {}, b: {}}\ncomponents:\n"
                                         "  src: {type: counter_source, rate_hz: 50, process: a, outputs: {out: count}}\n"
                                         "  sink: {type: counter_sink, trigger: in, process: b, params: {file: " +
                                         (dir_ / "no/such/dir/sink.txt").string() + "}, inputs: {in: count}}\n");
  Child c(Dyad({"run", g.string()}), dir_, "fail");  // a alone would run forever
  ASSERT_EQ(c.Wait(30), 1) << "launcher hung or exited wrongly\n" << c.err();
  EXPECT_NE(c.err().find("sink: activate failed: " + (dir_ / "no/such/dir/sink.txt").string() + ": cannot open for writing"),
            std::string::npos)
      << c.err();
  EXPECT_NE(c.err().find("process 'b' exited with 1"), std::string::npos) << c.err();
}

}  // namespace
