// Invalid graphs are rejected before anything runs, each problem with file:line:col and key.
#include <gtest/gtest.h>

#include <filesystem>

#include <dyad/catalog.hpp>
#include <dyad/graph.hpp>
#include <dyad/validate.hpp>

#include "plugin_catalog.hpp"

namespace dyad {
namespace {

std::vector<Diagnostic> Check(const std::string& yaml, const std::vector<std::string>& sets = {}) {
  std::vector<Diagnostic> diags;
  std::vector<Override> overrides;
  for (const auto& s : sets) overrides.push_back({s});
  Graph g = ParseGraph(yaml, "g.yaml", overrides, &diags);
  if (!g.components.empty()) ValidateGraph(g, testing::BuiltPlugins(), &diags);
  return diags;
}

// A valid base graph; cases below change one thing.
const char* kValid = R"(graph: ok
clock: stepped
components:
  src:
    type: counter_source
    rate_hz: 10
    params: {noise: 1}
    outputs: {out: count}
  sink:
    type: counter_sink
    trigger: in
    inputs: {in: count}
)";

TEST(GraphValidation, ValidGraphHasNoProblems) {
  auto d = Check(kValid);
  for (const auto& x : d) ADD_FAILURE() << x.ToString();
}

struct BadCase {
  const char* name;
  std::string yaml;
  std::string where;  // "g.yaml:L:C"
  std::string key;
  std::string message_part;
};

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  const auto pos = s.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  if (pos != std::string::npos) s.replace(pos, from.size(), to);
  return s;
}

