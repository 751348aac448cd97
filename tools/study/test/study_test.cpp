// A study file: its counterbalanced plan (a balanced Latin square, checked by its definition),
// blind labels, trial files, and every bad input at its line.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <vector>

#include <dyad/msg/types.hpp>

#include "attempt_outcome.hpp"
#include "bootstrap.hpp"
#include "dyad/mcap/reader.hpp"
#include "dyad/pvrnn/analytic_dataset.hpp"
#include "dyad/pvrnn/dataset.hpp"
#include "dyad/testing/cli.hpp"
#include "dyad/testing/csv.hpp"
#include "dyad/testing/mcap_channel.hpp"
#include "latin_square.hpp"
#include "self_reports.hpp"
#include "study_analysis.hpp"
#include "study_commands.hpp"
#include "study_file.hpp"
#include "study_serve.hpp"
#include "study_session.hpp"

namespace dyad::study {
namespace {

namespace fs = std::filesystem;

class LatinSquare : public ::testing::TestWithParam<int> {};

TEST_P(LatinSquare, EveryPositionAndEverySuccessionEquallyOften) {
  const int n = GetParam();
  const auto rows = BalancedLatinSquare(n);
  ASSERT_EQ(static_cast<int>(rows.size()), n % 2 == 0 ? n : 2 * n);
  std::map<std::pair<int, int>, int> at, follows;  // (position, condition), (a, b)
  for (const auto& row : rows) {
    ASSERT_EQ(static_cast<int>(row.size()), n);
    EXPECT_EQ(std::set<int>(row.begin(), row.end()).size(), static_cast<size_t>(n)) << "not a permutation";
    for (int i = 0; i < n; ++i) ++at[{i, row[static_cast<size_t>(i)]}];
    for (int i = 0; i + 1 < n; ++i) ++follows[{row[static_cast<size_t>(i)], row[static_cast<size_t>(i) + 1]}];
  }
  const int per = static_cast<int>(rows.size()) / n;
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < n; ++c) EXPECT_EQ((at[{i, c}]), per) << "condition " << c << " at position " << i;
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      if (a == b) continue;
      EXPECT_EQ((follows[{a, b}]), per) << a << " then " << b;
    }
}

INSTANTIATE_TEST_SUITE_P(Sizes, LatinSquare, ::testing::Values(1, 2, 3, 4, 5, 6, 7));

class StudyFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("dyad_study_" + std::to_string(getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    std::ofstream(dir_ / "g.yaml") << "graph: g\nclock: stepped\ncomponents:\n"
                                      "  src: {type: counter_source, rate_hz: 10, outputs: {out: c}}\n"
                                      "  sink: {type: counter_sink, rate_hz: 10, inputs: {in: c}}\n"
                                      "  recorder: {type: recorder, rate_hz: 1}\n";
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  std::string Write(const std::string& text) {
    std::ofstream(dir_ / "s.yaml") << text;
    return (dir_ / "s.yaml").string();
  }
  fs::path dir_;
};

TEST_F(StudyFile, ThePlanIsCounterbalancedBlindAndFixed) {
  const std::string f = Write("study: gain\ngraph: g.yaml\nparticipants: [P01, P02, P03, P04, P05, P06]\n"
                              "conditions:\n  low: {src.start: 1}\n  mid: {src.start: 2}\n  high: {src.start: 3}\n"
                              "trials: 2\nblind: true\n");
  std::vector<Diagnostic> problems;
  const Study s = LoadStudy(f, {}, &problems);
  ASSERT_TRUE(problems.empty()) << problems.front().ToString();
  EXPECT_EQ(s.data, (dir_ / "gain-data").string());
  EXPECT_EQ(s.square_rows, 6);
  std::set<std::string> labels;
  for (const auto& c : s.conditions) labels.insert(c.label);
  EXPECT_EQ(labels, (std::set<std::string>{"A", "B", "C"}));
  // Six participants: the six rows of the square, each condition twice in a row, files by label.
  std::set<std::vector<int>> orders;
  for (const auto& p : s.participants) {
    const auto trials = s.TrialsOf(p);
    ASSERT_EQ(trials.size(), 6u);
    std::vector<int> order;
    for (size_t i = 0; i < trials.size(); i += 2) {
      EXPECT_EQ(trials[i].condition, trials[i + 1].condition);
      EXPECT_EQ(trials[i + 1].repetition, 2);
      order.push_back(trials[i].condition);
    }
    orders.insert(order);
    const auto& c = s.conditions[static_cast<size_t>(trials[0].condition)];
    EXPECT_EQ(trials[0].file, (dir_ / "gain-data" / p / ("01-" + c.label + ".mcap")).string());
    EXPECT_EQ(s.Shown(c), "condition " + c.label);
  }
  EXPECT_EQ(orders.size(), 6u) << "every participant of a full square has an order of their own";
  // The same file gives the same plan and labels: it is fixed before anyone comes.
  std::vector<Diagnostic> again_problems;
  const Study again = LoadStudy(f, {}, &again_problems);
  for (size_t i = 0; i < s.conditions.size(); ++i) EXPECT_EQ(again.conditions[i].label, s.conditions[i].label);
  EXPECT_EQ(again.TrialsOf("P04")[3].file, s.TrialsOf("P04")[3].file);
}

TEST_F(StudyFile, EveryBadInputIsSaidAtItsLine) {
  const std::string f = Write("study: gain\ngraph: g.yaml\nparticipants: [P01, Jane Doe, P01]\n"
                              "conditions:\n  low: {src.nope: 1}\n  high: {}\n"
                              "trials: 0\nself_reports: sometimes\ncolour: blue\n");
  std::vector<Diagnostic> problems;
  LoadStudy(f, {}, &problems);
  std::string all;
  for (const auto& p : problems) all += p.ToString() + "\n";
  for (const std::string expected :
       {"s.yaml:3:21: participants[1]: 'Jane Doe' is not a pseudonymous ID", "s.yaml:3:31: participants[2]: participant P01 is listed twice (first at line 3)",
        "s.yaml:5:19: conditions.low.src.nope: does not validate:", "s.yaml:6:9: conditions.high: overrides nothing",
        "s.yaml:7:9: trials: must be in 1..99", "s.yaml:8:15: self_reports: must be after_event, after_trial or off",
        "s.yaml:9:1: colour: unknown key"})
    EXPECT_NE(all.find(expected), std::string::npos) << "no '" << expected << "' in\n" << all;
}

// The keys dyad study run and rehearse read: a recorder the graph lacks, a rehearsal graph that
// is not there or whose keys a condition does not find, after_trial without a page to ask.
TEST_F(StudyFile, BadRecorderRehearsalAndSelfReportsAreSaidAtTheirLine) {
  std::ofstream(dir_ / "other.yaml") << "graph: other\nclock: stepped\ncomponents:\n"
                                        "  src: {type: counter_source, rate_hz: 10, outputs: {out: c}}\n";
  for (const auto& [text, expected] : std::vector<std::pair<std::string, std::string>>{
           {"recorder: rec\n", "s.yaml:6:11: recorder: the graph's recorder 'rec' cannot record a trial:"},
           {"rehearsal: {graph: missing.yaml}\n", "s.yaml:6:20: rehearsal.graph: no such file: " + (dir_ / "missing.yaml").string()},
           {"rehearsal: {graph: other.yaml}\n", "s.yaml:6:12: rehearsal: condition low does not validate on the rehearsal graph"},
           {"rehearsal: {colour: blue}\n", "s.yaml:6:13: rehearsal.colour: unknown key"},
           {"self_reports: after_trial\n", "s.yaml:6:15: self_reports: after_trial needs the graph's one `web` component (its "
                                            "subject's page asks, then ends the trial) with its self_report output bound; " +
                                                (dir_ / "g.yaml").string() + " has none"}}) {
    const std::string f = Write("study: gain\ngraph: g.yaml\nparticipants: [P01]\nconditions:\n  low: {sink.rate_hz: 5}\n" + text);
    std::vector<Diagnostic> problems;
    LoadStudy(f, {}, &problems);
    std::string all;
    for (const auto& p : problems) all += p.ToString() + "\n";
    EXPECT_NE(all.find(expected), std::string::npos) << "no '" << expected << "' in\n" << all;
  }
}

// Where dyad study serve admits pages from: a browser leaves the scheme's default port out of its
// Origin, so an origin at 443 (https) or 80 (http) is admitted in both forms; others as given.
TEST(ServeOrigins, AnOriginAtItsSchemesDefaultPortIsAdmittedWithoutItToo) {
  ServeOptions o;
  o.address = "127.0.0.1";
  o.port = 443;
  o.tls_certificate = "web.pem";
  o.origins = {"https://proxy.example.org:8443", "http://lab.example.org:80"};
  const std::vector<std::string> got = PageOrigins(o, {"https://study.example.org:443", "https://study.example.org"});
  const std::set<std::string> origins(got.begin(), got.end());
  for (const char* expected : {"https://127.0.0.1:443", "https://127.0.0.1", "https://study.example.org",
                               "https://study.example.org:443", "http://lab.example.org", "https://proxy.example.org:8443"})
    EXPECT_EQ(origins.count(expected), 1u) << expected;
  EXPECT_EQ(origins.count("https://proxy.example.org"), 0u) << "8443 is no default port";
  o.port = 8443;
  o.tls_certificate.clear();
  const std::vector<std::string> plain = PageOrigins(o, {});
  EXPECT_EQ(std::set<std::string>(plain.begin(), plain.end()),
            (std::set<std::string>{"https://proxy.example.org:8443", "http://lab.example.org:80", "http://lab.example.org",
                                   "http://127.0.0.1:8443"}));
}

// The `online:` map of `dyad study serve`: its defaults, its values read, and each bad one at its line.
TEST_F(StudyFile, OnlineKeysAreReadAndEachBadOneIsSaidAtItsLine) {
  const std::string head = "study: gain\ngraph: g.yaml\nparticipants: [P01]\nconditions:\n  low: {src.start: 1}\n";
  std::vector<Diagnostic> problems;
  const Study defaults = LoadStudy(Write(head), {}, &problems);
  ASSERT_TRUE(problems.empty()) << problems.front().ToString();
  EXPECT_EQ(defaults.online.reconnect_s, 60);
  EXPECT_EQ(defaults.online.max_sessions, 16);
  EXPECT_EQ(defaults.online.completion_code, "");
  EXPECT_EQ(defaults.online.consent, "");
  std::ofstream(dir_ / "consent.txt") << "I agree to take part.\n";
  const Study s =
      LoadStudy(Write(head + "online:\n  reconnect_s: 5\n  max_sessions: 3\n  domains: [40, 42]\n  completion_code: C0DE-42\n"
                             "  consent: consent.txt\n"),
                {}, &problems);
  ASSERT_TRUE(problems.empty()) << problems.front().ToString();
  EXPECT_EQ(s.online.reconnect_s, 5);
  EXPECT_EQ(s.online.max_sessions, 3);
  ASSERT_TRUE(s.online.domains.has_value());
  EXPECT_EQ(s.online.domains->first, 40);
  EXPECT_EQ(s.online.domains->last, 42);
  EXPECT_FALSE(defaults.online.domains.has_value()) << "none given: from the graph's domain_id";
  EXPECT_EQ(s.online.completion_code, "C0DE-42");
  EXPECT_EQ(s.online.consent, (dir_ / "consent.txt").string());
  EXPECT_EQ(s.online.consent_text, "I agree to take part.\n");
  std::ofstream(dir_ / "empty.txt") << "  \n";
  for (const auto& [text, expected] : std::vector<std::pair<std::string, std::string>>{
           {"online:\n  reconnect_s: 0\n", "s.yaml:7:16: online.reconnect_s: must be > 0"},
           {"online:\n  reconnect_s: soon\n", "s.yaml:7:16: online.reconnect_s: must be a number of seconds, got 'soon'"},
           {"online:\n  max_sessions: 0\n", "s.yaml:7:17: online.max_sessions: must be >= 1"},
           {"online:\n  domains: [40]\n", "s.yaml:7:12: online.domains: must be [FIRST, LAST], two DDS domain ids in 0..232"},
           {"online:\n  domains: [42, 40]\n", "s.yaml:7:12: online.domains: must be [FIRST, LAST]"},
           {"online:\n  domains: [230, 233]\n", "s.yaml:7:12: online.domains: must be [FIRST, LAST]"},
           {"online:\n  domains: [-1, 3]\n", "s.yaml:7:12: online.domains: must be [FIRST, LAST]"},
           {"online:\n  domains: 40-42\n", "s.yaml:7:12: online.domains: must be [FIRST, LAST]: two DDS domain ids"},
           // fewer domains than live sessions, given or from the graph's domain_id on (past 232)
           {"online:\n  max_sessions: 3\n  domains: [40, 41]\n",
            "s.yaml:8:12: online.domains: 40-41 holds 2 domains for max_sessions 3"},
           {"online:\n  max_sessions: 234\n", "s.yaml:7:17: online.max_sessions: max_sessions 234 trials need domains 0-233"},
           {"online:\n  completion_code: a b\n", "s.yaml:7:20: online.completion_code: a code is 1-64 letters, digits"},
           {"online:\n  consent: missing.txt\n", "s.yaml:7:12: online.consent: cannot read " + (dir_ / "missing.txt").string()},
           {"online:\n  consent: empty.txt\n", "s.yaml:7:12: online.consent: " + (dir_ / "empty.txt").string() + " is empty"},
           {"online:\n  colour: blue\n", "s.yaml:7:3: online.colour: unknown key"},
           {"online: 3\n", "s.yaml:6:9: online: must be a mapping"}}) {
    problems.clear();
    LoadStudy(Write(head + text), {}, &problems);
    std::string all;
    for (const auto& p : problems) all += p.ToString() + "\n";
    EXPECT_NE(all.find(expected), std::string::npos) << "no '" << expected << "' in\n" << all;
  }
}

// `dyad study plan s.yaml` in the file's own folder: a bare file name has no parent folder (it
// used to throw from std::filesystem::absolute("")).
TEST_F(StudyFile, AFileNamedWithoutItsFolderIsReadInTheWorkingFolder) {
  Write("study: gain\ngraph: g.yaml\nparticipants: [P01]\nconditions:\n  low: {src.start: 1}\n");
  const fs::path before = fs::current_path();
  fs::current_path(dir_);
  std::vector<Diagnostic> problems;
  const Study s = LoadStudy("s.yaml", {}, &problems);
  fs::current_path(before);
  ASSERT_TRUE(problems.empty()) << problems.front().ToString();
  EXPECT_EQ(s.graph, (dir_ / "g.yaml").string());
  EXPECT_EQ(s.data, (dir_ / "gain-data").string());
}

TEST_F(StudyFile, PlanCommandPrintsOrdersAndKeepsTheBlind) {
  const std::string f = Write("study: gain\ngraph: g.yaml\nparticipants: [P01, P02, P03]\n"
                              "conditions:\n  low: {src.start: 1}\n  high: {src.start: 3}\nblind: true\n");
  auto r = dyad::testing::RunCommand(dyad::cli::AddStudyCommands, {"study", "plan", f});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("3 participants x 2 conditions x 1 trial"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("3 participants are not a multiple of 2: the orders are not balanced"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("low"), std::string::npos) << "a blind plan named a condition:\n" << r.out;
  EXPECT_NE(r.out.find("  P01: 01 "), std::string::npos) << r.out;
  auto unblind = dyad::testing::RunCommand(dyad::cli::AddStudyCommands, {"study", "plan", f, "--unblind"});
  EXPECT_NE(unblind.out.find("low (condition "), std::string::npos) << unblind.out;
  auto bad = dyad::testing::RunCommand(dyad::cli::AddStudyCommands, {"study", "plan", Write("study: x\n")});
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("graph: required key missing"), std::string::npos) << bad.err;
}

TEST(Bootstrap, OneValueIsItsOwnIntervalAndNansAreLeftOut) {
  const MeanInterval ci = BootstrapMean({std::nan(""), 0.25, std::nan("")}, 1);
  EXPECT_EQ(ci.n, 1);
  EXPECT_EQ(ci.mean, 0.25);
  EXPECT_EQ(ci.low, 0.25);
  EXPECT_EQ(ci.high, 0.25);
  const MeanInterval none = BootstrapMean({std::nan("")}, 1);
  EXPECT_EQ(none.n, 0);
  EXPECT_TRUE(std::isnan(none.mean) && std::isnan(none.low) && std::isnan(none.high));
}

// Two values a < b: a resample's mean is a, (a+b)/2 or b with probabilities 1/4, 1/2, 1/4, so
// the 2.5% and 97.5% quantiles are a and b.
TEST(Bootstrap, TwoValuesSpanTheirInterval) {
  const MeanInterval ci = BootstrapMean({0.8, 0.6}, 99);
  EXPECT_DOUBLE_EQ(ci.mean, 0.7);
  EXPECT_DOUBLE_EQ(ci.low, 0.6);
  EXPECT_DOUBLE_EQ(ci.high, 0.8);
}

// The documented draw (indices rng() % n of one mt19937_64) and type-1 quantiles, replayed here:
// with 40 resamples the 95% interval is the smallest and the 39th smallest of the 40 means.
TEST(Bootstrap, TheIntervalIsTheType1QuantilesOfTheDocumentedResamples) {
  const std::vector<double> x = {1, 2, 3, 4, 5, 6, 7};
  std::mt19937_64 rng(11);
  std::vector<double> means(40);
  for (double& m : means) {
    double s = 0;
    for (size_t i = 0; i < x.size(); ++i) s += x[static_cast<size_t>(rng() % x.size())];
    m = s / 7;
  }
  std::sort(means.begin(), means.end());
  const MeanInterval ci = BootstrapMean(x, 11, 40);
  EXPECT_EQ(ci.low, means[0]);
  EXPECT_EQ(ci.high, means[38]);
  EXPECT_EQ(BootstrapMean(x, 11, 40, /*level=*/7.0).low, ci.low) << "a level outside (0, 1) is 0.95";
}

// 600 samples of 25 draws from N(1, 2^2): the 95% interval covers the true mean in about 95% of
// them (the percentile bootstrap undercovers a little at this size: 92% measured), and the same values
// and seed give the same interval.
TEST(Bootstrap, CoversTheTrueMeanAboutAsOftenAsItSays) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal(1.0, 2.0);
  int covered = 0;
  for (int k = 0; k < 600; ++k) {
    std::vector<double> x(25);
    for (double& v : x) v = normal(rng);
    const MeanInterval ci = BootstrapMean(x, static_cast<uint64_t>(k), 2000);
    covered += ci.low <= 1.0 && 1.0 <= ci.high;
    if (k == 0) {
      const MeanInterval again = BootstrapMean(x, 0, 2000);
      EXPECT_EQ(again.low, ci.low);
      EXPECT_EQ(again.high, ci.high);
    }
  }
  std::cout << "coverage of the 95% interval: " << covered / 6.0 << "%\n";
  EXPECT_GE(covered, 540) << "coverage " << covered / 600.0;  // 90%
  EXPECT_LE(covered, 588) << "coverage " << covered / 600.0;  // 98%
}

