// DDS Security from the graph (dyad/security.hpp), with real processes: a secured two-process
// graph runs and delivers; a watcher with the graph's host identity hears it; an intruder with
// no identity, or with an identity from another CA, hears nothing; a process cannot publish what
// its permissions do not grant; and on the wire (loopback, captured as root) the component name
// every sample carries is never in clear, while the same run without security shows it.
#include <csignal>
#include <tuple>

#include "process_fixture.hpp"

namespace dyad::testing {
namespace {

class SecurityTest : public ProcessTest {
 protected:
  // pub (component marker_ writes ca at 50 Hz) and sub (counter_sink of ca) in two
  // processes; `extra` goes under network: and the components.
  std::string Graph(const std::string& keystore, const std::string& network = "", const std::string& extra = "") {
    return "graph: secure\ndomain_id: " + std::to_string(domain_) + "\n" + (network.empty() ? "" : "network: " + network + "\n") +
           (keystore.empty() ? "" : "security: {keystore: " + keystore + "}\n") +
           "processes:\n  pub: {}\n  sub: {}\ncomponents:\n"
           "  " + marker_ + ": {type: counter_source, rate_hz: 50, process: pub, outputs: {out: ca}}\n"
           "  sink: {type: counter_sink, trigger: in, process: sub, params: {file: " + (dir_ / "sink.txt").string() +
           "}, inputs: {in: ca}}\n" + extra;
  }
  int Init(const fs::path& keystore, const fs::path& graph, std::string* err = nullptr) {
    Child c(Dyad({"security", "init", keystore.string(), "--graph", graph.string()}), dir_, "init" + std::to_string(inits_++));
    const int code = c.Wait(120);
    if (err) *err = c.err();
    EXPECT_EQ(code, 0) << c.err();
    return code;
  }
  int inits_ = 0;
  // The writer's name, in every sample it writes: the marker looked for on the wire. One per test
  // process: a test running beside this one must not put its marker on the same loopback.
  const std::string marker_ = "plaintextmarker" + std::to_string(getpid());
};

TEST_F(SecurityTest, ASecuredGraphDeliversToItsOwnAndNothingToIntruders) {
  const fs::path graph = Write("g.yaml", Graph("keys"));
  ASSERT_EQ(Init(dir_ / "keys", graph), 0);
  // The same graph under another CA: a valid identity, but not of this graph's keystore.
  const fs::path other = Write("other.yaml", Graph("other_keys"));
  ASSERT_EQ(Init(dir_ / "other_keys", other), 0);

  Child run(Dyad({"run", graph.string(), "--duration", "25", "--quiet"}), dir_, "run");
  // The graph's own watcher (identity host.local) hears the samples.
  Child own(Dyad({"echo", "ca", "--graph", graph.string(), "--count", "3", "--wait", "15"}), dir_, "own");
  ASSERT_EQ(own.Wait(60), 0) << own.err();
  EXPECT_NE(own.out().find("\"" + marker_ + "\""), std::string::npos) << own.out();

  // No identity: the secured participants ignore it; it finds no writer of ca.
  Child bare(Dyad({"echo", "ca", "--domain", std::to_string(domain_), "--count", "1", "--wait", "4"}), dir_, "bare");
  EXPECT_NE(bare.Wait(60), 0);
  EXPECT_EQ(bare.out().find(marker_), std::string::npos) << bare.out();
  Child topics(Dyad({"topics", "--domain", std::to_string(domain_), "--wait", "3"}), dir_, "topics");
  topics.Wait(60);
  EXPECT_EQ(topics.out().find("ca "), std::string::npos) << "an unauthenticated watcher discovered the graph:\n" << topics.out();
  // An identity from another CA: authentication fails, nothing is delivered.
  Child foreign(Dyad({"echo", "ca", "--graph", other.string(), "--count", "1", "--wait", "4"}), dir_, "foreign");
  EXPECT_NE(foreign.Wait(60), 0);
  EXPECT_EQ(foreign.out().find(marker_), std::string::npos) << foreign.out();

  run.Signal(SIGINT);
  EXPECT_EQ(run.Wait(60), 130) << run.err();  // 128 + SIGINT: interrupted, as asked
  const auto received = ReadSink(dir_ / "sink.txt");
  EXPECT_GT(received.size(), 50u) << "the secured graph's own processes talk";

  // The same graph without security: the bare watcher hears it (so the checks above can fail).
  const fs::path open = Write("open.yaml", Graph(""));
  Child open_run(Dyad({"run", open.string(), "--duration", "15", "--quiet"}), dir_, "open_run");
  Child heard(Dyad({"echo", "ca", "--domain", std::to_string(domain_), "--count", "1", "--wait", "10"}), dir_, "heard");
  EXPECT_EQ(heard.Wait(60), 0) << heard.err();
  EXPECT_NE(heard.out().find(marker_), std::string::npos) << heard.out();
  open_run.Signal(SIGINT);
  open_run.Wait(60);
}

// `security.guests`: dyad pub publishes into a secured graph as the guest identity init issues,
// exactly what the graph grants; a topic outside the grant, or a graph that grants nothing, is
// refused before any participant is made, naming the key to change.
TEST_F(SecurityTest, AGuestPublishesWhatTheGraphGrantsItAndNothingElse) {
  auto graph = [&](const std::string& guests) {
    return "graph: secure\ndomain_id: " + std::to_string(domain_) + "\nsecurity:\n  keystore: keys\n" + guests +
           "topics:\n  ext: {type: Counter}\n  other: {type: Counter}\nprocesses:\n  sub: {}\ncomponents:\n"
           "  sink: {type: counter_sink, trigger: in, process: sub, params: {file: " + (dir_ / "sink.txt").string() +
           "}, inputs: {in: ext}}\n"
           "  sink2: {type: counter_sink, trigger: in, process: sub, params: {file: " + (dir_ / "sink2.txt").string() +
           "}, inputs: {in: other}}\n";
  };
  const fs::path g = Write("g.yaml", graph("  guests:\n    publish: [ext]\n"));
  ASSERT_EQ(Init(dir_ / "keys", g), 0);
  EXPECT_NE(ReadFile(dir_ / "keys" / "identities" / "guest" / "permissions.xml").find("<topic>ext</topic>"), std::string::npos);
  Child run(Dyad({"run", g.string(), "--duration", "60", "--quiet"}), dir_, "run");
  Child pub(Dyad({"pub", "ext", "{value: 7}", "--graph", g.string(), "--wait", "30"}), dir_, "pub");
  EXPECT_EQ(pub.Wait(60), 0) << pub.err();
  Child refused(Dyad({"pub", "other", "{value: 8}", "--graph", g.string(), "--wait", "5"}), dir_, "refused");
  EXPECT_EQ(refused.Wait(60), 2);
  EXPECT_NE(refused.err().find("dyad pub: topic 'other': the graph's guests may not publish it: add it to "
                               "security.guests.publish (" + g.string() + ":6:14), then rerun `dyad security init"),
            std::string::npos)
      << refused.err();
  // Without the section, the guest has no identity: the message says which key to add.
  const fs::path closed = Write("closed.yaml", graph(""));
  Child none(Dyad({"pub", "ext", "{value: 9}", "--graph", closed.string(), "--wait", "5"}), dir_, "none");
  EXPECT_EQ(none.Wait(60), 2);
  EXPECT_NE(none.err().find("is secured and lets no guest publish: add `guests: {publish: [ext]}` under security:"),
            std::string::npos)
      << none.err();
  std::this_thread::sleep_for(std::chrono::seconds(1));
  run.Signal(SIGINT);
  EXPECT_EQ(run.Wait(60), 130) << run.err();
  const auto got = ReadSink(dir_ / "sink.txt");
  ASSERT_EQ(got.size(), 1u) << ReadFile(dir_ / "sink.txt");
  EXPECT_EQ(got[0].value, 7);
  EXPECT_TRUE(ReadSink(dir_ / "sink2.txt").empty());
}

// `dyad security export`: each host runs from its own subset (its host identity and its
// processes' only) and the secured graph delivers across the two; a host that starts with the
// other host's subset is refused before anything starts, naming the identity it lacks, the host
// the subset is for and the export that would give it. Without --host, `dyad run` runs the host
// its subset was exported for (as the watchers join as it), and says so.
TEST_F(SecurityTest, EachHostRunsFromItsOwnExportAndNotFromAnothers) {
  auto graph = [&](const std::string& keystore) {
    return "graph: subsets\nclock: wall\ndomain_id: " + std::to_string(domain_) +
           "\nnetwork:\n  discovery: peers\n  hosts: {h1: 127.0.0.1, h2: 127.0.0.1}\n  start_timeout_s: 30\n"
           "security: {keystore: " +
           keystore +
           "}\n"
           "processes: {a: {host: h1}, b: {host: h2}}\ncomponents:\n"
           "  src: {type: counter_source, rate_hz: 50, process: a, outputs: {out: count}}\n"
           "  sink: {type: counter_sink, trigger: in, process: b, params: {file: " +
           (dir_ / "sink.txt").string() + "}, inputs: {in: count}}\n";
  };
  const fs::path whole = Write("g.yaml", graph("keys"));
  ASSERT_EQ(Init(dir_ / "keys", whole), 0);
  for (const char* host : {"h1", "h2"}) {
    Child e(Dyad({"security", "export", (dir_ / "keys").string(), "--graph", whole.string(), "--host", host,
                  (dir_ / (std::string(host) + "_keys")).string()}),
            dir_, std::string("export_") + host);
    ASSERT_EQ(e.Wait(60), 0) << e.err();
  }
  ASSERT_FALSE(fs::exists(dir_ / "h1_keys" / "identities" / "process.b"));
  const fs::path on_h1 = Write("h1.yaml", graph("h1_keys")), on_h2 = Write("h2.yaml", graph("h2_keys"));
  // h1 from its subset alone (this machine's name is neither h1 nor h2), h2 named with --host.
  Child a(Dyad({"run", on_h1.string(), "--steps", "40"}), dir_, "a");
  Child b(Dyad({"run", on_h2.string(), "--host", "h2", "--steps", "40"}), dir_, "b");
  EXPECT_EQ(a.Wait(90), 0) << a.err();
  EXPECT_EQ(b.Wait(90), 0) << b.err();
  EXPECT_GE(ReadSink(dir_ / "sink.txt").size(), 30u) << a.err() << b.err();
  const std::string said = "dyad run: running as host 'h1', the host keystore " + (dir_ / "h1_keys").string() +
                           " was exported for (" + (dir_ / "h1_keys" / "subset.yaml").string() + ")\n";
  EXPECT_NE(a.err().find(said), std::string::npos) << a.err();
  EXPECT_EQ(a.err().find(said, a.err().find(said) + 1), std::string::npos) << "said once, by the launcher:\n" << a.err();
  EXPECT_EQ(b.err().find("running as host"), std::string::npos) << "--host given: nothing to say\n" << b.err();

  Child wrong(Dyad({"run", on_h2.string(), "--host", "h1", "--steps", "5"}), dir_, "wrong");
  EXPECT_EQ(wrong.Wait(60), 2);
  EXPECT_NE(wrong.err().find("identity 'process.a' is not in keystore " + (dir_ / "h2_keys").string() +
                             ": it is the subset for host 'h2' (" + (dir_ / "h2_keys" / "subset.yaml").string() +
                             "), which holds only process.b, host.h2; on the machine with the whole keystore, "
                             "`dyad security export " +
                             (dir_ / "keys").string() + " --graph " + whole.string() + " --host h1 OUT`"),
            std::string::npos)
      << wrong.err();
  EXPECT_NE(wrong.err().find("identity 'host.h1' is not in keystore"), std::string::npos) << wrong.err();
}

TEST_F(SecurityTest, AProcessCannotPublishWhatItsPermissionsDoNotGrant) {
  const fs::path graph = Write("g.yaml", Graph("keys"));
  ASSERT_EQ(Init(dir_ / "keys", graph), 0);
  // The graph grew a writer of cb in pub after the keystore was made: its permissions lack cb.
  const fs::path grown = Write("grown.yaml", Graph("keys", "", "  extra: {type: counter_source, rate_hz: 10, process: pub, outputs: {out: cb}}\n"));
  Child run(Dyad({"run", grown.string(), "--duration", "3", "--quiet"}), dir_, "run");
  EXPECT_NE(run.Wait(60), 0);
  EXPECT_NE(run.err().find("cb"), std::string::npos) << run.err();
  EXPECT_NE(run.err().find("DDS Security: the permissions of participant 'dyad/secure/pub' do not let it publish this topic"),
            std::string::npos)
      << run.err();
}

TEST_F(SecurityTest, NothingOnTheWireIsInClear) {
  if (geteuid() != 0) GTEST_SKIP() << "capturing loopback packets needs root (AF_PACKET)";
  // UDP only, so that data crosses loopback rather than shared memory.
  const std::string udp = "{transport: udp}";
  const fs::path secured = Write("g.yaml", Graph("keys", udp));
  ASSERT_EQ(Init(dir_ / "keys", secured), 0);
  const fs::path open = Write("open.yaml", Graph("", udp));
  auto marked = [&](const fs::path& graph) {
    Child capture({"/usr/bin/python3", DYAD_CAPTURE_MARKER, marker_, "8"}, dir_, "capture_" + graph.stem().string());
    EXPECT_TRUE(capture.WaitForOutput("capturing", 10)) << capture.err();
    Child run(Dyad({"run", graph.string(), "--duration", "5", "--quiet"}), dir_, "run_" + graph.stem().string());
    EXPECT_EQ(run.Wait(60), 0) << run.err();
    EXPECT_EQ(capture.Wait(30), 0) << capture.err();
    std::istringstream words(capture.out().substr(capture.out().find("packets")));
    std::string w1, w2;
    int packets = -1, count = -1;
    words >> w1 >> packets >> w2 >> count;
    EXPECT_GT(packets, 100) << capture.out();
    return count;
  };
  EXPECT_GT(marked(open), 50) << "without security the marker is on the wire (the check can fail)";
  EXPECT_EQ(marked(secured), 0) << "with security no packet carries the marker in clear";
  EXPECT_GT(ReadSink(dir_ / "sink.txt").size(), 100u);
}

// Nothing named in clear (dyad/wire_names.hpp, docs/security.md "Names on the wire"): a secured
// run placed on a host of its own, over UDP on loopback, with a stranger (an identity of another
// CA) trying to join it all along, captured as root: no frame carries the graph's name, a
// process's or the host's; the same run unsecured does (so the check can fail). The graph's own
// watcher still reads its peers' names (the start barrier and dyad status match by them).
TEST_F(SecurityTest, NoFrameNamesTheGraphItsProcessesOrItsHost) {
  if (geteuid() != 0) GTEST_SKIP() << "capturing loopback packets needs root (AF_PACKET)";
  const std::string tag = std::to_string(getpid());
  const std::string name = "hush" + tag, pa = "alpha" + tag, pb = "bravo" + tag, host = "lab" + tag;
  auto graph = [&](const std::string& graph_name, const std::string& keystore) {
    std::string g = "graph: " + graph_name + "\ndomain_id: " + std::to_string(domain_) + "\n";
    g += "network: {transport: udp, hosts: {" + host + ": 127.0.0.1}}\n";
    if (!keystore.empty()) g += "security: {keystore: " + keystore + "}\n";
    g += "processes:\n  " + pa + ": {host: " + host + "}\n  " + pb + ": {host: " + host + "}\ncomponents:\n";
    g += "  src: {type: counter_source, rate_hz: 50, process: " + pa + ", outputs: {out: ca}}\n";
    g += "  sink: {type: counter_sink, trigger: in, process: " + pb + ", params: {file: " + (dir_ / "sink.txt").string() + "}, ";
    return g + "inputs: {in: ca}}\n";
  };
  const fs::path secured = Write("g.yaml", graph(name, "keys")), open = Write("open.yaml", graph(name, ""));
  const fs::path stranger = Write("stranger.yaml", graph("stranger" + tag, "stranger_keys"));
  ASSERT_EQ(Init(dir_ / "keys", secured), 0);
  ASSERT_EQ(Init(dir_ / "stranger_keys", stranger), 0);
  const std::string markers = name + "," + pa + "," + pb + "," + host;
  // Frames naming any of them, over 10 s around a 7 s run; the stranger knocks all along.
  auto naming = [&](const fs::path& g, const std::string& label) {
    Child capture({"/usr/bin/python3", DYAD_CAPTURE_MARKER, markers, "10"}, dir_, "capture_" + label);
    EXPECT_TRUE(capture.WaitForOutput("capturing", 10)) << capture.err();
    Child run(Dyad({"run", g.string(), "--host", host, "--duration", "7", "--quiet"}), dir_, "run_" + label);
    // The graph's own watcher lists the writer of ca by its participant's name, read back.
    Child topics(Dyad({"topics", "--graph", g.string(), "--host", host, "--wait", "4"}), dir_, "topics_" + label);
    for (int i = 0; i < 3; ++i) {
      Child knock(Dyad({"echo", "ca", "--graph", stranger.string(), "--host", host, "--count", "1", "--wait", "1.5"}), dir_,
                  "knock_" + label + std::to_string(i));
      EXPECT_NE(knock.Wait(60), 0) << "the stranger heard the graph:\n" << knock.out();
    }
    topics.Wait(60);
    const std::string heard = topics.out() + topics.err();
    EXPECT_EQ(run.Wait(60), 0) << run.err();
    EXPECT_EQ(capture.Wait(30), 0) << capture.err();
    std::istringstream words(capture.out().substr(capture.out().find("packets")));
    std::string w1, w2;
    int packets = -1, count = -1;
    words >> w1 >> packets >> w2 >> count;
    EXPECT_GT(packets, 100) << capture.out();
    return std::make_tuple(count, capture.out(), heard);
  };
  const auto [open_count, open_out, open_topics] = naming(open, "open");
  EXPECT_GT(open_count, 20) << "without security the names are on the wire (the check can fail):\n" << open_out;
  for (const std::string& m : {name, pa, pb, host})
    EXPECT_EQ(open_out.find("marker " + m + " 0\n"), std::string::npos) << m << " not seen unsecured:\n" << open_out;
  const auto [secured_count, secured_out, secured_topics] = naming(secured, "secured");
  EXPECT_EQ(secured_count, 0) << "a secured run names something of the graph in clear:\n" << secured_out;
  // Its own watcher reads the names back from the opaque ones.
  EXPECT_NE(secured_topics.find("dyad/" + name + "/" + pa), std::string::npos) << secured_topics;
  EXPECT_NE(open_topics.find("dyad/" + name + "/" + pa), std::string::npos) << open_topics;
  EXPECT_GT(ReadSink(dir_ / "sink.txt").size(), 100u);
}

}  // namespace
}  // namespace dyad::testing