std::vector<BadCase> BadCases() {
  const std::string v = kValid;
  const std::string wall = Replace(v, "clock: stepped", "clock: wall ");  // same columns
  return {
      {"YamlSyntax", "components: {a: [1, 2}\n", "g.yaml:1:", "", "YAML syntax error"},
      {"UnknownTopLevelKey", Replace(v, "clock: stepped", "clock: stepped\nspeed: 3"), "g.yaml:3:1", "speed", "unknown key"},
      {"UnknownComponentKey", Replace(v, "    rate_hz: 10", "    rate_hz: 10\n    colour: red"), "g.yaml:7:5",
       "components.src.colour", "unknown key"},
      {"UnknownType", Replace(v, "type: counter_source", "type: counter_sauce"), "g.yaml:5:11", "components.src.type",
       "unknown component type 'counter_sauce'"},
      {"MissingType", Replace(v, "    type: counter_source\n", ""), "g.yaml:4:3", "components.src.type", "missing"},
      {"UnknownParam", Replace(v, "{noise: 1}", "{noize: 1}"), "g.yaml:7:14", "components.src.params.noize",
       "unknown parameter"},
      {"MistypedParam", Replace(v, "{noise: 1}", "{noise: loud}"), "g.yaml:7:21", "components.src.params.noise",
       "must be a finite number"},
      {"ParamOutOfRange", Replace(v, "{noise: 1}", "{noise: -1}"), "g.yaml:7:21", "components.src.params.noise",
       "must be >= 0"},
      {"IntParamGivenFloat", Replace(v, "{noise: 1}", "{limit: 2.5}"), "g.yaml:7:21", "components.src.params.limit",
       "must be an integer"},
      {"ZeroRate", Replace(v, "rate_hz: 10", "rate_hz: 0"), "g.yaml:6:14", "components.src.rate_hz", "must be > 0"},
      {"NegativeRate", Replace(v, "rate_hz: 10", "rate_hz: -5"), "g.yaml:6:14", "components.src.rate_hz", "must be > 0"},
      {"RateNotANumber", Replace(v, "rate_hz: 10", "rate_hz: fast"), "g.yaml:6:14", "components.src.rate_hz",
       "must be a number"},
      {"NoRateNorTrigger", Replace(v, "    trigger: in\n", ""), "g.yaml:9:3", "components.sink", "needs rate_hz"},
      {"TriggerNotAnInput", Replace(v, "trigger: in", "trigger: nope"), "g.yaml:11:14", "components.sink.trigger",
       "not an input"},
      {"DuplicateComponent", Replace(v, "  sink:", "  src:\n    type: counter_source\n    rate_hz: 1\n  sink:"),
       "g.yaml:9:3", "components.src", "duplicate key"},
      {"InputNobodyPublishes", Replace(v, "inputs: {in: count}", "inputs: {in: cuont}"), "g.yaml:12:18",
       "components.sink.inputs.in", "nothing publishes topic 'cuont'"},
      {"UnknownInputPort", Replace(v, "inputs: {in: count}", "inputs: {in: count, extra: count}"), "g.yaml:12:32",
       "components.sink.inputs.extra", "no input 'extra'"},
      {"UnknownOutputPort", Replace(v, "outputs: {out: count}", "outputs: {output: count}"), "g.yaml:8:23",
       "components.src.outputs.output", "no output 'output'"},
      {"TopicTypeMismatch", v + "topics:\n  count: {type: HumanInput}\n", "g.yaml:8:20", "components.src.outputs.out",
       "carries HumanInput"},
      {"UnknownTopicType", v + "topics:\n  count: {type: Humanoid}\n", "g.yaml:14:17", "topics.count.type",
       "unknown message type 'Humanoid'"},
      {"BadReliability", v + "topics:\n  count: {reliability: sometimes}\n", "g.yaml:14:24", "topics.count.reliability",
       "reliable or best_effort"},
      {"BadDepth", v + "topics:\n  count: {depth: 0}\n", "g.yaml:14:18", "topics.count.depth", "must be >= 1"},
      {"BadClock", Replace(v, "clock: stepped", "clock: sundial"), "g.yaml:2:8", "clock", "wall or stepped"},
      {"BadDomain", Replace(v, "clock: stepped", "clock: stepped\ndomain_id: 300"), "g.yaml:3:12", "domain_id",
       "0..232"},
      {"UndeclaredProcess", Replace(v, "    rate_hz: 10", "    rate_hz: 10\n    process: robot") + "processes:\n  main: {}\n",
       "g.yaml:7:14", "components.src.process", "no process 'robot'"},
      {"SteppedAcrossProcesses",
       Replace(Replace(v, "    rate_hz: 10", "    rate_hz: 10\n    process: a"), "    trigger: in", "    trigger: in\n    process: b") +
           "processes:\n  a: {}\n  b: {}\n",
       "g.yaml:2:8", "clock", "one process"},  // at the clock line
      {"RequiredInputUnbound", Replace(v, "    inputs: {in: count}\n", ""), "g.yaml:9:3", "components.sink.inputs.in",
       "required input is not bound"},
      {"BothRateAndTrigger", Replace(v, "    trigger: in", "    trigger: in\n    rate_hz: 5"), "g.yaml:11:14",
       "components.sink.trigger", "either rate_hz or trigger"},
      {"ComponentsNotAMap", "graph: x\ncomponents: [a, b]\n", "g.yaml:2:13", "components", "must be a mapping"},
      // ROS 2 topics (dyad/ros2_names.hpp): each rule a bad name breaks is said.
      {"Ros2NameRelative", wall + "topics:\n  arm: {ros2: servo/cmd, type: geometry_msgs/msg/Twist}\n", "g.yaml:14:15",
       "topics.arm.ros2", "must be fully qualified (start with '/')"},
      {"Ros2NameRepeatedSlash", wall + "topics:\n  arm: {ros2: /a//b, type: geometry_msgs/msg/Twist}\n", "g.yaml:14:15",
       "topics.arm.ros2", "must not contain repeated '/'"},
      {"Ros2NameDigitToken", wall + "topics:\n  arm: {ros2: /arm/2d, type: geometry_msgs/msg/Twist}\n", "g.yaml:14:15",
       "topics.arm.ros2", "must not start with a digit ('2d')"},
      {"Ros2NameBadCharacter", wall + "topics:\n  arm: {ros2: /arm-1, type: geometry_msgs/msg/Twist}\n", "g.yaml:14:15",
       "topics.arm.ros2", "not '-'"},
      {"Ros2NameTrailingSlash", wall + "topics:\n  arm: {ros2: /arm/, type: geometry_msgs/msg/Twist}\n", "g.yaml:14:15",
       "topics.arm.ros2", "must not end with '/'"},
      {"UnknownRos2Type", wall + "topics:\n  arm: {ros2: /a, type: geometry_msgs/msg/Wrench}\n", "g.yaml:14:25",
       "topics.arm.type", "unknown message type 'geometry_msgs/msg/Wrench'"},
      {"DyadTypeOnARos2Topic", wall + "topics:\n  arm: {ros2: /a, type: HumanInput}\n", "g.yaml:14:25", "topics.arm.type",
       "is a dyad type; ROS 2 topic '/a' needs a ROS 2 type"},
      {"Ros2TopicWithoutType", wall + "topics:\n  arm: {ros2: /a}\n", "g.yaml:14:15", "topics.arm.type",
       "a ROS 2 topic needs its type"},
      {"UnknownRos2Qos", wall + "topics:\n  arm: {ros2: /a, type: geometry_msgs/msg/Twist, qos: fast}\n", "g.yaml:14:55",
       "topics.arm.qos", "unknown ROS 2 QoS profile 'fast' (known: default, sensor_data"},
      {"QosOnADyadTopic", v + "topics:\n  count: {qos: default}\n", "g.yaml:14:16", "topics.count.qos",
       "only a ROS 2 topic"},
      {"Ros2TopicInASteppedRun", v + "topics:\n  arm: {ros2: /a, type: geometry_msgs/msg/Twist}\n", "g.yaml:2:8", "clock",
       "ROS 2 topic /a, which programs outside the graph share"},
      {"TwoTopicsOneRos2Name",
       wall + "topics:\n  a: {ros2: /x, type: geometry_msgs/msg/Twist}\n  b: {ros2: /x, type: geometry_msgs/msg/Twist}\n",
       "g.yaml:15:13", "topics.b.ros2", "is also topics.a.ros2"},
      {"SlashTopicName", Replace(Replace(v, "outputs: {out: count}", "outputs: {out: /count}"), "inputs: {in: count}", "inputs: {in: /count}"),
       "g.yaml:8:20", "topics./count", "a ROS 2 name: declare a topic of the graph with ros2: /count"},
      // Tried by hand while fuzzing graphs: yaml-cpp stops deep nesting but said only "bad file".
      {"NestedTooDeep", "graph: x\ncomponents: " + std::string(3000, '[') + "\n", "g.yaml:3:", "",
       "YAML syntax error: nested too deeply (500 levels)"},
  };
}

