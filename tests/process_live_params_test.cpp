// Process-level tests of live parameters: a param_script changes the mixer's gain in a stepped
// run (at the next step, the same in every run, recorded with refusals), and `dyad param get|set`
// reads and changes it in a running wall-clock graph.
#include "process_fixture.hpp"

#include "dyad/testing/csv.hpp"

#include <signal.h>

#include <map>

namespace {

using namespace dyad::testing;

// The mixer between fixed inputs (human at x = 10, robot at x = 0): its command's x is 10 * gain.
std::string MixerGraph(const std::string& clock, int domain, const fs::path& recording, const std::string& extra = "") {
  return "graph: live\nclock: " + clock + "\ndomain_id: " + std::to_string(domain) + "\nplugins: [" +
         DYAD_TEST_FIXED_INPUTS_PLUGIN + "]\ncomponents:\n"
         "  inputs: {type: fixed_inputs, rate_hz: 10, outputs: {human: human/input, robot: robot/intention}}\n"
         "  mixer: {type: compliance_mixer, rate_hz: 10, params: {max_step: 0, max_speed: 0},\n"
         "          inputs: {human: human/input, robot: robot/intention}, outputs: {command: robot/command}}\n"
         "  rec: {type: recorder, rate_hz: 10, params: {file: " + recording.string() + "}}\n" + extra;
}

TEST_F(ProcessTest, AScriptedLiveGainChangesAtTheNextStepTheSameInEveryRun) {
  const std::string script =
      "  script: {type: param_script, rate_hz: 10, outputs: {requests: dyad/param_requests}, params: {changes: [\n"
      "    {at_s: 1.5, set: {mixer.gain: 2, mixer.kp: 3}},\n"
      "    {at_s: 1.0, set: {mixer.gain: 0.2}}]}}\n";
  std::vector<std::string> exports;
  for (const std::string run : {"a", "b"}) {
    const fs::path rec = dir_ / (run + ".mcap");
    const fs::path g = Write(run + ".yaml", MixerGraph("stepped", domain_, rec, script));
    Child c(Dyad({"run", g.string(), "--steps", "30", "--quiet"}), dir_, "run_" + run);
    ASSERT_EQ(c.Wait(60), 0) << c.err();
    Child csv(Dyad({"bag", "export", rec.string(), "--csv", (dir_ / run).string()}), dir_, "csv_" + run);
    ASSERT_EQ(csv.Wait(60), 0) << csv.err();
    exports.push_back(ReadFile(dir_ / run / "robot_command.csv") + ReadFile(dir_ / run / "dyad_params.csv"));
  }
  EXPECT_EQ(exports[0], exports[1]) << "two runs of one stepped graph changed the gain differently";

  // The script asked at 1.0 s (step 10 of the mixer has run with 0.9): from step 11 on, 0.2.
  const auto commands = ReadCsv(dir_ / "a" / "robot_command.csv");
  ASSERT_EQ(commands.size(), 30u);
  for (size_t i = 0; i < commands.size(); ++i)
    EXPECT_DOUBLE_EQ(std::stod(commands[i].at("x")), i <= 10 ? 9.0 : 2.0) << "command " << i;
  const auto changes = ReadCsv(dir_ / "a" / "dyad_params.csv");
  ASSERT_EQ(changes.size(), 3u) << ReadFile(dir_ / "a" / "dyad_params.csv");
  EXPECT_EQ(changes[0].at("op"), "applied");
  EXPECT_EQ(changes[0].at("component_name") + "." + changes[0].at("param_name"), "mixer.gain");
  EXPECT_EQ(changes[0].at("old_value"), "0.9");
  EXPECT_EQ(changes[0].at("value"), "0.2");
  EXPECT_EQ(changes[0].at("step"), "11");
  EXPECT_EQ(changes[0].at("who"), "param_script script");
  EXPECT_EQ(changes[1].at("op"), "refused");
  EXPECT_EQ(changes[1].at("reason"), "must be <= 1, got 2");
  EXPECT_EQ(changes[2].at("op"), "refused");
  EXPECT_EQ(changes[2].at("reason"), "'kp' is not live: read once, at configure (live: gain, max_step)");
}

TEST_F(ProcessTest, ParamGetAndSetChangeARunningGraphAndAreRecorded) {
  const fs::path rec = dir_ / "rec.mcap";
  const fs::path g = Write("g.yaml", MixerGraph("wall", domain_, rec));
  Child run(Dyad({"run", g.string(), "--duration", "30", "--quiet"}), dir_, "run");

  Child get(Dyad({"param", "get", "mixer.gain", "--graph", g.string(), "--wait", "20"}), dir_, "get");
  ASSERT_EQ(get.Wait(60), 0) << get.err();
  EXPECT_EQ(get.out(), "mixer.gain: 0.9\n");
  Child set(Dyad({"param", "set", "mixer.gain=0.25", "--graph", g.string(), "--wait", "20"}), dir_, "set");
  ASSERT_EQ(set.Wait(60), 0) << set.err();
  EXPECT_EQ(set.out().rfind("mixer.gain: 0.9 -> 0.25 (from step ", 0), 0u) << set.out();
  // Checked against the graph file before anything is asked.
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"mixer.mode=pi", "dyad param: mixer.mode: not live: compliance_mixer reads it once, at configure (live params of mixer: gain, max_step)"},
      {"mixer.gain=7", "dyad param: mixer.gain = 7: must be <= 1, got 7"},
      {"mix.gain=0.1", "dyad param: mix.gain: graph 'live' has no component 'mix' (components: inputs, mixer, rec)"},
      {"mixer.gain", "dyad param: 'mixer.gain': expected COMPONENT.PARAM=VALUE (e.g. mixer.gain=0.5)"}};
  for (const auto& [arg, expected] : bad) {
    Child c(Dyad({"param", "set", arg, "--graph", g.string()}), dir_, "bad");
    EXPECT_EQ(c.Wait(30), 2) << arg;
    EXPECT_NE(c.err().find(expected), std::string::npos) << arg << ": " << c.err();
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // a few commands with the new gain
  run.Signal(SIGINT);
  ASSERT_EQ(run.Wait(30), 130) << run.err();
  Child csv(Dyad({"bag", "export", rec.string(), "--csv", (dir_ / "csv").string()}), dir_, "csv");
  ASSERT_EQ(csv.Wait(60), 0) << csv.err();
  const auto changes = ReadCsv(dir_ / "csv" / "dyad_params.csv");
  ASSERT_EQ(changes.size(), 2u) << ReadFile(dir_ / "csv" / "dyad_params.csv");
  EXPECT_EQ(changes[0].at("op"), "value");
  EXPECT_EQ(changes[1].at("op"), "applied");
  EXPECT_EQ(changes[1].at("who").rfind("dyad param (", 0), 0u) << changes[1].at("who");
  const auto commands = ReadCsv(dir_ / "csv" / "robot_command.csv");
  ASSERT_FALSE(commands.empty());
  EXPECT_DOUBLE_EQ(std::stod(commands.front().at("x")), 9.0);
  EXPECT_DOUBLE_EQ(std::stod(commands.back().at("x")), 2.5);
}

