// Process-level tests of the watchers: `dyad topics`, `echo`, `hz` and `status` on a running
// graph, as another program on the domain.
#include "process_fixture.hpp"

#include <signal.h>

#include <cstring>

namespace {

using namespace dyad::testing;

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

  // With --graph, `topics` and `status` end once they have seen what the graph says is there:
  // long before the 30 s they may wait. A graph of one process is in `status` too.
  const auto asked = std::chrono::steady_clock::now();
  Child graph_topics(Dyad({"topics", "--graph", g.string(), "--wait", "30"}), dir_, "graph_topics");
  ASSERT_EQ(graph_topics.Wait(60), 0) << graph_topics.err();
  EXPECT_NE(graph_topics.out().find("count  dyad::msg::Counter#"), std::string::npos) << graph_topics.out();
  Child status(Dyad({"status", "--graph", g.string(), "--wait", "30"}), dir_, "status");
  ASSERT_EQ(status.Wait(60), 0) << status.err();
  EXPECT_LT(std::chrono::steady_clock::now() - asked, std::chrono::seconds(10)) << "a watcher waited for its upper bound";
  EXPECT_NE(status.out().find("intro/main "), std::string::npos) << status.out();
  EXPECT_NE(status.out().find("running"), std::string::npos) << status.out();
  EXPECT_NE(status.out().find("src                 main"), std::string::npos) << status.out();
  EXPECT_NE(status.out().find("sink                main"), std::string::npos) << status.out();


  Child hz(Dyad({"hz", "count", "--domain", domain, "--duration", "2.5", "--wait", "20"}), dir_, "hz");
  ASSERT_EQ(hz.Wait(30), 0) << hz.err();
  double rate = 0;
  ASSERT_EQ(std::sscanf(hz.out().c_str(), "rate %lf Hz", &rate), 1) << hz.out();
  EXPECT_NEAR(rate, 50.0, 5.0) << hz.out();

  // The running graph as discovered (`dyad graph --live`): its process with its components, the
  // topic between them with its type and measured rate.
  Child live(Dyad({"graph", "--live", g.string(), "--wait", "20", "--listen", "2"}), dir_, "live");
  ASSERT_EQ(live.Wait(60), 0) << live.err();
  EXPECT_NE(live.out().find("label=\"process main\\nsrc (counter_source)\\nsink (counter_sink)\""), std::string::npos) << live.out();
  const size_t at = live.out().find("label=\"count\\nCounter\\n");
  ASSERT_NE(at, std::string::npos) << live.out();
  double live_rate = 0;
  EXPECT_EQ(std::sscanf(live.out().c_str() + at + std::strlen("label=\"count\\nCounter\\n"), "%lf Hz", &live_rate), 1) << live.out();
  EXPECT_NEAR(live_rate, 50.0, 5.0) << live.out();
  EXPECT_NE(live.out().find("\"p:dyad/intro/main\" -> \"t:count\""), std::string::npos) << live.out();

  // Domain 231 is outside the tests' 1..200: nothing there, and `topics` says so.
  Child empty(Dyad({"topics", "--domain", "231", "--wait", "0.3"}), dir_, "empty");
  EXPECT_EQ(empty.Wait(30), 1);
  EXPECT_NE(empty.err().find("no endpoint discovered on domain 231 within 0.3 s"), std::string::npos) << empty.err();

  Child none(Dyad({"echo", "no/such/topic", "--domain", domain, "--wait", "1"}), dir_, "none");
  EXPECT_EQ(none.Wait(30), 1);
  EXPECT_NE(none.err().find("no writer of topic 'no/such/topic'"), std::string::npos) << none.err();
  // Without --graph a watcher is local (this machine only): it says so, and how to watch a graph of scope lan.
  EXPECT_NE(none.err().find("; this watcher is local (network.scope: local"), std::string::npos) << none.err();

  run.Signal(SIGINT);
  EXPECT_EQ(run.Wait(15), 130) << run.err();
  EXPECT_NE(run.err().find("dyad run: interrupted (SIGINT)"), std::string::npos) << run.err();
}