void PrintTo(const BadCase& c, std::ostream* os) { *os << c.name; }

class BadGraph : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadGraph, IsRejectedWithFileLineAndKey) {
  const BadCase& c = GetParam();
  const auto diags = Check(c.yaml);
  ASSERT_FALSE(diags.empty()) << "accepted:\n" << c.yaml;
  bool found = false;
  std::string all;
  for (const auto& d : diags) {
    all += d.ToString() + "\n";
    if (d.ToString().rfind(c.where, 0) == 0 && d.key == c.key && d.message.find(c.message_part) != std::string::npos)
      found = true;
  }
  EXPECT_TRUE(found) << "expected " << c.where << ": " << c.key << ": ..." << c.message_part << "...\ngot:\n" << all;
}

INSTANTIATE_TEST_SUITE_P(Table, BadGraph, ::testing::ValuesIn(BadCases()),
                         [](const ::testing::TestParamInfo<BadCase>& info) { return std::string(info.param.name); });

TEST(GraphValidation, ReportsEveryProblemAtOnce) {
  std::string y = Replace(Replace(Replace(kValid, "{noise: 1}", "{noise: -1}"), "rate_hz: 10", "rate_hz: 0"),
                          "inputs: {in: count}", "inputs: {in: other}");
  const auto diags = Check(y);
  EXPECT_GE(diags.size(), 3u);
}