// A param_script's schedule is checked before anything runs: the element and what is wrong.
TEST_F(ProcessTest, ABadParamScriptIsRefusedNamingTheElement) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"{at_s: -1, set: {src.start: 1}}", "g.yaml:6:107: components.script.params.changes[0].at_s: must be a number of seconds >= 0"},
      {"{at_s: 1, set: {mix.gain: 1}}", "components.script.params.changes[0].set.mix.gain: no component 'mix' in the graph (components: script, src)"},
      {"{at_s: 1, set: {gain: 1}}", "components.script.params.changes[0].set.gain: must be COMPONENT.PARAM"}};
  for (const auto& [change, expected] : cases) {
    const fs::path g = Write("g.yaml", "graph: ps\nclock: stepped\ndomain_id: " + std::to_string(domain_) +
                                           "\ncomponents:\n  src: {type: counter_source, rate_hz: 10, outputs: {out: c}}\n"
                                           "  script: {type: param_script, rate_hz: 10, outputs: {requests: dyad/param_requests}, "
                                           "params: {changes: [" + change + "]}}\n");
    Child c(Dyad({"validate", g.string()}), dir_, "validate");
    EXPECT_EQ(c.Wait(30), 2) << change;
    EXPECT_NE(c.err().find(expected), std::string::npos) << change << ":\n" << c.err();
  }
}

}  // namespace