// `dyad pub` publishes into a running graph as a guest: its fields as YAML, its type the graph's
// (or named), a dyad header filled in; the graph's input and `dyad echo` get the samples. A bad
// field is named at its column and nothing is published.
TEST_F(ProcessTest, PubReachesTheGraphAndEcho) {
  const std::string domain = std::to_string(domain_);
  const fs::path heard = dir_ / "heard.txt";
  const fs::path g = Write("g.yaml", "graph: pub\ndomain_id: " + domain +
                                         "\ntopics:\n  count: {type: Counter, depth: 8}\n"
                                         "components:\n"
                                         "  sink: {type: counter_sink, trigger: in, params: {file: " + heard.string() +
                                         ", expect: 5}, inputs: {in: count}}\n");
  Child run(Dyad({"run", g.string(), "--duration", "30", "--quiet"}), dir_, "run");
  Child bad(Dyad({"pub", "count", "{value: 1, stamp: 2}", "--graph", g.string()}), dir_, "bad");
  EXPECT_EQ(bad.Wait(30), 2);
  EXPECT_NE(bad.err().find("dyad pub: the fields: line 1, column 12: stamp: unknown member of dyad::msg::Counter (members: header, value)"),
            std::string::npos)
      << bad.err();
  // Three at 20 Hz with the graph's type, then two more with a header given, back to back (the
  // topic keeps 8: with depth 1 a slow sink rightly hears only the newer). With the graph, pub
  // waits for the graph's own readers: without it, for whichever readers it found first.
  Child pub(Dyad({"pub", "count", "{value: 42}", "--graph", g.string(), "--rate", "20", "--count", "3", "--wait", "20"}), dir_, "pub");
  ASSERT_EQ(pub.Wait(60), 0) << pub.err();
  EXPECT_NE(pub.out().find("dyad pub: 3 samples of dyad::msg::Counter on count"), std::string::npos) << pub.out();
  Child named(Dyad({"pub", "count", "{header: {source: me, sequence_number: 9}, value: -7}", "--graph", g.string(), "--count", "2",
                    "--wait", "20"}),
              dir_, "named");
  ASSERT_EQ(named.Wait(60), 0) << named.err();
  // Without a graph, the type named: on a topic nobody reads, published anyway, saying so.
  Child typed(Dyad({"pub", "nobody/reads", "{x: 0.5, engaged: true}", "--domain", domain, "--type", "HumanInput", "--wait", "0.5"}),
              dir_, "typed");
  ASSERT_EQ(typed.Wait(30), 0) << typed.err();
  EXPECT_NE(typed.out().find("dyad pub: 1 sample of dyad::msg::HumanInput on nobody/reads"), std::string::npos) << typed.out();
  EXPECT_NE(typed.err().find("warning: dyad pub: no reader of 'nobody/reads' discovered within 0.5 s; publishing anyway"),
            std::string::npos)
      << typed.err();
  ASSERT_EQ(run.Wait(60), 0) << run.err();  // the sink ends the run at its fifth sample
  // `dyad echo` hears `dyad pub`: echo opens its reader once it has found a writer (for its type),
  // so pub publishes at a rate for long enough, after a short wait for readers.
  Child echo(Dyad({"echo", "pub/echoed", "--domain", domain, "-n", "2", "--wait", "30", "--duration", "40"}), dir_, "echo");
  Child echoed(Dyad({"pub", "pub/echoed", "{value: 7}", "--domain", domain, "--type", "Counter", "--rate", "10", "--count", "60",
                     "--wait", "0.5"}),
               dir_, "echoed");
  ASSERT_EQ(echo.Wait(60), 0) << echo.err();
  echoed.Signal(SIGINT);
  EXPECT_EQ(echoed.Wait(30), 130) << echoed.err();  // stopped before its count: 128 + SIGINT
  EXPECT_NE(echo.out().find("{\"header\":{\"source\":\"dyad/pub\",\"sequence_number\":"), std::string::npos) << echo.out();
  EXPECT_NE(echo.out().find("\"value\":7}"), std::string::npos) << echo.out();

  const std::vector<Received> got = ReadSink(heard);
  ASSERT_EQ(got.size(), 5u) << ReadFile(heard);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(got[i].value, 42);
    EXPECT_EQ(got[i].source, "dyad/pub");
    EXPECT_EQ(got[i].sequence, i + 1);
    EXPECT_GT(got[i].stamp_ns, 0);
  }
  for (size_t i = 3; i < 5; ++i) {
    EXPECT_EQ(got[i].value, -7);
    EXPECT_EQ(got[i].source, "me");
    EXPECT_EQ(got[i].sequence, 9u);
  }
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
  // Both have measured the other (each warns: 25 ms is past max_clock_offset_ms), and published it.
  const std::string warned = "[warn] clock: the clock of process";
  for (int i = 0; i < 300 && (a.err().find(warned) == std::string::npos || b.err().find(warned) == std::string::npos); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  std::this_thread::sleep_for(std::chrono::seconds(1));
  // With --graph it ends once it has heard all of it: long before the 30 s it may wait.
  const auto asked = std::chrono::steady_clock::now();
  Child status(Dyad({"status", "--graph", g.string(), "--wait", "30"}), dir_, "status");
  ASSERT_EQ(status.Wait(60), 0) << status.err();
  EXPECT_LT(std::chrono::steady_clock::now() - asked, std::chrono::seconds(10)) << "status waited for its upper bound";
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

}  // namespace