TEST(GraphValidation, OverrideSetsParamAndIsValidated) {
  EXPECT_TRUE(Check(kValid, {"src.noise=2"}).empty());
  const auto bad = Check(kValid, {"src.noise=-3"});
  ASSERT_EQ(bad.size(), 1u);
  EXPECT_EQ(bad[0].key, "components.src.params.noise");
  EXPECT_NE(bad[0].mark.file.find("--set src.noise"), std::string::npos) << bad[0].ToString();
  const auto unknown = Check(kValid, {"nobody.noise=1"});
  ASSERT_EQ(unknown.size(), 1u);
  EXPECT_NE(unknown[0].message.find("no such component"), std::string::npos);
  EXPECT_EQ(Check(kValid, {"garbage"}).size(), 1u);
}

// Issue #40: where yaml-cpp threw out of the loader (`dyad validate` died with "terminate called
// after throwing an instance of 'YAML::InvalidNode'", exit 134): a malformed file given with a
// --set, a node of another kind where a mapping belongs, a --set into a section the file does not
// have. Each is a diagnostic at the file (or the --set) now; a --set is not checked against a
// file that could not be read (its syntax error is the one problem).
TEST(GraphValidation, MalformedInputIsADiagnosticAtItsFileNeverAnException) {
  const std::string v = kValid;
  struct Case {
    const char* name;
    std::string yaml;
    std::vector<std::string> sets;
    std::string where;  // the start of the diagnostic's text
    std::string message_part;
  };
  const Case cases[] = {
      {"syntax error with a set", "components: {a: [1, 2}\n", {"src.noise=2"}, "g.yaml:1:", "YAML syntax error"},
      {"tab indentation with a set", Replace(v, "  sink:\n    type", "  sink:\n\ttype"), {"src.noise=2"}, "g.yaml:", "YAML syntax error"},
      {"cut short in a flow mapping with a set", v.substr(0, v.find("{noise: 1}") + 9), {"src.noise=2"}, "g.yaml:", "YAML syntax error"},
      {"empty file with a set", "", {"src.noise=2"}, "g.yaml:1:1", "must be a YAML mapping"},
      {"network a scalar", v + "network: 5\n", {}, "g.yaml:13:10: network: must be a mapping", ""},
      {"cut short in a block with a set", v.substr(0, v.find("rate_hz") + 3), {"src.noise=2"}, "g.yaml:6:5: components.src.rat",
       "unknown key"},  // (a plain "rat" at the end is a key without a value to YAML)
      {"a set into absent processes", v, {"processes.robot.host=lab"}, "--set processes.robot.host=lab: processes.robot",
       "no such process"},
      {"a set into absent components", "graph: x\n", {"src.noise=2"}, "--set src.noise=2: components.src", "no such component"},
  };
  for (const Case& c : cases) {
    std::vector<Diagnostic> diags;
    EXPECT_NO_THROW(diags = Check(c.yaml, c.sets)) << c.name;
    std::string all;
    bool found = false;
    for (const auto& d : diags) {
      all += d.ToString() + "\n";
      found |= d.ToString().rfind(c.where, 0) == 0 && d.message.find(c.message_part) != std::string::npos;
    }
    EXPECT_TRUE(found) << c.name << ": expected " << c.where << "..." << c.message_part << "\ngot:\n" << all;
    if (c.message_part == "YAML syntax error") {
      EXPECT_EQ(diags.size(), 1u) << c.name << ":\n" << all;
    }
  }
}

TEST(GraphValidation, OverrideSetsTheGraphsOwnScalars) {
  std::vector<Diagnostic> diags;
  Graph g = ParseGraph(kValid, "g.yaml", {{"clock=wall"}, {"seed=7"}, {"domain_id=12"}, {"graph=renamed"}}, &diags);
  EXPECT_TRUE(diags.empty()) << diags[0].ToString();
  EXPECT_EQ(g.clock, ClockMode::kWall);
  EXPECT_EQ(g.seed, 7u);
  EXPECT_EQ(g.domain_id, 12);
  EXPECT_EQ(g.name, "renamed");
  EXPECT_NE(g.yaml_text.find("clock: wall"), std::string::npos) << g.yaml_text;  // recorded as run
  const std::pair<const char*, const char*> bad[] = {{"clock=sometimes", "must be wall or stepped"},
                                                     {"seed=-1", "non-negative integer"},
                                                     {"domain_id=999", "0..232"},
                                                     {"graph=two words", "A-Z a-z 0-9 _ . -"},
                                                     {"nokey=1", "expected COMPONENT.PARAM=VALUE"}};
  for (const auto& [set, why] : bad) {
    diags.clear();
    ParseGraph(kValid, "g.yaml", {{set}}, &diags);
    ASSERT_EQ(diags.size(), 1u) << set;
    EXPECT_EQ(diags[0].mark.file, std::string("--set ") + set);
    EXPECT_NE(diags[0].message.find(why), std::string::npos) << diags[0].ToString();
  }
}

