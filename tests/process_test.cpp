// Process-level tests: real `dyad` processes started, signalled, killed and waited for.
#include <gtest/gtest.h>

#include "dyad/testing/dds_domain.hpp"

#include "dyad/testing/child_process.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

namespace fs = std::filesystem;

namespace {

using Child = dyad::testing::ChildProcess;

class ProcessTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("dyad_test_" + std::to_string(getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // A domain of its own per test process, so parallel ctest runs don't hear each other.
    domain_ = dyad::testing::DomainForThisProcess();
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  fs::path Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  }
  std::vector<std::string> Dyad(std::vector<std::string> args) {
    args.insert(args.begin(), DYAD_EXE);
    return args;
  }
  fs::path dir_;
  int domain_ = 1;
};

// One line of counter_sink's file.
struct Received {
  int64_t value;
  std::string source;
  uint64_t sequence;
  int64_t stamp_ns;
};

std::vector<Received> ReadSink(const fs::path& file) {
  std::istringstream lines(dyad::testing::ReadFile(file));
  std::vector<Received> out;
  Received r;
  while (lines >> r.value >> r.source >> r.sequence >> r.stamp_ns) out.push_back(r);
  return out;
}

std::string SteppedGraph(const fs::path& out, int domain) {
  return "graph: det\nclock: stepped\nseed: 42\ndomain_id: " + std::to_string(domain) +
         "\ncomponents:\n"
         "  src: {type: counter_source, rate_hz: 100, params: {noise: 5}, outputs: {out: count}}\n"
         "  slow: {type: counter_source, rate_hz: 30, params: {start: 1000, noise: 2}, outputs: {out: count}}\n"
         "  sink: {type: counter_sink, trigger: in, params: {file: " + out.string() + "}, inputs: {in: count}}\n"
         "topics:\n  count: {depth: 8}\n";
}

TEST_F(ProcessTest, SteppedModeGivesByteIdenticalOutputTwice) {
  std::string files[2];
  for (int i = 0; i < 2; ++i) {
    const std::string run = i == 0 ? "run0" : "run1";
    const fs::path out = dir_ / (run + ".txt");
    const fs::path g = Write(run + ".yaml", SteppedGraph(out, domain_));
    Child c(Dyad({"run", g.string(), "--steps", "2000", "--quiet"}), dir_, run);
    ASSERT_EQ(c.Wait(60), 0) << c.err();
    files[i] = dyad::testing::ReadFile(out);
  }
  // 20 s of simulated time: 2000 steps of src, and slow (period 33333333 ns) steps at k*period < 20 s: 601.
  EXPECT_EQ(std::count(files[0].begin(), files[0].end(), '\n'), 2000 + 601);
  EXPECT_EQ(files[0], files[1]);
  // And a different seed gives different samples: the comparison above can fail.
  const fs::path out = dir_ / "seed.txt";
  const fs::path g = Write("seed.yaml", SteppedGraph(out, domain_));
  Child c(Dyad({"run", g.string(), "--steps", "2000", "--quiet", "--set", "src.noise=6"}), dir_, "seed");
  ASSERT_EQ(c.Wait(60), 0) << c.err();
  EXPECT_NE(dyad::testing::ReadFile(out), files[0]);
}

// A stepped run is hermetic: a wall-clock graph publishing on the same domain and topic, and
// listening there, neither changes its output nor hears it.
TEST_F(ProcessTest, SteppedRunIgnoresOtherProcessesOnItsDomain) {
  const fs::path alone = dir_ / "alone.txt";
  Child a(Dyad({"run", Write("a.yaml", SteppedGraph(alone, domain_)).string(), "--steps", "2000", "--quiet"}), dir_, "a");
  ASSERT_EQ(a.Wait(60), 0) << a.err();

  const fs::path heard = dir_ / "heard.txt";
  const fs::path intruder = Write("intruder.yaml", "graph: intruder\ndomain_id: " + std::to_string(domain_) +
                                                      "\ncomponents:\n"
                                                      "  src: {type: counter_source, rate_hz: 200, params: {start: 5000000}, outputs: {out: count}}\n"
                                                      "  sink: {type: counter_sink, trigger: in, params: {file: " + heard.string() +
                                                      "}, inputs: {in: count}}\n");
  Child noisy(Dyad({"run", intruder.string(), "--duration", "30", "--quiet"}), dir_, "intruder");
  // Wait until the intruder is publishing (its own sink hears it), then run the stepped graph.
  for (int i = 0; i < 100 && ReadSink(heard).size() < 20; ++i) usleep(50'000);
  ASSERT_GE(ReadSink(heard).size(), 20u) << noisy.err();
  const fs::path with = dir_ / "with.txt";
  Child b(Dyad({"run", Write("b.yaml", SteppedGraph(with, domain_)).string(), "--steps", "2000", "--quiet"}), dir_, "b");
  ASSERT_EQ(b.Wait(60), 0) << b.err();
  noisy.Signal(SIGINT);
  EXPECT_EQ(noisy.Wait(30), 130) << noisy.err();  // interrupted: 128 + SIGINT
  EXPECT_EQ(dyad::testing::ReadFile(with), dyad::testing::ReadFile(alone));
  for (const Received& r : ReadSink(heard)) ASSERT_GE(r.value, 5000000) << "the intruder heard the stepped run";
}

TEST_F(ProcessTest, TwoComponentsExchangeSamplesInOneProcess) {
  const fs::path out = dir_ / "sink.txt";
  const fs::path g = Write("g.yaml", "graph: one\ndomain_id: " + std::to_string(domain_) +
                                         "\ncomponents:\n"
                                         "  src: {type: counter_source, rate_hz: 200, outputs: {out: count}}\n"
                                         "  sink: {type: counter_sink, trigger: in, params: {file: " + out.string() +
                                         ", expect: 50}, inputs: {in: count}}\n");
  Child c(Dyad({"run", g.string()}), dir_, "one");
  ASSERT_EQ(c.Wait(30), 0) << c.err();
  const auto received = ReadSink(out);
  ASSERT_EQ(received.size(), 50u);
  for (size_t i = 0; i < received.size(); ++i) {
    EXPECT_EQ(received[i].value, static_cast<int64_t>(i));  // in order, none lost
    EXPECT_EQ(received[i].sequence, i + 1);
    EXPECT_EQ(received[i].source, "src");
  }
  EXPECT_NE(c.out().find("timing (process main)"), std::string::npos);
}

TEST_F(ProcessTest, TwoComponentsExchangeSamplesAcrossTwoOsProcesses) {
  const fs::path out = dir_ / "sink.txt";
  const fs::path g = Write("g.yaml", "graph: two\ndomain_id: " + std::to_string(domain_) +
                                         "\nprocesses: {a: {}, b: {}}\ncomponents:\n"
                                         "  src: {type: counter_source, rate_hz: 50, process: a, outputs: {out: count}}\n"
                                         "  sink: {type: counter_sink, rate_hz: 100, process: b, params: {file: " +
                                         out.string() + ", expect: 30}, inputs: {in: count}}\n");
  // Start each process by hand, as on two machines.
  Child b(Dyad({"run", g.string(), "--process", "b"}), dir_, "b");
  Child a(Dyad({"run", g.string(), "--process", "a", "--duration", "20"}), dir_, "a");
  ASSERT_EQ(b.Wait(30), 0) << b.err();
  a.Signal(SIGINT);
  ASSERT_EQ(a.Wait(10), 130) << a.err();
  const auto received = ReadSink(out);
  ASSERT_EQ(received.size(), 30u);
  for (size_t i = 1; i < received.size(); ++i)  // increasing (the first few may be missed while discovery completes)
    EXPECT_GT(received[i].value, received[i - 1].value);
  EXPECT_NE(a.out().find("timing (process a)"), std::string::npos);
}

// Two copies of one wall-clock graph (the same name) side by side on one domain, as two rigs in
// a lab: each run is its own DDS partition, so each sink and each recording holds exactly its
// own source's samples, and each run says that the other's writer was seen and ignored.
TEST_F(ProcessTest, TwoRunsOfOneGraphOnOneDomainNeverMix) {
  auto graph = [&](const std::string& copy, int start) {
    return Write(copy + ".yaml", "graph: twin\nclock: wall\ndomain_id: " + std::to_string(domain_) +
                                     "\ncomponents:\n"
                                     "  src: {type: counter_source, rate_hz: 20, params: {start: " + std::to_string(start) +
                                     "}, outputs: {out: count}}\n"
                                     "  sink: {type: counter_sink, trigger: in, params: {file: " + (dir_ / (copy + ".txt")).string() +
                                     "}, inputs: {in: count}}\n"
                                     "  rec: {type: recorder, rate_hz: 1, params: {file: " + (dir_ / (copy + ".mcap")).string() + "}}\n");
  };
  const fs::path a = graph("a", 0), b = graph("b", 100000);
  Child ca(Dyad({"run", a.string(), "--duration", "5", "--quiet"}), dir_, "a");
  Child cb(Dyad({"run", b.string(), "--duration", "5", "--quiet"}), dir_, "b");
  ASSERT_EQ(ca.Wait(30), 0) << ca.err();
  ASSERT_EQ(cb.Wait(30), 0) << cb.err();
  for (const auto& [copy, lo] : {std::pair<std::string, int64_t>{"a", 0}, {"b", 100000}}) {
    const auto received = ReadSink(dir_ / (copy + ".txt"));
    ASSERT_GE(received.size(), 60u) << copy;  // 20 Hz for 5 s: ~100
    ASSERT_LE(received.size(), 110u) << copy << ": more samples than its own source wrote";
    for (size_t i = 0; i < received.size(); ++i) {
      EXPECT_GE(received[i].value, lo) << copy << " received another run's sample";
      EXPECT_LT(received[i].value, lo + 1000) << copy << " received another run's sample";
      if (i > 0) {
        EXPECT_EQ(received[i].sequence, received[i - 1].sequence + 1) << copy;
      }
    }
    // The recording, read by `dyad bag info`: one channel of `count` with as many samples as the
    // sink saw (give or take the first and last, which a later-matched or earlier-closed
    // endpoint may miss), never the two runs' together.
    Child info(Dyad({"bag", "info", (dir_ / (copy + ".mcap")).string()}), dir_, "info_" + copy);
    ASSERT_EQ(info.Wait(30), 0) << info.err();
    std::smatch m;
    const std::string text = info.out();
    ASSERT_TRUE(std::regex_search(text, m, std::regex(R"(  count  (\d+) msgs)"))) << text;
    const long recorded = std::stol(m[1]);
    EXPECT_LE(recorded, static_cast<long>(received.size()) + 3) << copy << ": " << text;
    EXPECT_GE(recorded, static_cast<long>(received.size()) - 3) << copy << ": " << text;
  }
  // Each saw the other's writer of `count` and said it ignored it.
  EXPECT_NE(ca.err().find("topic 'count' is also written by 'dyad/twin/main'"), std::string::npos) << ca.err();
  EXPECT_NE(ca.err().find("another run on this domain: ignored"), std::string::npos) << ca.err();
  EXPECT_NE(cb.err().find("another run on this domain: ignored"), std::string::npos) << cb.err();
}

// A component that never stepped is named at exit; --strict makes it an error.
TEST_F(ProcessTest, AComponentThatNeverSteppedIsNamedAndStrictMakesItAnError) {
  const fs::path g = Write("g.yaml", "graph: idle\nclock: wall\ndomain_id: " + std::to_string(domain_) +
                                         "\ncomponents:\n  src: {type: counter_source, rate_hz: 10, outputs: {out: count}}\n"
                                         "  sink: {type: counter_sink, trigger: in, inputs: {in: ext}}\n"
                                         "topics:\n  ext: {type: Counter}\n");
  Child lax(Dyad({"run", g.string(), "--duration", "1", "--quiet"}), dir_, "lax");
  EXPECT_EQ(lax.Wait(30), 0) << lax.err();
  EXPECT_NE(lax.err().find("warning: process main: component 'sink' never stepped (triggered by input 'in': nothing arrived on 'ext')"),
            std::string::npos) << lax.err();
  EXPECT_EQ(lax.err().find("component 'src' never stepped"), std::string::npos) << lax.err();
  EXPECT_NE(lax.err().find("topics.ext: no component of the graph writes this topic"), std::string::npos) << lax.err();
  Child strict(Dyad({"run", g.string(), "--duration", "1", "--quiet", "--strict"}), dir_, "strict");
  EXPECT_EQ(strict.Wait(30), 1) << strict.err();
  EXPECT_NE(strict.err().find("error: process main: component 'sink' never stepped"), std::string::npos) << strict.err();
}

// A run's id may not be a partition pattern.
TEST_F(ProcessTest, ARunIdThatIsNotAWordIsRefused) {
  const fs::path g = Write("g.yaml", "graph: t\ncomponents:\n  src: {type: counter_source, rate_hz: 10, outputs: {out: count}}\n");
  Child c(Dyad({"run", g.string(), "--run-id", "a*", "--steps", "2"}), dir_, "bad");
  EXPECT_EQ(c.Wait(30), 2);
  EXPECT_NE(c.err().find("--run-id 'a*'"), std::string::npos) << c.err();
}

TEST_F(ProcessTest, SigintStopsEveryProcessCleanly) {
  const fs::path out = dir_ / "sink.txt";
  const fs::path g = Write("g.yaml", "graph: sig\ndomain_id: " + std::to_string(domain_) +
                                         "\nprocesses: {a: {}, b: {}}\ncomponents:\n"
                                         "  src: {type: counter_source, rate_hz: 100, process: a, outputs: {out: count}}\n"
                                         "  sink: {type: counter_sink, trigger: in, process: b, params: {file: " +
                                         out.string() + "}, inputs: {in: count}}\n");
  Child launcher(Dyad({"run", g.string()}), dir_, "launcher");  // starts a and b as children
  std::this_thread::sleep_for(std::chrono::seconds(3));
  launcher.Signal(SIGINT);
  ASSERT_EQ(launcher.Wait(15), 130) << "hung or failed after SIGINT\n" << launcher.err();
  EXPECT_NE(launcher.err().find("dyad run: interrupted (SIGINT)"), std::string::npos) << launcher.err();
  EXPECT_EQ(launcher.err().find("exited with"), std::string::npos) << "a child was not stopped cleanly\n" << launcher.err();
  const std::string o = launcher.out();
  EXPECT_NE(o.find("timing (process a)"), std::string::npos) << o;
  EXPECT_NE(o.find("timing (process b)"), std::string::npos) << o;
  const std::string received = dyad::testing::ReadFile(out);
  EXPECT_GT(std::count(received.begin(), received.end(), '\n'), 10);
}

TEST_F(ProcessTest, InvalidGraphExitsTwoAndStartsNothing) {
  const fs::path out = dir_ / "never.txt";
  const fs::path g = Write("bad.yaml", "components:\n  sink: {type: counter_sink, trigger: in, params: {file: " + out.string() +
                                           ", expect: -1}, inputs: {in: nowhere}}\n");
  Child c(Dyad({"run", g.string()}), dir_, "bad");
  ASSERT_EQ(c.Wait(30), 2);
  EXPECT_NE(c.err().find(g.string() + ":2:"), std::string::npos) << c.err();
  EXPECT_NE(c.err().find("components.sink.params.expect"), std::string::npos) << c.err();
  EXPECT_NE(c.err().find("nothing publishes topic 'nowhere'"), std::string::npos) << c.err();
  EXPECT_FALSE(fs::exists(out));
  Child v(Dyad({"validate", g.string()}), dir_, "validate");
  EXPECT_EQ(v.Wait(30), 2);
}

TEST_F(ProcessTest, TypeMismatchWithAPeerIsReportedNamingBoth) {
  const fs::path g = Write("g.yaml", "graph: mm\ndomain_id: " + std::to_string(domain_) +
                                         "\ncomponents:\n"
                                         "  src: {type: counter_source, rate_hz: 10, outputs: {out: count}}\n"
                                         "  sink: {type: counter_sink, trigger: in, inputs: {in: count}}\n");
  Child peer({DYAD_TYPE_PEER, std::to_string(domain_), "count", "8", "dyad/mm/r1"}, dir_, "peer");
  Child c(Dyad({"run", g.string(), "--duration", "4", "--run-id", "r1"}), dir_, "mm");
  EXPECT_EQ(c.Wait(30), 1) << c.err();
  const std::string e = c.err();
  EXPECT_NE(e.find("type mismatch on topic 'count'"), std::string::npos) << e;
  EXPECT_NE(e.find("dyad::msg::Counter#0000000000000000"), std::string::npos) << e;
  EXPECT_NE(e.find("'type-peer'"), std::string::npos) << e;
  EXPECT_NE(e.find("'dyad/mm/main'"), std::string::npos) << e;
  peer.Signal(SIGTERM);
  peer.Wait(10);
}

}  // namespace

namespace {

TEST_F(ProcessTest, PluginThatDoesNotLoadIsAGraphErrorWithItsLine) {
  const fs::path g = Write("g.yaml", "graph: p\nplugins: [missing/plugin.so]\ncomponents:\n"
                                         "  src: {type: counter_source, rate_hz: 10}\n");
  Child c(Dyad({"validate", g.string()}), dir_, "validate");
  ASSERT_EQ(c.Wait(30), 2);
  EXPECT_NE(c.err().find(g.string() + ":2:11: plugins: " + (dir_ / "missing/plugin.so").string() + ": no such plugin"),
            std::string::npos)
      << c.err();
  Child d(Dyad({"run", (dir_ / "absent.yaml").string()}), dir_, "absent");
  ASSERT_EQ(d.Wait(30), 2);
  EXPECT_NE(d.err().find((dir_ / "absent.yaml").string() + ": cannot open graph file"), std::string::npos) << d.err();
}

// topics, echo and hz join the domain from outside and see a running graph.
TEST_F(ProcessTest, IntrospectionSeesARunningGraph) {
  const std::string domain = std::to_string(domain_);
  const fs::path g = Write("g.yaml", "graph: intro\ndomain_id: " + domain +
                                         "\ncomponents:\n"
                                         "  src: {type: counter_source, rate_hz: 50, params: {start: 1000}, outputs: {out: count}}\n"
                                         "  sink: {type: counter_sink, trigger: in, inputs: {in: count}}\n");
  Child run(Dyad({"run", g.string(), "--duration", "20", "--stats-period", "0.5"}), dir_, "run");

  // Generous discovery waits (they end at the first writer found): a loaded CI machine may take
  // seconds to start the graph. `topics` goes after `echo`, which proves the graph is up.
  Child echo(Dyad({"echo", "count", "--domain", domain, "-n", "3", "--wait", "20"}), dir_, "echo");
  ASSERT_EQ(echo.Wait(30), 0) << echo.err();
  const std::string e = echo.out();
  EXPECT_EQ(std::count(e.begin(), e.end(), '\n'), 3) << e;
  EXPECT_NE(e.find("{\"header\":{\"source\":\"src\",\"sequence_number\":"), std::string::npos) << e;
  EXPECT_NE(e.find("\"value\":1"), std::string::npos) << e;  // values start at 1000

  Child stats(Dyad({"echo", "dyad/stats", "--domain", domain, "-n", "1", "--wait", "20"}), dir_, "stats");
  ASSERT_EQ(stats.Wait(30), 0) << stats.err();
  EXPECT_NE(stats.out().find("\"process_name\":\"main\""), std::string::npos) << stats.out();

  Child topics(Dyad({"topics", "--domain", domain, "--wait", "4"}), dir_, "topics");
  ASSERT_EQ(topics.Wait(30), 0) << topics.err() << topics.out();
  EXPECT_NE(topics.out().find("count  dyad::msg::Counter#"), std::string::npos) << topics.out();
  EXPECT_NE(topics.out().find("dyad/intro/main"), std::string::npos) << topics.out();


  Child hz(Dyad({"hz", "count", "--domain", domain, "--duration", "2.5", "--wait", "20"}), dir_, "hz");
  ASSERT_EQ(hz.Wait(30), 0) << hz.err();
  double rate = 0;
  ASSERT_EQ(std::sscanf(hz.out().c_str(), "rate %lf Hz", &rate), 1) << hz.out();
  EXPECT_NEAR(rate, 50.0, 5.0) << hz.out();

  // Domain 231 is outside the tests' 1..200: nothing there, and `topics` says so.
  Child empty(Dyad({"topics", "--domain", "231", "--wait", "0.3"}), dir_, "empty");
  EXPECT_EQ(empty.Wait(30), 1);
  EXPECT_NE(empty.err().find("no endpoint discovered on domain 231 within 0.3 s"), std::string::npos) << empty.err();

  Child none(Dyad({"echo", "no/such/topic", "--domain", domain, "--wait", "1"}), dir_, "none");
  EXPECT_EQ(none.Wait(30), 1);
  EXPECT_NE(none.err().find("no writer of topic 'no/such/topic'"), std::string::npos) << none.err();

  run.Signal(SIGINT);
  EXPECT_EQ(run.Wait(15), 130) << run.err();
  EXPECT_NE(run.err().find("dyad run: interrupted (SIGINT)"), std::string::npos) << run.err();
}

}  // namespace

namespace {

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
  EXPECT_FALSE(fs::exists(out));  // the robot's process was not started here
}

// Two launchers started 3 s apart, as on two machines, in each discovery mode (on loopback):
// nothing runs before both are up, so the sink has every sample from the first.
// A loopback UDP port the kernel says is free now (a fixed one could be a Fast DDS port of a test
// running in parallel on another domain).
int FreeUdpPort() {
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof(a);
  int port = 0;
  if (fd >= 0 && bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)) == 0 &&
      getsockname(fd, reinterpret_cast<sockaddr*>(&a), &length) == 0)
    port = ntohs(a.sin_port);
  if (fd >= 0) close(fd);
  return port;
}