// What `dyad study run` has the recorder write: `study` may name another study than `s`.
std::map<std::string, std::string> RunOf(const Study& s, const std::string& study, const std::string& participant, const Trial& t,
                                         const std::string& rehearsal = "false") {
  const Condition& c = s.conditions[static_cast<size_t>(t.condition)];
  return {{"study", study},
          {"participant", participant},
          {"condition", s.blind ? c.label : c.name},
          {"trial", std::to_string(t.number)},
          {"attempt", "1"},
          {"rehearsal", rehearsal}};
}

// A recording of one trial as `dyad analyze` reads it: a synthetic human's event at steps 10..19
// (primitive 2), 30 steps; the observer names the human's primitive throughout, the robot's from
// step 10 + `switch_after`; congruence `c` at every step; the human's self-report `said`.
// `run`: its "dyad.run" metadata, as `dyad study run` has the recorder write it. `steps`: how
// long it is; `chunk`: the writer's chunk size (small: a cut loses only the last chunks).
// `dataset`: the graph's data set (its names.txt names the primitives); `engaged` false: nobody
// held (no subject's page connected), human/input disengaged throughout.
void WriteTrial(const fs::path& file, double c, int switch_after, int said, const std::map<std::string, std::string>& run,
                int steps = 30, uint64_t chunk = 256 * 1024, const std::string& dataset = "", bool engaged = true) {
  fs::create_directories(file.parent_path());
  mcap::WriterOptions options;
  options.chunk_size = chunk;
  auto w = mcap::Writer::Open(file.string(), options);
  ASSERT_TRUE(w.ok());
  if (!run.empty()) {
    ASSERT_TRUE(w->AddMetadata("dyad.run", run).ok());
  }
  ASSERT_TRUE(w->AddMetadata("dyad.graph", {{"yaml", "graph: t\nclock: stepped\ncomponents:\n  human:\n    type: human_synthetic\n"
                                                     "    rate_hz: 10\n    params:\n      events: [{start: 10, end: 20, primitive: 2}]\n" +
                                                         (dataset.empty() ? std::string() : "      dataset: " + dataset + "\n")}})
                  .ok());
  testing::McapChannel<msg::HumanInput> human(*w, "human/input");
  testing::McapChannel<msg::IntentionLabel> labels(*w, "observer/labels");
  testing::McapChannel<msg::SelfReport> reports(*w, "human/self_report");
  for (int t = 0; t < steps; ++t) {
    msg::HumanInput h;
    h.engaged(engaged && t >= 10 && t < 20);
    human.Write(h, t);
    msg::IntentionLabel l;
    std::vector<double> p(7, 0.01), q(7, 0.01);
    p[2] = 0.9;
    q[t >= 10 + switch_after ? 2 : 0] = 0.9;
    l.human(p);
    l.robot(q);
    l.congruence(c);
    labels.Write(l, t);
    if (t == 22) {
      msg::SelfReport r;
      r.header().source("human");
      r.choice(said);
      r.segment_start_ns(1'000'000'000 + 10 * 100'000'000LL);
      r.segment_end_ns(1'000'000'000 + 20 * 100'000'000LL);
      reports.Write(r, t);
    }
  }
  ASSERT_TRUE(w->Close().ok());
}

// Two participants x two conditions x two trials; P02's two trials of `low` were never recorded.
// Per condition the numbers are computed by hand from what each trial holds: a participant's
// trials are averaged first, then the participants (the interval resamples participants).
TEST_F(StudyFile, AnalyzeMakesOneTableAcrossEveryoneAndSaysWhatIsMissing) {
  const std::string f = Write("study: gain\ngraph: g.yaml\nparticipants: [P01, P02]\n"
                              "conditions:\n  low: {src.start: 1}\n  high: {src.start: 3}\ntrials: 2\n");
  std::vector<Diagnostic> problems;
  const Study s = LoadStudy(f, {}, &problems);
  ASSERT_TRUE(problems.empty()) << problems.front().ToString();
  std::map<std::string, Trial> trial_of;  // "P01/low/1" -> its trial
  for (const std::string p : {"P01", "P02"})
    for (const Trial& t : s.TrialsOf(p))
      trial_of[p + "/" + s.conditions[static_cast<size_t>(t.condition)].name + "/" + std::to_string(t.repetition)] = t;
  WriteTrial(trial_of.at("P01/low/1").file, 0.2, 4, 4, RunOf(s, "gain", "P01", trial_of.at("P01/low/1")));  // said 4, drew 2
  WriteTrial(trial_of.at("P01/low/2").file, 0.4, 4, 2, RunOf(s, "gain", "P01", trial_of.at("P01/low/2")));
  WriteTrial(trial_of.at("P01/high/1").file, 0.6, 2, 2, RunOf(s, "gain", "P01", trial_of.at("P01/high/1")));
  WriteTrial(trial_of.at("P01/high/2").file, 0.6, 2, 2, RunOf(s, "gain", "P01", trial_of.at("P01/high/2")));
  WriteTrial(trial_of.at("P02/high/1").file, 0.8, 6, 2, RunOf(s, "gain", "P02", trial_of.at("P02/high/1")));
  WriteTrial(trial_of.at("P02/high/2").file, 1.0, 8, 2, RunOf(s, "gain", "P02", trial_of.at("P02/high/2")));
  const Trial& broken = trial_of.at("P02/low/1");  // a file that is no recording: listed with the reason
  fs::create_directories(fs::path(broken.file).parent_path());
  std::ofstream(broken.file) << "not an MCAP file";

  auto r = dyad::testing::RunCommand(dyad::cli::AddStudyCommands, {"study", "analyze", f});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("6 trials analysed, 2 missing"), std::string::npos) << r.out;
  const Trial& never = trial_of.at("P02/low/2");
  EXPECT_NE(r.out.find("P02 trial " + std::to_string(never.number) + " (" + never.file + "): not recorded"), std::string::npos) << r.out;
  const std::string broken_line = "P02 trial " + std::to_string(broken.number) + " (" + broken.file + "): ";
  ASSERT_NE(r.out.find(broken_line), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find(broken_line + "not recorded"), std::string::npos) << "the reason, not 'not recorded':\n" << r.out;
  const fs::path out = fs::path(s.data) / "analysis";
  std::map<std::string, std::map<std::string, std::string>> summary;  // "low/measure" -> row
  for (const auto& row : dyad::testing::ReadCsv(out / "summary.csv")) summary[row.at("condition") + "/" + row.at("measure")] = row;
  ASSERT_EQ(summary.size(), 12u);
  auto num = [&](const std::string& key, const std::string& col) { return std::stod(summary.at(key).at(col)); };
  EXPECT_EQ(summary.at("low/mean_congruence").at("participants"), "1");
  EXPECT_EQ(summary.at("low/mean_congruence").at("trials"), "2");
  EXPECT_NEAR(num("low/mean_congruence", "mean"), 0.3, 1e-9);
  EXPECT_NEAR(num("low/mean_congruence", "ci_low"), 0.3, 1e-9);
  EXPECT_NEAR(num("low/mean_congruence", "ci_high"), 0.3, 1e-9);
  // high: P01 0.6 and P02 0.9, so the interval spans 0.6..0.9 (resampling the four trials would
  // reach 1.0).
  EXPECT_EQ(summary.at("high/mean_congruence").at("participants"), "2");
  EXPECT_EQ(summary.at("high/mean_congruence").at("trials"), "4");
  EXPECT_NEAR(num("high/mean_congruence", "mean"), 0.75, 1e-9);
  EXPECT_NEAR(num("high/mean_congruence", "ci_low"), 0.6, 1e-9);
  EXPECT_NEAR(num("high/mean_congruence", "ci_high"), 0.9, 1e-9);
  // The robot follows from step 10 + k of the 10-step event: (10 - k) / 10; switch latency k * 0.1 s.
  EXPECT_NEAR(num("low/robot_follows", "mean"), 0.6, 1e-9);
  EXPECT_NEAR(num("high/robot_follows", "mean"), (0.8 + (0.4 + 0.2) / 2) / 2, 1e-9);
  EXPECT_NEAR(num("high/switch_latency_s", "mean"), (0.2 + (0.6 + 0.8) / 2) / 2, 1e-9);
  EXPECT_NEAR(num("low/observer_accuracy", "mean"), 1.0, 1e-9);
  const auto trials = dyad::testing::ReadCsv(out / "trials.csv");
  ASSERT_EQ(trials.size(), 6u);
  EXPECT_EQ(trials[0].count("nelbo_mean"), 1u);
  const auto events = dyad::testing::ReadCsv(out / "events.csv");
  ASSERT_EQ(events.size(), 6u);
  int said_four = 0;
  for (const auto& e : events) said_four += e.at("self_report") == "4" && e.at("participant") == "P01" && e.at("condition") == "low";
  EXPECT_EQ(said_four, 1);
  // Against the self-reports, in events (steps beside): one event said to be 4 (the observer: 2
  // on its 10 steps), five said 2. No names.txt: "primitive K".
  std::map<std::string, std::string> confusion;
  for (const auto& row : dyad::testing::ReadCsv(out / "reported_confusion.csv"))
    confusion[row.at("reported") + "," + row.at("observer")] = row.at("events") + "/" + row.at("steps");
  EXPECT_EQ(confusion, (std::map<std::string, std::string>{{"primitive 4,primitive 2", "1/10"}, {"primitive 2,primitive 2", "5/50"}}));
  // The synthetic humans traced 2 every time; one of the six said 4.
  std::map<std::string, std::string> vs_plan;
  for (const auto& row : dyad::testing::ReadCsv(out / "reports_vs_plan.csv")) vs_plan[row.at("planned") + "," + row.at("reported")] = row.at("events");
  EXPECT_EQ(vs_plan, (std::map<std::string, std::string>{{"primitive 2,primitive 2", "5"}, {"primitive 2,primitive 4", "1"}}));
  std::ifstream md(out / "report.md");
  const std::string report((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(report.find("| high (" + s.conditions[1].label + ") | mean_congruence | 2 | 4 | 0.75 | 0.6 to 0.9 |"), std::string::npos) << report;
  EXPECT_NE(report.find("## Missing trials"), std::string::npos) << report;
  EXPECT_NE(report.find("1 of 6 self-reports name another primitive than the one traced (16.6667%"), std::string::npos) << report;
  // Per condition, the observer against the self-reports: in low P01 said 4 once (the observer:
  // 2 throughout), so their trials' accuracies are 0 and 1; in high everyone said 2.
  const auto per_condition = report.find("## The observer against the self-reports, per condition");
  ASSERT_NE(per_condition, std::string::npos) << report;
  const auto low = report.find("### low (" + s.conditions[0].label + ")\n\nAccuracy 0.5 (95% interval 0.5 to 0.5; 1 participant, 2 trials).",
                               per_condition);
  EXPECT_NE(low, std::string::npos) << report;
  EXPECT_NE(report.find("| said / observer | primitive 2 |\n|---|---|\n| **primitive 2** | 1 (10) |\n| **primitive 4** | 1 (10) |", low),
            std::string::npos) << report;
  EXPECT_NE(report.find("### high (" + s.conditions[1].label + ")\n\nAccuracy 1 (95% interval 1 to 1; 2 participants, 4 trials).",
                        per_condition),
            std::string::npos) << report;
  EXPECT_EQ(summary.at("low/reported_accuracy").at("mean"), "0.5");
}

// What the analysis takes from a folder: the last complete attempt of a trial (the session log
// says which), never a recording of another study, another trial, or a rehearsal; every file it
// left out is said.
TEST_F(StudyFile, AnalyzeTakesTheLastCompleteAttemptAndRefusesOtherRecordings) {
  const std::string f = Write("study: gain\ngraph: g.yaml\nparticipants: [P01, P02]\n"
                              "conditions:\n  low: {src.start: 1}\n  high: {src.start: 3}\n");
  std::vector<Diagnostic> problems;
  const Study s = LoadStudy(f, {}, &problems);
  ASSERT_TRUE(problems.empty()) << problems.front().ToString();
  const auto p1 = s.TrialsOf("P01"), p2 = s.TrialsOf("P02");
  // P01 trial 1: attempt 1 stopped early, attempt 2 complete (the one analysed: congruence 0.5).
  ASSERT_TRUE(AppendSessionEvent(s, "P01", R"({"event":"consent","how":"test"})").ok());
  ASSERT_TRUE(AppendSessionEvent(s, "P01", R"({"event":"start","trial":1,"attempt":1,"file":")" + p1[0].file + R"("})").ok());
  ASSERT_TRUE(AppendSessionEvent(s, "P01", R"({"event":"end","trial":1,"attempt":1,"outcome":"stopped","seconds":40})").ok());
  const std::string second = AttemptFile(p1[0], 2);
  EXPECT_EQ(fs::path(second).filename().string(), fs::path(p1[0].file).stem().string() + ".try2.mcap");
  ASSERT_TRUE(AppendSessionEvent(s, "P01", R"({"event":"start","trial":1,"attempt":2,"file":")" + second +
                                               R"(","reason":"fire alarm"})").ok());
  ASSERT_TRUE(AppendSessionEvent(s, "P01", R"({"event":"end","trial":1,"attempt":2,"outcome":"complete","seconds":120})").ok());
  WriteTrial(p1[0].file, 0.1, 2, 2, RunOf(s, "gain", "P01", p1[0]));
  auto second_run = RunOf(s, "gain", "P01", p1[0]);
  second_run["attempt"] = "2";
  WriteTrial(second, 0.5, 2, 2, second_run);
  // P01 trial 2: started, and the session ended during it (no end in the log).
  ASSERT_TRUE(AppendSessionEvent(s, "P01", R"({"event":"start","trial":2,"attempt":1,"file":")" + p1[1].file + R"("})").ok());
  WriteTrial(p1[1].file, 0.9, 2, 2, RunOf(s, "gain", "P01", p1[1]));
  // P02: a recording of another study, and one of the rehearsal, at its planned paths.
  WriteTrial(p2[0].file, 0.9, 2, 2, RunOf(s, "other", "P02", p2[0]));
  WriteTrial(p2[1].file, 0.9, 2, 2, RunOf(s, "gain", "P02", p2[1], "true"));
  WriteTrial(fs::path(s.data) / "P02" / "copy.mcap", 0.9, 2, 2, RunOf(s, "gain", "P02", p2[1]));
  std::ofstream(fs::path(s.data) / "P01" / "session.log", std::ios::app) << "not json\n";

  std::ostringstream warnings;
  const StudyAnalysis a = AnalyzeStudy(s, warnings);
  ASSERT_EQ(a.trials.size(), 1u);
  EXPECT_EQ(a.trials[0].attempt, 2);
  EXPECT_EQ(a.trials[0].trial.file, second);
  EXPECT_EQ(a.trials[0].repeated, "attempt 1 stopped; attempt 2 analysed, repeated because: fire alarm");
  for (const auto& [name, value] : a.trials[0].metrics)
    if (name == "mean_congruence") {
      EXPECT_NEAR(value, 0.5, 1e-9) << "not the analysed attempt's";
    }
  ASSERT_EQ(a.missing.size(), 3u);
  EXPECT_EQ(a.missing[0], "P01 trial 2 (" + p1[1].file + "): incomplete (attempt 1 interrupted (the session ended during it))");
  EXPECT_EQ(a.missing[1], "P02 trial 1 (" + p2[0].file + "): a recording of study other, not gain");
  EXPECT_EQ(a.missing[2], "P02 trial 2 (" + p2[1].file + "): a rehearsal's recording (synthetic participant)");
  EXPECT_EQ(a.unplanned, (std::vector<std::string>{(fs::path(s.data) / "P02" / "copy.mcap").string()}));
  EXPECT_NE(warnings.str().find("session.log:7: not a session event"), std::string::npos) << warnings.str();
  // A file without the study's metadata is not taken for a trial either.
  WriteTrial(p2[0].file.substr(0, p2[0].file.size() - 5) + ".try9.mcap", 0.9, 2, 2, {});
  EXPECT_EQ(NotThisTrial(p2[0].file.substr(0, p2[0].file.size() - 5) + ".try9.mcap", s, "P02", p2[0], false),
            "no study metadata (\"dyad.run\"): not recorded by dyad study run");
  ASSERT_TRUE(WriteStudyAnalysis(s, a, (dir_ / "out").string()).ok());
  std::ifstream md(dir_ / "out" / "report.md");
  const std::string report((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(report.find("## Repeated trials\n\n- P01 trial 1: attempt 1 stopped; attempt 2 analysed, repeated because: fire alarm"),
            std::string::npos) << report;
  EXPECT_NE(report.find("## Files not in the plan (not analysed)"), std::string::npos) << report;
  EXPECT_EQ(dyad::testing::ReadCsv(dir_ / "out" / "trials.csv").at(0).at("attempt"), "2");
}

// Each summary.csv row recomputed from trials.csv as the contract says (per participant the mean
// of their counted trials in the file's order, then the mean of those in ID order): the same
// double, bit for bit (the numbers are printed exactly).
void ExpectSummaryRecomputedExactly(const fs::path& dir, bool include_incomplete) {
  const auto trials = dyad::testing::ReadCsv(dir / "trials.csv");
  const auto summary = dyad::testing::ReadCsv(dir / "summary.csv");
  ASSERT_FALSE(summary.empty());
  for (const auto& row : summary) {
    std::map<std::string, std::pair<double, int>> by;  // participant -> sum, count
    int n = 0;
    for (const auto& t : trials) {
      if (t.at("condition") != row.at("condition") || (t.at("complete") != "true" && !include_incomplete)) continue;
      const std::string& cell = t.at(row.at("measure"));
      if (cell.empty()) continue;
      by[t.at("participant")].first += std::strtod(cell.c_str(), nullptr);
      ++by[t.at("participant")].second;
      ++n;
    }
    const std::string what = row.at("condition") + " " + row.at("measure");
    EXPECT_EQ(row.at("participants"), std::to_string(by.size())) << what;
    EXPECT_EQ(row.at("trials"), std::to_string(n)) << what;
    if (by.empty()) {
      EXPECT_EQ(row.at("mean"), "") << what;
      continue;
    }
    double sum = 0;
    for (const auto& [p, s] : by) sum += s.first / s.second;
    const double mean = sum / static_cast<double>(by.size());
    const double said = std::strtod(row.at("mean").c_str(), nullptr);
    EXPECT_EQ(std::memcmp(&mean, &said, sizeof mean), 0) << what << ": recomputed " << mean << ", summary.csv " << row.at("mean");
  }
}

// Three participants; P01's trial of low cut in its middle (a crash, a full disk), P03's
// shorter than the study's duration. Both are marked in trials.csv, left out of the summary and
// the confusion, and listed in the report with their reasons; --include-incomplete counts them.
// Every summary is the exact mean of trials.csv's rows.
TEST_F(StudyFile, AnIncompleteTrialIsMarkedLeftOutOfTheSummaryAndReported) {
  const std::string f = Write("study: gain\ngraph: g.yaml\nparticipants: [P01, P02, P03]\n"
                              "conditions:\n  low: {src.start: 1}\n  high: {src.start: 3}\nduration: 3\n");
  std::vector<Diagnostic> problems;
  const Study s = LoadStudy(f, {}, &problems);
  ASSERT_TRUE(problems.empty()) << problems.front().ToString();
  const std::map<std::string, double> congruence = {{"P01/low", 0.1234567891}, {"P02/low", 0.7654321987}, {"P03/low", 1.0 / 3},
                                                    {"P01/high", 0.55555555555}, {"P02/high", 0.61803398875}, {"P03/high", 0.2718281828}};
  std::map<std::string, Trial> low;
  for (const std::string p : {"P01", "P02", "P03"})
    for (const Trial& t : s.TrialsOf(p)) {
      const std::string c = s.conditions[static_cast<size_t>(t.condition)].name;
      if (c == "low") low[p] = t;
      WriteTrial(t.file, congruence.at(p + "/" + c), 3, 2, RunOf(s, "gain", p, t), p == "P03" && c == "low" ? 20 : 30, 1024);
    }
  {  // cut inside its middle chunk, as a crash or a full disk leaves a file
    auto whole = mcap::Reader::Open(low.at("P01").file);
    ASSERT_TRUE(whole.ok()) << whole.status().ToString();
    ASSERT_GE(whole->chunks().size(), 4u);
    const mcap::ChunkInfo& middle = whole->chunks()[whole->chunks().size() / 2];
    fs::resize_file(low.at("P01").file, middle.offset + middle.length / 2);
  }

  auto r = dyad::testing::RunCommand(dyad::cli::AddStudyCommands, {"study", "analyze", f, "--no-plots"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("6 trials analysed, 0 missing; 2 incomplete, left out of the summary"), std::string::npos) << r.out;
  const std::string cut =
      "P01 trial " + std::to_string(low.at("P01").number) + " (" + low.at("P01").file + "): cut short: file ends at byte";
  const std::string short_one = "P03 trial " + std::to_string(low.at("P03").number) + " (" + low.at("P03").file +
                                "): shorter than planned: 20 steps of 100 ms (2 s) of the 3 s planned";
  EXPECT_NE(r.out.find("  incomplete: " + cut), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  incomplete: " + short_one), std::string::npos) << r.out;
  const fs::path out = fs::path(s.data) / "analysis";
  std::map<std::string, std::map<std::string, std::string>> trials;  // "P01/low" -> row
  for (const auto& row : dyad::testing::ReadCsv(out / "trials.csv")) trials[row.at("participant") + "/" + row.at("condition")] = row;
  EXPECT_EQ(trials.at("P01/low").at("complete"), "false");
  EXPECT_EQ(trials.at("P01/low").at("reason").rfind("cut short: file ends at byte", 0), 0u) << trials.at("P01/low").at("reason");
  EXPECT_EQ(trials.at("P03/low").at("complete"), "false");
  EXPECT_EQ(trials.at("P02/low").at("complete"), "true");
  EXPECT_EQ(trials.at("P02/low").at("reason"), "");
  std::map<std::string, std::map<std::string, std::string>> summary;
  for (const auto& row : dyad::testing::ReadCsv(out / "summary.csv")) summary[row.at("condition") + "/" + row.at("measure")] = row;
  EXPECT_EQ(summary.at("low/mean_congruence").at("participants"), "1");
  EXPECT_EQ(summary.at("high/mean_congruence").at("participants"), "3");
  ExpectSummaryRecomputedExactly(out, false);
  // The confusion against the self-reports: four whole trials, an event of 10 labelled steps each, said 2.
  const auto confusion = dyad::testing::ReadCsv(out / "reported_confusion.csv");
  ASSERT_EQ(confusion.size(), 1u);
  EXPECT_EQ(confusion[0].at("reported") + "," + confusion[0].at("observer"), "primitive 2,primitive 2");
  EXPECT_EQ(confusion[0].at("events"), "4");
  EXPECT_EQ(confusion[0].at("steps"), "40");
  std::ifstream md(out / "report.md");
  const std::string report((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(report.find("6 trials analysed (2 incomplete, left out of the summary; below)"), std::string::npos) << report;
  const auto section = report.find("## Incomplete trials\n\nLeft out of the summary");
  ASSERT_NE(section, std::string::npos) << report;
  EXPECT_NE(report.find("- " + cut, section), std::string::npos) << report;
  EXPECT_NE(report.find("- " + short_one, section), std::string::npos) << report;

  const std::string all = (dir_ / "all").string();
  r = dyad::testing::RunCommand(dyad::cli::AddStudyCommands, {"study", "analyze", f, "--no-plots", "--include-incomplete", "-o", all});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("2 incomplete, counted (--include-incomplete)"), std::string::npos) << r.out;
  for (const auto& row : dyad::testing::ReadCsv(fs::path(all) / "summary.csv")) {
    if (row.at("measure") == "mean_congruence") {
      EXPECT_EQ(row.at("participants"), "3") << row.at("condition");
    }
  }
  ExpectSummaryRecomputedExactly(all, true);
}

// Empty trials are not data: P02 never took part (no subject's page: human/input disengaged
// throughout, though the recordings are whole and long enough). Both their trials are incomplete
// with the reason, and the summary is P01's alone.
TEST_F(StudyFile, TrialsWithNobodyEngagedAreIncompleteAndLeftOutOfTheSummary) {
  const std::string f = Write("study: gain\ngraph: g.yaml\nparticipants: [P01, P02]\n"
                              "conditions:\n  low: {src.start: 1}\n  high: {src.start: 3}\nduration: 3\n");
  std::vector<Diagnostic> problems;
  const Study s = LoadStudy(f, {}, &problems);
  ASSERT_TRUE(problems.empty()) << problems.front().ToString();
  for (const std::string p : {"P01", "P02"})
    for (const Trial& t : s.TrialsOf(p)) WriteTrial(t.file, p == "P01" ? 0.25 : 0.75, 3, 2, RunOf(s, "gain", p, t), 30, 1024, "", p == "P01");

  auto r = dyad::testing::RunCommand(dyad::cli::AddStudyCommands, {"study", "analyze", f, "--no-plots"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("4 trials analysed, 0 missing; 2 incomplete, left out of the summary"), std::string::npos) << r.out;
  const fs::path out = fs::path(s.data) / "analysis";
  int empty = 0;
  for (const auto& row : dyad::testing::ReadCsv(out / "trials.csv")) {
    const bool nobody = row.at("participant") == "P02";
    EXPECT_EQ(row.at("complete"), nobody ? "false" : "true") << row.at("participant");
    if (nobody) {
      EXPECT_EQ(row.at("reason"), "no subject: not one engaged step (no subject's page connected, or nobody held)");
      ++empty;
    }
  }
  EXPECT_EQ(empty, 2);
  for (const auto& row : dyad::testing::ReadCsv(out / "summary.csv"))
    if (row.at("measure") == "mean_congruence") {
      EXPECT_EQ(row.at("participants"), "1") << row.at("condition");
      EXPECT_EQ(row.at("mean"), "0.25") << row.at("condition");
    }
  ExpectSummaryRecomputedExactly(out, false);
}

// Readable answers: reported_confusion.csv and report.md name the primitives (the graph's data
// set's names.txt), "something else" is an answer of its own, and the counts are events with
// their labelled steps beside.
TEST_F(StudyFile, TheSelfReportsAreCountedInEventsByNameWithSomethingElseOfItsOwn) {
  const std::string f = Write("study: gain\ngraph: g.yaml\nparticipants: [P01]\n"
                              "conditions:\n  low: {src.start: 1}\n  high: {src.start: 3}\ntrials: 2\n");
  std::vector<Diagnostic> problems;
  const Study s = LoadStudy(f, {}, &problems);
  ASSERT_TRUE(problems.empty()) << problems.front().ToString();
  const std::string data = (dir_ / "named_set").string();
  ASSERT_TRUE(pvrnn::WriteNrlDataset(pvrnn::MakeAnalyticDataset(), data).ok());
  int k = 0;  // said: triangle (2), star (4), "something else" (-1), triangle
  for (const Trial& t : s.TrialsOf("P01")) WriteTrial(t.file, 0.5, 3, std::vector<int>{2, 4, -1, 2}[static_cast<size_t>(k++)], RunOf(s, "gain", "P01", t), 30, 256 * 1024, data);
  auto r = dyad::testing::RunCommand(dyad::cli::AddStudyCommands, {"study", "analyze", f, "--no-plots"});
  ASSERT_EQ(r.code, 0) << r.err;
  const fs::path out = fs::path(s.data) / "analysis";
  std::map<std::string, std::string> confusion;
  for (const auto& row : dyad::testing::ReadCsv(out / "reported_confusion.csv"))
    confusion[row.at("reported") + "," + row.at("observer")] = row.at("events") + "/" + row.at("steps");
  EXPECT_EQ(confusion, (std::map<std::string, std::string>{
                           {"triangle,triangle", "2/20"}, {"star,triangle", "1/10"}, {"something else,triangle", "1/10"}}));
  std::ifstream md(out / "report.md");
  const std::string report((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(report.find("| said / observer | triangle |\n|---|---|\n"), std::string::npos) << report;
  EXPECT_NE(report.find("| **something else** | 1 (10) |"), std::string::npos) << report;
  // The rehearsal's table of reports against the plan names them too.
  std::map<std::string, std::string> vs_plan;
  for (const auto& row : dyad::testing::ReadCsv(out / "reports_vs_plan.csv")) vs_plan[row.at("planned") + "," + row.at("reported")] = row.at("events");
  EXPECT_EQ(vs_plan, (std::map<std::string, std::string>{{"triangle,triangle", "2"}, {"triangle,star", "1"}, {"triangle,something else", "1"}}));
  EXPECT_NE(report.find("| triangle | something else | 1 |"), std::string::npos) << report;
}

// The session log's note line names the trial under way (none between trials), and the log
// reads it back so.
TEST_F(StudyFile, ANoteLineNamesTheTrialUnderWay) {
  const std::string f = Write("study: gain\ngraph: g.yaml\nparticipants: [P01]\nconditions:\n  low: {src.start: 1}\n");
  std::vector<Diagnostic> problems;
  const Study s = LoadStudy(f, {}, &problems);
  ASSERT_TRUE(problems.empty()) << problems.front().ToString();
  ASSERT_TRUE(AddNote(s, "P01", "before").ok());
  ASSERT_TRUE(AppendSessionEvent(s, "P01", R"({"event":"start","trial":1,"attempt":1,"file":"x.mcap"})").ok());
  ASSERT_TRUE(AddNote(s, "P01", "during").ok());
  ASSERT_TRUE(AppendSessionEvent(s, "P01", R"({"event":"end","trial":1,"attempt":1,"outcome":"complete","seconds":1,"exit":0})").ok());
  ASSERT_TRUE(AddNote(s, "P01", "after").ok());
  std::ifstream in(SessionLogPath(s, "P01"));
  std::vector<std::string> notes;
  for (std::string line; std::getline(in, line);)
    if (line.find("\"note\"") != std::string::npos) notes.push_back(line);
  ASSERT_EQ(notes.size(), 3u);
  EXPECT_EQ(notes[0].find("\"trial\""), std::string::npos) << notes[0];
  EXPECT_NE(notes[1].find("\"trial\":1"), std::string::npos) << notes[1];
  EXPECT_EQ(notes[2].find("\"trial\""), std::string::npos) << notes[2];
  const Session read = ReadSession(s, "P01");
  ASSERT_EQ(read.notes.size(), 3u);
  EXPECT_EQ(read.notes[1].trial, 1);
  EXPECT_EQ(read.notes[2].trial, 0);
}

// AB12 and ab12 would share a folder on a case-insensitive file system: refused at the line. A
// bad override is said once, not again by the rehearsal's check (its own overrides on the study's
// graph).
TEST_F(StudyFile, IdsDifferingOnlyInCaseAreRefusedAndABadOverrideIsSaidOnce) {
  const std::string f = Write("study: gain\ngraph: g.yaml\nparticipants: [AB12, ab12]\nconditions:\n  low: {src.nope: 1}\n"
                              "rehearsal: {set: {sink.rate_hz: 5}}\n");  // on the study's own graph
  std::vector<Diagnostic> problems;
  LoadStudy(f, {}, &problems);
  std::string all;
  int nope = 0;
  for (const auto& p : problems) {
    all += p.ToString() + "\n";
    nope += p.ToString().find("src.nope") != std::string::npos;
  }
  EXPECT_NE(all.find("s.yaml:3:22: participants[1]: participant ab12 is AB12 (line 3) in another case"), std::string::npos) << all;
  EXPECT_EQ(nope, 1) << all;
}

// Labels are drawn from the study's name; a blind listing in the file's order would tell whoever
// knows the file which label is which condition. Plan, summary and report list them by label.
TEST_F(StudyFile, BlindListingsAreSortedByLabelNotInTheFilesOrder) {
  std::string f;
  Study s;
  for (int k = 0; k < 50; ++k) {  // a name whose labels are not in the file's order
    f = Write("study: s" + std::to_string(k) + "\ngraph: g.yaml\nparticipants: [P01]\nconditions:\n  low: {src.start: 1}\n"
              "  mid: {src.start: 2}\n  high: {src.start: 3}\nblind: true\n");
    std::vector<Diagnostic> problems;
    s = LoadStudy(f, {}, &problems);
    ASSERT_TRUE(problems.empty()) << problems.front().ToString();
    if (s.conditions[0].label != "A" || s.conditions[1].label != "B") break;
  }
  ASSERT_FALSE(s.conditions[0].label == "A" && s.conditions[1].label == "B");
  auto in_order = [](const std::string& text, const std::vector<std::string>& parts) {
    size_t at = 0;
    for (const std::string& p : parts) {
      at = text.find(p, at);
      if (at == std::string::npos) return false;
    }
    return true;
  };
  auto plan = dyad::testing::RunCommand(dyad::cli::AddStudyCommands, {"study", "plan", f});
  ASSERT_EQ(plan.code, 0) << plan.err;
  EXPECT_TRUE(in_order(plan.out, {"  condition A\n", "  condition B\n", "  condition C\n"})) << plan.out;
  auto unblind = dyad::testing::RunCommand(dyad::cli::AddStudyCommands, {"study", "plan", f, "--unblind"});
  EXPECT_TRUE(in_order(unblind.out, {"(condition A):", "(condition B):", "(condition C):"})) << unblind.out;
  StudyAnalysis nothing;
  nothing.unblinded = false;  // a blind rehearsal's
  ASSERT_TRUE(WriteStudyAnalysis(s, nothing, (dir_ / "out").string()).ok());
  std::vector<std::string> labels;
  for (const auto& row : dyad::testing::ReadCsv(dir_ / "out" / "summary.csv"))
    if (labels.empty() || labels.back() != row.at("label")) labels.push_back(row.at("label"));
  EXPECT_EQ(labels, (std::vector<std::string>{"A", "B", "C"}));
  std::ifstream md(dir_ / "out" / "report.md");
  const std::string report((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_TRUE(in_order(report, {"| condition A |", "| condition B |", "| condition C |"})) << report;
}

// The closed sets of a study, one table each: every value has its word, the word reads back to
// it, and a word outside says which are allowed (the words the study file's error lists).
TEST(ClosedSets, EveryValueReadsBackFromItsWordAndOthersAreRefusedWithTheList) {
  for (const AttemptOutcome o :
       {AttemptOutcome::kComplete, AttemptOutcome::kStopped, AttemptOutcome::kFailed, AttemptOutcome::kIncomplete}) {
    auto back = ParseAttemptOutcome(ToString(o));
    ASSERT_TRUE(back.ok()) << ToString(o);
    EXPECT_EQ(*back, o) << ToString(o);
  }
  EXPECT_EQ(ToString(AttemptOutcome::kUnended), "");  // never written: a start without its end
  EXPECT_FALSE(ParseAttemptOutcome("").ok());
  EXPECT_EQ(ParseAttemptOutcome("done").status().message(), "outcome \"done\": must be complete, stopped, failed or incomplete");
  for (const SelfReports w : {SelfReports::kAfterEvent, SelfReports::kAfterTrial, SelfReports::kOff}) {
    auto back = ParseSelfReports(ToString(w));
    ASSERT_TRUE(back.ok()) << ToString(w);
    EXPECT_EQ(*back, w) << ToString(w);
  }
  EXPECT_EQ(ParseSelfReports("sometimes").status().message(), "must be after_event, after_trial or off");
}

// A session log whose end line has a word that is no outcome: said (file:line), and the attempt
// is not complete (it is run again), where it used to be taken as it was, silently.
TEST_F(StudyFile, AnOutcomeThatIsNoOutcomeIsAProblemOfTheLog) {
  const std::string f = Write("study: gain\ngraph: g.yaml\nparticipants: [P01]\nconditions:\n  low: {src.start: 1}\n");
  std::vector<Diagnostic> problems;
  const Study s = LoadStudy(f, {}, &problems);
  ASSERT_TRUE(problems.empty()) << problems.front().ToString();
  ASSERT_TRUE(AppendSessionEvent(s, "P01", R"({"event":"start","trial":1,"attempt":1,"file":"x.mcap"})").ok());
  ASSERT_TRUE(AppendSessionEvent(s, "P01", R"({"event":"end","trial":1,"attempt":1,"outcome":"Complete","seconds":1})").ok());
  const Session read = ReadSession(s, "P01");
  ASSERT_EQ(read.problems.size(), 1u);
  EXPECT_NE(read.problems[0].find("session.log:2: outcome \"Complete\": must be complete, stopped, failed or incomplete"),
            std::string::npos)
      << read.problems[0];
  ASSERT_EQ(read.attempts.size(), 1u);
  EXPECT_EQ(read.attempts[0].outcome, AttemptOutcome::kFailed);
  EXPECT_EQ(read.Complete(1), nullptr);
}

// One failure, one exit code (tools/support/exit_code.hpp): a trial that cannot start for want of
// a session log it can write (here a folder where the log should be) is a failure (1), whether
// the trial comes in its order or is repeated with --trial; the --trial path said bad input (2).
// A trial the plan's order refuses is bad input (2) either way.
TEST_F(StudyFile, ATrialThatCannotStartExitsOneInOrderAndWithTrial) {
  const std::string f = Write(
      "study: gain\ngraph: g.yaml\nparticipants: [P01]\nconditions:\n  low: {src.start: 1}\n"
      "  high: {src.start: 3}\nconsent_required: false\n");
  std::vector<Diagnostic> problems;
  const Study s = LoadStudy(f, {}, &problems);
  ASSERT_TRUE(problems.empty()) << problems.front().ToString();
  fs::create_directories(SessionLogPath(s, "P01"));  // no file can be appended to there
  auto in_order = dyad::testing::RunCommand(dyad::cli::AddStudyCommands, {"study", "run", f, "--participant", "P01", "--yes"});
  EXPECT_EQ(in_order.code, 1) << in_order.err;
  EXPECT_NE(in_order.err.find("session.log"), std::string::npos) << in_order.err;
  auto repeated = dyad::testing::RunCommand(dyad::cli::AddStudyCommands,
                                            {"study", "run", f, "--participant", "P01", "--trial", "1", "--reason", "again"});
  EXPECT_EQ(repeated.code, 1) << repeated.err;
  EXPECT_NE(repeated.err.find("session.log"), std::string::npos) << repeated.err;
  fs::remove(SessionLogPath(s, "P01"));
  auto out_of_order = dyad::testing::RunCommand(dyad::cli::AddStudyCommands,
                                                {"study", "run", f, "--participant", "P01", "--trial", "2", "--reason", "first"});
  EXPECT_EQ(out_of_order.code, 2) << out_of_order.err;
  EXPECT_NE(out_of_order.err.find("trial 1 comes first"), std::string::npos) << out_of_order.err;
}

}  // namespace
}  // namespace dyad::study