// A process's host names its launcher's DDS participant, dyad/launcher/<host>, which a secured
// graph's participants must read back from its opaque wire name (dyad/wire_names.hpp): a host of
// 64 characters (a machine name's most) is taken, a longer one refused at its line, never left to
// be silently unreadable on the wire.
TEST(GraphValidation, AHostNameLongerThanAMachinesIsRefusedAtItsLine) {
  auto graph = [](const std::string& host) {
    return "graph: hosts\nprocesses:\n  a: {host: " + host + "}\n  b: {host: " + host + "}\n" +
           "components:\n  src: {type: counter_source, rate_hz: 10, process: a, outputs: {out: count}}\n" +
           "  sink: {type: counter_sink, trigger: in, process: b, inputs: {in: count}}\n";
  };
  const std::string edge = "lab-" + std::string(56, 'm') + ".org";  // 64: a machine name may have dots
  ASSERT_EQ(edge.size(), 64u);
  for (const auto& d : Check(graph(edge))) ADD_FAILURE() << d.ToString();
  ASSERT_EQ(LauncherParticipantName(edge).size(), 78u);
  const std::string longer = edge + "x";
  const auto diags = Check(graph(longer));
  ASSERT_EQ(diags.size(), 2u) << (diags.empty() ? "" : diags[0].ToString());
  EXPECT_EQ(diags[0].ToString().rfind("g.yaml:3:13: processes.a.host:", 0), 0u) << diags[0].ToString();
  EXPECT_NE(diags[0].message.find("has 65 characters: a host name has at most 64"), std::string::npos) << diags[0].ToString();
  EXPECT_NE(diags[0].message.find("dyad/launcher/<host>"), std::string::npos) << diags[0].ToString();
  EXPECT_EQ(diags[1].key, "processes.b.host");
}

// Legal holes in the wiring are warnings, at their lines; the graph stays valid.
TEST(GraphValidation, AnUnboundOutputAndADeclaredTopicNoComponentWritesAreWarnings) {
  std::vector<Diagnostic> diags;
  const std::string y = Replace(kValid, "    outputs: {out: count}\n", "") + "topics:\n  count: {type: Counter}\n";
  Graph g = ParseGraph(y, "g.yaml", {}, &diags);
  const ResolvedGraph r = ValidateGraph(g, testing::BuiltPlugins(), &diags);
  EXPECT_TRUE(diags.empty()) << diags[0].ToString();
  ASSERT_EQ(r.warnings.size(), 2u);
  EXPECT_EQ(r.warnings[0].key, "components.src.outputs.out");
  EXPECT_EQ(r.warnings[0].mark.line, 4);
  EXPECT_NE(r.warnings[0].message.find("bound to no topic"), std::string::npos);
  EXPECT_EQ(r.warnings[1].key, "topics.count");
  EXPECT_EQ(r.warnings[1].mark.line, 13);
  EXPECT_NE(r.warnings[1].message.find("no component of the graph writes"), std::string::npos);
  EXPECT_TRUE(ValidateGraph(ParseGraph(kValid, "g.yaml", {}, &diags), testing::BuiltPlugins(), &diags).warnings.empty());
}

