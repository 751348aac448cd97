// Process-level tests of one graph run: stepped and wall-clock runs in one or two OS processes,
// runs kept apart, what a run says at its end, signals, and bad graphs, plugins and peers.
#include "process_fixture.hpp"

#include <signal.h>
#include <sys/wait.h>

#include <regex>

namespace {

using namespace dyad::testing;

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

// A graph file is code: validating it runs its plugins. --no-plugins runs none (the marker
// plugin's file is not created), notes what it could not check, and validates the rest; without
// the flag the same graph's plugin does run (so the check can fail).
TEST_F(ProcessTest, ValidateWithoutPluginsRunsNoneOfTheGraphs) {
  const fs::path marker = dir_ / "plugin_was_loaded";
  ASSERT_EQ(setenv("DYAD_TEST_PLUGIN_MARKER", marker.c_str(), 1), 0);
  const fs::path g = Write("g.yaml", std::string("graph: p\nplugins: [") + DYAD_TEST_MARKER_PLUGIN + "]\ncomponents:\n"
                                         "  src: {type: counter_source, rate_hz: 10, outputs: {out: count}}\n"
                                         "  sink: {type: counter_sink, trigger: in, inputs: {in: count}}\n"
                                         "  arm: {type: from_the_plugin, rate_hz: 10}\n");
  Child safe(Dyad({"validate", g.string(), "--no-plugins"}), dir_, "safe");
  EXPECT_EQ(safe.Wait(30), 0) << safe.err();
  EXPECT_FALSE(fs::exists(marker)) << "validate --no-plugins loaded the graph's plugin";
  EXPECT_NE(safe.err().find(g.string() + ":2:11: note: plugin not loaded (--no-plugins)"), std::string::npos) << safe.err();
  EXPECT_NE(safe.err().find(g.string() + ":6:15: components.arm.type: note: not checked"), std::string::npos) << safe.err();
  // The rest is still checked.
  Child bad(Dyad({"validate", g.string(), "--no-plugins", "--set", "src.noise=-1"}), dir_, "bad");
  EXPECT_EQ(bad.Wait(30), 2) << bad.err();
  EXPECT_FALSE(fs::exists(marker));

  Child full(Dyad({"validate", g.string()}), dir_, "full");
  EXPECT_EQ(full.Wait(30), 2);  // from_the_plugin is not a type the marker registers
  EXPECT_TRUE(fs::exists(marker)) << full.err();
  unsetenv("DYAD_TEST_PLUGIN_MARKER");
}

}  // namespace