// The steps of `component` in a `dyad run` timing table printed in `out` (0: not found).
size_t StepsOf(const std::string& out, const std::string& component) {
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("[", 0) == 0 && line.find("] ") != std::string::npos) line.erase(0, line.find("] ") + 2);  // "[a] "
    std::istringstream row(line);
    std::string name;
    size_t steps = 0;
    if (row >> name >> steps && name == component) return steps;
  }
  return 0;
}

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

// The pid of the `dyad run ... --process P` child whose command line holds `graph`, or 0.
pid_t ChildPid(const fs::path& graph, const std::string& process) {
  for (const auto& entry : fs::directory_iterator("/proc")) {
    const std::string name = entry.path().filename();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream in(entry.path() / "cmdline");
    std::string cmdline((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::replace(cmdline.begin(), cmdline.end(), '\0', ' ');
    if (cmdline.find(graph.string()) != std::string::npos && cmdline.find("--process " + process + " ") != std::string::npos)
      return static_cast<pid_t>(std::stoi(name));
  }
  return 0;
}

// ChildPid, waiting up to 5 s for the launcher to start that child; 0 if it did not.
pid_t AwaitChildPid(const fs::path& graph, const std::string& process) {
  for (int i = 0; i < 100; ++i) {
    if (const pid_t pid = ChildPid(graph, process)) return pid;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return 0;
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

// `dyad status` on a split graph whose second process's clock is 25 ms ahead (the test-only
// DYAD_TEST_CLOCK_OFFSET_MS): both processes listed with their hosts and pids, the offset
// measured within 1 ms both ways, and the warning said by the process that measured it.
TEST_F(ProcessTest, StatusListsTheProcessesAndTheMeasuredClockOffsets) {
  const fs::path g = Write("g.yaml", "graph: clocks\nclock: wall\ndomain_id: " + std::to_string(domain_) +
                                         "\nnetwork: {discovery: peers, hosts: {h1: 127.0.0.1, h2: 127.0.0.1}}\n"
                                         "processes: {a: {host: h1}, b: {host: h2}}\ncomponents:\n"
                                         "  src: {type: counter_source, rate_hz: 20, process: a, outputs: {out: count}}\n"
                                         "  sink: {type: counter_sink, trigger: in, process: b, inputs: {in: count}}\n");
  Child a(Dyad({"run", g.string(), "--host", "h1", "--steps", "200"}), dir_, "a");
  Child b(Dyad({"run", g.string(), "--host", "h2", "--steps", "200"}), dir_, "b", {"DYAD_TEST_CLOCK_OFFSET_MS=25"});
  std::this_thread::sleep_for(std::chrono::seconds(3));
  Child status(Dyad({"status", "--graph", g.string(), "--wait", "4"}), dir_, "status");
  ASSERT_EQ(status.Wait(30), 0) << status.err();
  const pid_t pid_a = ChildPid(g, "a"), pid_b = ChildPid(g, "b");
  ASSERT_EQ(a.Wait(60), 0) << a.err();
  ASSERT_EQ(b.Wait(60), 0) << b.err();
  const std::string out = status.out();
  EXPECT_NE(out.find("clocks/a                h1              " + std::to_string(pid_a) + " "), std::string::npos) << out;
  EXPECT_NE(out.find("clocks/b                h2              " + std::to_string(pid_b) + " "), std::string::npos) << out;
  EXPECT_NE(out.find("running"), std::string::npos) << out;
  auto offset_ms = [&](const std::string& from, const std::string& to) {
    const std::string key = "  " + from + std::string(16 - from.size(), ' ') + "-> " + to;
    const auto at = out.find(key);
    EXPECT_NE(at, std::string::npos) << key << "\n" << out;
    return at == std::string::npos ? 0.0 : std::stod(out.substr(at + key.size(), 40));
  };
  // Within 1 ms; an instrumented build's scheduling delays make the round trips lopsided.
#ifdef DYAD_SANITIZED
  const double tolerance_ms = 5;
#else
  const double tolerance_ms = 1;
#endif
  EXPECT_NEAR(offset_ms("a", "b"), 25.0, tolerance_ms) << out;
  EXPECT_NEAR(offset_ms("b", "a"), -25.0, tolerance_ms) << out;
  EXPECT_NE(a.err().find("[warn] clock: the clock of process 'b' is +2"), std::string::npos) << a.err();
  EXPECT_NE(out.find("src                 a"), std::string::npos) << out;  // step stats
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