// A graph open to the network without `interfaces` talks on every interface: a warning at the
// network section; naming them, or staying on this machine, says nothing.
TEST(GraphValidation, ANetworkGraphWithoutInterfacesIsWarnedAbout) {
  auto warnings = [](const std::string& network) {
    std::vector<Diagnostic> diags;
    Graph g = ParseGraph("graph: n\nnetwork: " + network + "\n" + std::string(kValid).substr(std::string(kValid).find("components:")), "g.yaml", {}, &diags);
    const ResolvedGraph r = ValidateGraph(g, testing::BuiltPlugins(), &diags);
    EXPECT_TRUE(diags.empty()) << diags[0].ToString();
    std::vector<Diagnostic> out;
    for (const auto& w : r.warnings)
      if (w.key == "network.interfaces") out.push_back(w);
    return out;
  };
  const auto open = warnings("{scope: lan}");
  ASSERT_EQ(open.size(), 1u);
  EXPECT_EQ(open[0].mark.line, 2);
  EXPECT_NE(open[0].message.find("every interface of each host (Wi-Fi included)"), std::string::npos) << open[0].ToString();
  EXPECT_TRUE(warnings("{scope: lan, interfaces: [eth0]}").empty());
  EXPECT_TRUE(warnings("{scope: local}").empty());
}

// A secret param (the web component's token) is redacted where it stands whole, and never
// inside a name that contains it: a token "web" leaves component `web` and topic `web/pointer`.
TEST(GraphValidation, SecretParamsAreRedactedWholeFromTheGraphText) {
  std::vector<Diagnostic> diags;
  const std::string y =
      "graph: red\ncomponents:\n"
      "  web: {type: web, rate_hz: 10, params: {token: web}, outputs: {pointer: web/pointer}}\n"
      "  human: {type: web_human, rate_hz: 10, inputs: {pointer: web/pointer}, outputs: {input: human/input}}\n"
      "topics:\n  human/input: {type: HumanInput}\n";
  Graph g = ParseGraph(y, "g.yaml", {{"web.port=0"}}, &diags);
  const ResolvedGraph r = ValidateGraph(g, testing::BuiltPlugins(), &diags);
  ASSERT_TRUE(diags.empty()) << diags[0].ToString();
  const std::string text = RedactedGraphYaml(g, r);
  EXPECT_NE(text.find("token: <redacted>"), std::string::npos) << text;
  EXPECT_NE(text.find("web/pointer"), std::string::npos) << text;
  Graph again = ParseGraph(text, "g.yaml", {}, &diags);
  ASSERT_TRUE(diags.empty()) << diags[0].ToString();
  EXPECT_NE(again.FindComponent("web"), nullptr) << text;

  Graph set = ParseGraph(y, "g.yaml", {{"web.token=LongS3cretToken"}}, &diags);
  const ResolvedGraph rs = ValidateGraph(set, testing::BuiltPlugins(), &diags);
  ASSERT_TRUE(diags.empty()) << diags[0].ToString();
  const std::string redacted = RedactedGraphYaml(set, rs);
  EXPECT_EQ(redacted.find("LongS3cretToken"), std::string::npos) << "the --set header keeps the token:\n" << redacted;
}

// A graph's name is part of its runs' DDS partition: no pattern characters, no spaces.
TEST(GraphValidation, AGraphNameThatCannotNameAPartitionIsAnErrorAtItsLine) {
  for (const char* name : {"demo*", "my graph", "a/b"}) {
    const auto diags = Check(Replace(kValid, "graph: ok", std::string("graph: \"") + name + "\""));
    ASSERT_EQ(diags.size(), 1u) << name;
    EXPECT_EQ(diags[0].key, "graph");
    EXPECT_EQ(diags[0].mark.line, 1);
    EXPECT_NE(diags[0].message.find(std::string("got '") + name + "'"), std::string::npos) << diags[0].ToString();
  }
}

TEST(GraphValidation, SteppedAcrossProcessesSetOnTheCommandLineIsBlamedOnTheSet) {
  std::string y = Replace(Replace(kValid, "clock: stepped", "clock: wall"), "    rate_hz: 10", "    rate_hz: 10\n    process: a");
  y = Replace(y, "    trigger: in", "    trigger: in\n    process: b") + "processes:\n  a: {}\n  b: {}\n";
  const auto diags = Check(y, {"clock=stepped"});
  ASSERT_EQ(diags.size(), 1u);
  EXPECT_EQ(diags[0].mark.file, "--set clock=stepped");
}

// What a recorder stores: the file as read, or with --set, the graph as run.
TEST(GraphValidation, OverridesAreInTheRecordedGraphText) {
  std::vector<Diagnostic> diags;
  EXPECT_EQ(ParseGraph(kValid, "g.yaml", {}, &diags).yaml_text, kValid);
  const Graph g = ParseGraph(kValid, "g.yaml", {{"src.noise=2.5"}, {"sink.limit=7"}}, &diags);
  ASSERT_TRUE(diags.empty());
  EXPECT_EQ(g.yaml_text.rfind("# the graph as run: g.yaml with --set src.noise=2.5 --set sink.limit=7\n", 0), 0u)
      << g.yaml_text;
  const YAML::Node run = YAML::Load(g.yaml_text);
  EXPECT_EQ(run["components"]["src"]["params"]["noise"].as<double>(), 2.5);
  EXPECT_EQ(run["components"]["sink"]["params"]["limit"].as<int>(), 7);
  EXPECT_EQ(run["components"]["src"]["rate_hz"].as<double>(), 10);  // the rest as written
}

TEST(GraphValidation, FillsDefaultsAndResolvesPeriods) {
  std::vector<Diagnostic> diags;
  Graph g = ParseGraph(kValid, "g.yaml", {}, &diags);
  ResolvedGraph r = ValidateGraph(g, testing::BuiltPlugins(), &diags);
  ASSERT_TRUE(diags.empty());
  ASSERT_EQ(r.components.size(), 2u);
  EXPECT_EQ(r.components[0].period_ns, 100'000'000);
  EXPECT_EQ(r.components[1].period_ns, 0);
  EXPECT_DOUBLE_EQ(r.components[0].params.Double("noise"), 1.0);
  EXPECT_EQ(r.components[0].params.Int("limit"), 0);
  EXPECT_EQ(r.topics.at("count").type->short_name(), "Counter");
}

// A path param written in a graph file is relative to that file's folder; one given with --set,
// to the working folder; absolute and empty values are kept; plain strings are not paths.
TEST(GraphValidation, PathParamsAreRelativeToTheGraphFileOrToTheWorkingFolderForASet) {
  const std::string graph = R"(graph: paths
clock: stepped
components:
  src: {type: counter_source, rate_hz: 10, outputs: {out: count}}
  a: {type: counter_sink, trigger: in, inputs: {in: count}, params: {file: out/a.txt}}
  b: {type: counter_sink, trigger: in, inputs: {in: count}, params: {file: /abs/b.txt}}
  c: {type: counter_sink, trigger: in, inputs: {in: count}, params: {file: ../c.txt}}
  d: {type: counter_sink, trigger: in, inputs: {in: count}}
  e: {type: counter_sink, trigger: in, inputs: {in: count}, params: {file: e.txt}}
)";
  std::vector<Diagnostic> diags;
  Graph g = ParseGraph(graph, "/lab/graphs/g.yaml", {{"e.file=set/e.txt"}}, &diags);
  ResolvedGraph r = ValidateGraph(g, testing::BuiltPlugins(), &diags);
  ASSERT_TRUE(diags.empty()) << diags[0].ToString();
  ASSERT_EQ(r.components.size(), 6u);
  EXPECT_EQ(r.components[1].params.String("file"), "/lab/graphs/out/a.txt");
  EXPECT_EQ(r.components[2].params.String("file"), "/abs/b.txt");
  EXPECT_EQ(r.components[3].params.String("file"), "/lab/c.txt");
  EXPECT_EQ(r.components[4].params.String("file"), "");
  EXPECT_EQ(r.components[5].params.String("file"), (std::filesystem::current_path() / "set/e.txt").string());
  // A relative graph path is taken from the working folder first.
  g = ParseGraph(graph, "graphs/g.yaml", {}, &diags);
  r = ValidateGraph(g, testing::BuiltPlugins(), &diags);
  EXPECT_EQ(r.components[1].params.String("file"), (std::filesystem::current_path() / "graphs/out/a.txt").string());
}

}  // namespace
}  // namespace dyad
