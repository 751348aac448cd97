// `dyad analyze`: step alignment, event scores and confusion against hand-computed values on a
// synthetic recording written with the real IDL schemas and CDR; live parameter changes on the
// same step grid; the CLI's report folder (PNG files checked by their magic bytes) and its errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <tuple>

#include <dyad/msg/types.hpp>

#include "analyze_commands.hpp"
#include "build_report.hpp"
#include "dyad/testing/cli.hpp"
#include "dyad/testing/mcap_channel.hpp"
#include "dyad/mcap/writer.hpp"
#include "demonstrations.hpp"
#include "dyad/pvrnn/analytic_dataset.hpp"
#include "dyad/pvrnn/dataset.hpp"
#include "experiment_analysis.hpp"
#include "recording_tables.hpp"
#include "report_writer.hpp"

namespace dyad::analyze {
namespace {

constexpr int64_t kPeriod = 100'000'000;

std::string TempPath(const std::string& name) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string path = ::testing::TempDir() + "dyad_analyze_" + info->name() + "_" + name;
  std::filesystem::remove_all(path);
  return path;
}

std::vector<std::string> Lines(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

const char* kGraph = R"(graph: unit
clock: stepped
components:
  human:
    type: human_synthetic
    rate_hz: 10
    params:
      dataset: /nonexistent/dataset
      events:
        - {start: 10, end: 20, primitive: 2}
        - {start: 30, end: 34, primitive: 5}
)";

// Stamped at 1 s + step * kPeriod (t0 != 0: alignment subtracts it).
template <class T>
using Channel = testing::McapChannel<T>;

std::vector<double> OneHot(int k, int n = 7) {
  std::vector<double> p(n, 0.02);
  p[k] = 0.9;
  return p;
}

// 40 steps. Human engaged during the graph's two events. Observer: the human's class is right
// except at steps 12 and 13 (says 3); the robot's class is 1 until step 15, then 2 until 25,
// then 1. Congruence = step / 100.
// `reports`: self-reports {first step, release step, choice} written 2 steps after the release.
// `practice`: {step, practice} samples of subject/task.
std::string WriteExperiment(const std::string& path, bool with_observer = true,
                            const std::map<std::string, std::string>& graph = {{"yaml", kGraph}},
                            const std::vector<std::array<int64_t, 3>>& reports = {},
                            const std::vector<std::pair<int64_t, bool>>& practice = {}) {
  auto writer = mcap::Writer::Open(path);
  EXPECT_TRUE(writer.ok());
  EXPECT_TRUE(writer->AddMetadata("dyad.graph", graph).ok());
  Channel<msg::HumanInput> human(*writer, "human/input");
  Channel<msg::Intention> robot(*writer, "robot/intention");
  Channel<msg::CartesianState> state(*writer, "robot/state");
  Channel<msg::IntentionLabel> labels(*writer, "observer/labels");
  std::optional<Channel<msg::SelfReport>> said;
  if (!reports.empty()) said.emplace(*writer, "human/self_report");
  std::optional<Channel<msg::SubjectTask>> task;
  if (!practice.empty()) task.emplace(*writer, "subject/task");
  for (int t = 0; t < 40; ++t) {
    for (const auto& [step, on] : practice) {
      if (step != t) continue;
      msg::SubjectTask k;
      k.header().source("web");
      k.target(-1);
      k.practice(on);
      task->Write(k, t);
    }
    for (const auto& [first, release, choice] : reports) {
      if (release + 2 != t) continue;
      msg::SelfReport r;
      r.header().source("human");
      r.choice(static_cast<int32_t>(choice));
      r.response_s(0.2);
      r.segment_start_ns(1'000'000'000 + first * kPeriod);
      r.segment_end_ns(1'000'000'000 + release * kPeriod);
      said->Write(r, t);
    }
    const bool engaged = (t >= 10 && t < 20) || (t >= 30 && t < 34);
    msg::HumanInput h; h.x(t); h.y(-t); h.engaged(engaged);
    human.Write(h, t);
    msg::Intention i; i.x(2 * t); i.y(1); i.nelbo(0.5 + t); i.reconstruction(0.25); i.regulation(0.25);
    i.optimisation_s(1e-4); i.iterations(15);
    robot.Write(i, t);
    msg::CartesianState s; s.x(3 * t); s.y(2);
    state.Write(s, t);
    if (with_observer) {
      msg::IntentionLabel l;
      const int truth = t < 25 ? 2 : 5;
      l.human(OneHot((t == 12 || t == 13) ? 3 : truth));
      l.robot(OneHot(t >= 15 && t < 25 ? 2 : 1));
      l.congruence(t / 100.0);
      labels.Write(l, t);
    }
  }
  EXPECT_TRUE(writer->Close().ok());
  return path;
}

Report Analyse(const std::string& path) {
  auto reader = mcap::Reader::Open(path);
  EXPECT_TRUE(reader.ok());
  Report r;
  r.recording = path;
  r.graph_yaml = GraphMetadata(*reader, "yaml");
  auto plan = PlanFromGraphYaml(r.graph_yaml);
  EXPECT_TRUE(plan.ok()) << plan.status().ToString();
  r.plan = *plan;
  auto tables = ReadTables(*reader, {});
  EXPECT_TRUE(tables.ok()) << tables.status().ToString();
  auto timeline = BuildTimeline(*tables, r.plan);
  EXPECT_TRUE(timeline.ok()) << timeline.status().ToString();
  r.timeline = *timeline;
  auto events = Events(r.timeline, r.plan);
  r.events = SummariseEvents(r.timeline, events);
  r.confusion = HumanConfusion(r.timeline, events);
  return r;
}

TEST(Analyze, PlanComesFromTheRecordedGraph) {
  auto plan = PlanFromGraphYaml(kGraph);
  ASSERT_TRUE(plan.ok());
  EXPECT_EQ(plan->graph_name, "unit");
  EXPECT_EQ(plan->period_ns, kPeriod);
  EXPECT_EQ(plan->dataset, "/nonexistent/dataset");
  ASSERT_EQ(plan->events.size(), 2u);
  EXPECT_EQ(plan->events[1].start_step, 30);
  EXPECT_EQ(plan->events[1].primitive, 5);
  EXPECT_FALSE(PlanFromGraphYaml("components: [unclosed").ok());
  auto empty = PlanFromGraphYaml("");
  ASSERT_TRUE(empty.ok());
  EXPECT_TRUE(empty->events.empty());
}

TEST(Analyze, TimelineAlignsEveryTopicOnTheStepGrid) {
  Report r = Analyse(WriteExperiment(TempPath("a.mcap")));
  ASSERT_EQ(r.timeline.steps.size(), 40u);
  EXPECT_TRUE(r.timeline.missing_topics.empty());
  EXPECT_EQ(r.timeline.classes, 7);
  const StepSample& s = r.timeline.steps[17];
  EXPECT_EQ(s.step, 17);
  EXPECT_DOUBLE_EQ(s.human_x, 17);
  EXPECT_TRUE(s.engaged);
  EXPECT_DOUBLE_EQ(s.robot_x, 34);
  EXPECT_DOUBLE_EQ(s.nelbo, 17.5);
  EXPECT_DOUBLE_EQ(s.executed_x, 51);
  EXPECT_DOUBLE_EQ(s.congruence, 0.17);
  EXPECT_FALSE(r.timeline.steps[20].engaged);
}

// A graph split over processes, the deliberator's clock 250 ms (2.5 steps) ahead of the
// recorder's: its stamps are moved back by what the recorder's process measured (the exchange
// with the least round trip), so its intentions land on their own steps again.
TEST(Analyze, StampsOfAnotherProcessAreCorrectedByTheMeasuredClockOffset) {
  const char* graph = R"(graph: split
clock: wall
components:
  human: {type: human_synthetic, rate_hz: 10, process: lab}
  mind: {type: deliberator, rate_hz: 10, process: mind}
  recorder: {type: recorder, rate_hz: 1, process: rec}
)";
  const std::string path = TempPath("split.mcap");
  {
    auto writer = mcap::Writer::Open(path);
    ASSERT_TRUE(writer.ok());
    ASSERT_TRUE(writer->AddMetadata("dyad.graph", {{"yaml", graph}}).ok());
    Channel<msg::HumanInput> human(*writer, "human/input");
    Channel<msg::Intention> robot(*writer, "robot/intention");
    Channel<msg::ClockOffset> offsets(*writer, "dyad/clock_offsets");
    for (int t = 0; t < 20; ++t) {
      msg::HumanInput h; h.header().source("human"); h.x(t);
      human.Write(h, t);
      msg::Intention i; i.header().source("mind"); i.x(2 * t);
      robot.Write(i, t, 250'000'000);
    }
    // rec's measurements of mind: a noisy one (long round trip) and the good one; and what
    // mind measured of rec (not the recorder's view: ignored).
    for (auto [measurer, offset, rtt] : {std::tuple{"rec", 262'000'000, 9'000'000}, std::tuple{"rec", 250'000'000, 200'000},
                                         std::tuple{"mind", -250'000'000, 100'000}}) {
      msg::ClockOffset o; o.process_name(measurer); o.peer_process(measurer == std::string("rec") ? "mind" : "rec");
      o.offset_ns(offset); o.round_trip_ns(rtt);
      offsets.Write(o, 0);
    }
    ASSERT_TRUE(writer->Close().ok());
  }
  auto reader = mcap::Reader::Open(path);
  ASSERT_TRUE(reader.ok());
  auto plan = PlanFromGraphYaml(GraphMetadata(*reader, "yaml"));
  ASSERT_TRUE(plan.ok());
  EXPECT_EQ(plan->recorder_process, "rec");
  EXPECT_EQ(plan->process_of.at("mind"), "mind");
  auto tables = ReadTables(*reader, {});
  ASSERT_TRUE(tables.ok());
  auto corrections = ClockCorrections(*tables, *plan);
  ASSERT_TRUE(corrections.ok()) << corrections.status().ToString();
  ASSERT_EQ(corrections->size(), 1u);
  EXPECT_EQ(corrections->at("mind"), 250'000'000);
  auto uncorrected = BuildTimeline(*tables, *plan);
  auto timeline = BuildTimeline(*tables, *plan, *corrections);
  ASSERT_TRUE(uncorrected.ok() && timeline.ok());
  EXPECT_TRUE(std::isnan(uncorrected->steps[5].robot_x) || uncorrected->steps[5].robot_x != 10);  // 2.5 steps late
  EXPECT_DOUBLE_EQ(timeline->steps[5].human_x, 5);
  EXPECT_DOUBLE_EQ(timeline->steps[5].robot_x, 10);
  EXPECT_EQ(timeline->steps.size(), 20u);
}

TEST(Analyze, EventScoresMatchHandComputedValues) {
  Report r = Analyse(WriteExperiment(TempPath("a.mcap")));
  ASSERT_EQ(r.events.size(), 2u);
  const EventSummary& a = r.events[0];  // steps 10..19, primitive 2
  EXPECT_NEAR(a.mean_congruence, 0.145, 1e-12);  // mean of 0.10..0.19
  EXPECT_NEAR(a.final_congruence, 0.19, 1e-12);
  EXPECT_NEAR(a.human_accuracy, 0.8, 1e-12);     // wrong at 12 and 13
  EXPECT_NEAR(a.robot_follows, 0.5, 1e-12);      // 15..19
  EXPECT_EQ(a.robot_switch_after, 5);
  const EventSummary& b = r.events[1];  // steps 30..33, primitive 5: robot never follows
  EXPECT_NEAR(b.human_accuracy, 1.0, 1e-12);
  EXPECT_NEAR(b.robot_follows, 0.0, 1e-12);
  EXPECT_EQ(b.robot_switch_after, -1);
}

TEST(Analyze, ConfusionCountsTheHumansTracedSteps) {
  Report r = Analyse(WriteExperiment(TempPath("a.mcap")));
  ASSERT_EQ(r.confusion.size(), 7u);
  EXPECT_EQ(r.confusion[2][2], 8);
  EXPECT_EQ(r.confusion[2][3], 2);
  EXPECT_EQ(r.confusion[5][5], 4);
  int64_t total = 0;
  for (const auto& row : r.confusion) for (int64_t c : row) total += c;
  EXPECT_EQ(total, 14);
  const std::string md = FormatMarkdown(r);
  EXPECT_NE(md.find("| 0 | 10-19 | 2 | 0.145 | 0.190 | 0.800 | 0.500 | 5 steps |"), std::string::npos) << md;
  EXPECT_NE(md.find("| **2** | 0.00 | 0.00 | 0.80 | 0.20 |"), std::string::npos) << md;
}

// A run shorter than the graph's plan (`dyad run --steps N`): events after the last recorded
// step never happened and must not be scored ("robot switched after: never"); an event the run
// cut short is scored over its recorded steps only.
TEST(Analyze, EventsAfterTheEndOfTheRecordingAreNotScored) {
  Report r = Analyse(WriteExperiment(TempPath("a.mcap")));  // 40 steps
  r.plan.events.push_back({36, 50, 1});   // cut by the end of the recording
  r.plan.events.push_back({60, 80, 4});   // entirely after it
  const auto events = Events(r.timeline, r.plan);
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[2].start_step, 36);
  EXPECT_EQ(events[2].end_step, 40);
  r.events = SummariseEvents(r.timeline, events);
  const std::string md = FormatMarkdown(r);
  EXPECT_EQ(md.find("| 3 | 60-80"), std::string::npos) << md;
  EXPECT_NE(md.find("| 2 | 36-39 (cut off by the end of the recording; planned to 49) | 1 |"), std::string::npos) << md;
  EXPECT_NE(md.find("\"robot switched after\": steps from the event's start"), std::string::npos) << md;
  EXPECT_NE(md.find("1 planned event after the end of the recording (not scored)"), std::string::npos) << md;
}

// The participant settling in before their first hold is no part of the interaction: the
// disengaged congruence is averaged from the first engagement on. N-ELBO and P(C_t) are explained.
TEST(Analyze, IdleTimeBeforeTheFirstEngagementIsLeftOutOfTheMeans) {
  Report r = Analyse(WriteExperiment(TempPath("a.mcap")));
  double sum = 0;
  int n = 0;
  bool seen = false;
  for (auto& x : r.timeline.steps) {
    seen = seen || x.engaged;
    if (!seen) x.congruence = 0.99;  // idle: must not count
    else if (!x.engaged && !std::isnan(x.congruence)) sum += x.congruence, ++n;
  }
  ASSERT_GT(n, 0);
  ASSERT_FALSE(r.timeline.steps.front().engaged);
  std::ostringstream expected;
  expected.setf(std::ios::fixed);
  expected.precision(3);
  expected << ", " << sum / n << " otherwise (from the first engagement on)";
  const std::string md = FormatMarkdown(r);
  EXPECT_NE(md.find(expected.str()), std::string::npos) << expected.str() << "\n" << md;
  EXPECT_NE(md.find("N-ELBO is the deliberator's free energy"), std::string::npos) << md;
  EXPECT_NE(md.find("P(C_t), the congruence, is the observer's probability"), std::string::npos) << md;
}

TEST(Analyze, ANeverEngagedHumanIsSaidSoNotAnEmptyNumber) {
  Report r = Analyse(WriteExperiment(TempPath("a.mcap")));
  for (auto& x : r.timeline.steps) x.engaged = false;
  const std::string md = FormatMarkdown(r);
  EXPECT_NE(md.find("- congruence P(C_t): never engaged, so not measured while engaged"), std::string::npos) << md;
  EXPECT_EQ(md.find("mean  while"), std::string::npos) << md;
}

// A person steering (web_human: no planned events) and no deliberator: the engaged runs are the
// events, and what was not recorded is said, not printed as empty numbers.
TEST(Analyze, AnInteractiveRunHasItsEngagedRunsAsEventsAndSaysWhatWasNotRecorded) {
  Report r = Analyse(WriteExperiment(TempPath("a.mcap")));
  r.plan.events.clear();
  for (auto& x : r.timeline.steps) {
    x.engaged = (x.step >= 5 && x.step < 12) || (x.step >= 20 && x.step < 23);
    x.nelbo = x.optimisation_s = std::nan("");
  }
  const auto events = Events(r.timeline, r.plan);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].start_step, 5);
  EXPECT_EQ(events[0].end_step, 12);
  EXPECT_EQ(events[1].start_step, 20);
  EXPECT_EQ(events[1].end_step, 23);
  EXPECT_EQ(events[1].primitive, -1);
  r.events = SummariseEvents(r.timeline, events);
  const std::string md = FormatMarkdown(r);
  // Nobody knows what the person traced in event 1: its measures against that primitive say so.
  const size_t row = md.find("| 1 | 20-22 | unknown |");
  ASSERT_NE(row, std::string::npos) << md;
  const std::string line = md.substr(row, md.find('\n', row) - row);
  EXPECT_EQ(line.substr(line.size() - 31), "| unknown | unknown | unknown |") << line;
  EXPECT_NE(md.find("- N-ELBO: not recorded"), std::string::npos) << md;
  EXPECT_NE(md.find("- deliberation time per step: not recorded"), std::string::npos) << md;
  EXPECT_EQ(md.find("mean , median"), std::string::npos) << md;
}

// The synthetic human's two events (steps 10..19 primitive 2, 30..33 primitive 5), reported as
// 2 and, wrongly, 4: each event keeps its traced primitive and gets its report; the observer is
// judged against the reports in a second matrix (event 1's 4 steps, all classified 5, in row 4).
TEST(Analyze, SelfReportsJoinTheirEventsAndJudgeTheObserverInASecondMatrix) {
  const std::string path = WriteExperiment(TempPath("s.mcap"), true, {{"yaml", kGraph}}, {{10, 20, 2}, {30, 34, 4}});
  std::ostringstream warnings;
  auto r = BuildReport(path, warnings);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->events.size(), 2u);
  EXPECT_EQ(r->events[0].event.primitive, 2);
  EXPECT_EQ(r->events[0].event.reported, 2);
  EXPECT_EQ(r->events[1].event.primitive, 5);
  EXPECT_EQ(r->events[1].event.reported, 4);
  EXPECT_EQ(r->confusion[5][5], 4);
  ASSERT_EQ(r->reported_confusion.size(), 7u);
  EXPECT_EQ(r->reported_confusion[2][2], 8);
  EXPECT_EQ(r->reported_confusion[2][3], 2);
  EXPECT_EQ(r->reported_confusion[4][5], 4);
  EXPECT_EQ(r->reported_confusion[5][5], 0);
  const std::string md = FormatMarkdown(*r);
  EXPECT_NE(md.find("| 1 | 30-33 | 5 (said 4) |"), std::string::npos) << md;
  EXPECT_NE(md.find("## Observer confusion against the self-reports"), std::string::npos) << md;
  EXPECT_NE(md.find("| **4** | 0.00 | 0.00 | 0.00 | 0.00 | 0.00 | 1.00 | 0.00 |"), std::string::npos) << md;
  const std::string dir = TempPath("s_report");
  ASSERT_TRUE(WriteReport(*r, dir).ok());
  const auto events = Lines(dir + "/events.csv");
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[0].substr(events[0].rfind(',') + 1), "self_report");
  EXPECT_EQ(events[2].substr(events[2].rfind(',') + 1), "4");
  const auto counts = Lines(dir + "/reported_confusion.csv");
  EXPECT_NE(std::find(counts.begin(), counts.end(), "4,5,4"), counts.end());
}

// Events that start while the subject's page says "practice" are left out, and the report says so.
TEST(Analyze, EventsStartedInPracticeAreLeftOutAndSaidSo) {
  const std::string path = WriteExperiment(TempPath("practice.mcap"), true, {{"yaml", kGraph}}, {}, {{0, true}, {25, false}});
  std::ostringstream warnings;
  auto r = BuildReport(path, warnings);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->practice_events, 1);
  ASSERT_EQ(r->events.size(), 1u);
  EXPECT_EQ(r->events[0].event.start_step, 30);
  EXPECT_EQ(r->confusion[2][2], 0) << "the practice event's steps are not in the matrix";
  EXPECT_NE(FormatMarkdown(*r).find("1 event(s) started while the subject's page said \"practice\""), std::string::npos);
  // Practice from step 12 to the end (its last sample repeats it): the event from step 10 started
  // before and is kept, the one from 30 is left out.
  auto spans = WriteExperiment(TempPath("practice2.mcap"), true, {{"yaml", kGraph}}, {}, {{5, false}, {12, true}, {32, true}});
  auto r2 = BuildReport(spans, warnings);
  ASSERT_TRUE(r2.ok()) << r2.status().ToString();
  EXPECT_EQ(r2->practice_events, 1);
  ASSERT_EQ(r2->events.size(), 1u);
  EXPECT_EQ(r2->events[0].event.start_step, 10);
}

// The graph's data set names its primitives (names.txt): the report calls them so, in the events
// and in the confusion's rows; the numbers stay in the CSV files. A bad names.txt is a warning.
TEST(Analyze, PrimitivesAreCalledByTheirDataSetsNames) {
  const std::string data = TempPath("named_set");
  ASSERT_TRUE(pvrnn::WriteNrlDataset(pvrnn::MakeAnalyticDataset(), data).ok());
  std::string graph = kGraph;
  graph.replace(graph.find("/nonexistent/dataset"), std::string("/nonexistent/dataset").size(), data);
  const std::string path = WriteExperiment(TempPath("named.mcap"), true, {{"yaml", graph}}, {{30, 34, 4}});
  std::ostringstream warnings;
  auto r = BuildReport(path, warnings);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(warnings.str(), "");
  const std::string md = FormatMarkdown(*r);
  EXPECT_NE(md.find("| 0 | 10-19 | triangle (2) |"), std::string::npos) << md;
  EXPECT_NE(md.find("| 1 | 30-33 | heart (5) (said star (4)) |"), std::string::npos) << md;
  EXPECT_NE(md.find("| **triangle (2)** |"), std::string::npos) << md;
  const std::string dir = TempPath("report");
  ASSERT_TRUE(WriteReport(*r, dir).ok());
  EXPECT_EQ(Lines(dir + "/events.csv").at(1).rfind("0,10,20,2,", 0), 0u) << Lines(dir + "/events.csv").at(1);
  { std::ofstream(data + "/names.txt") << "just one\n"; }
  auto bad = BuildReport(path, warnings);
  ASSERT_TRUE(bad.ok()) << bad.status().ToString();
  EXPECT_NE(warnings.str().find("the primitives' names not read: " + data + "/names.txt: 1 names, dataset.d says numberprims=7"),
            std::string::npos) << warnings.str();
  EXPECT_NE(FormatMarkdown(*bad).find("| 0 | 10-19 | 2 |"), std::string::npos);
}

// A self-report whose choice is neither a primitive nor -1 fails the analysis, naming the message.
TEST(Analyze, ASelfReportWithABadChoiceIsRefusedNamingTheMessage) {
  const std::string path = WriteExperiment(TempPath("bad_report.mcap"), true, {{"yaml", kGraph}}, {{10, 20, 2}, {30, 34, -5}});
  std::ostringstream warnings;
  auto r = BuildReport(path, warnings);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), Status::Code::kDataLoss);
  EXPECT_NE(r.status().message().find("topic human/self_report message 2"), std::string::npos) << r.status().ToString();
  EXPECT_NE(r.status().message().find("field \"choice\" holds -5"), std::string::npos) << r.status().ToString();
}

// A person (no planned events): the engaged runs are the events and what the person said is their
// primitive; "something else" leaves it unknown.
TEST(Analyze, APersonsSelfReportsNameTheirEngagedRuns) {
  const std::string path = WriteExperiment(TempPath("p.mcap"), true, {{"yaml", "graph: unit\nclock: stepped\n"}}, {{10, 20, 2}, {30, 34, -1}});
  std::ostringstream warnings;
  auto r = BuildReport(path, warnings);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->events.size(), 2u);
  EXPECT_EQ(r->events[0].event.primitive, 2);
  EXPECT_NEAR(r->events[0].human_accuracy, 0.8, 1e-12);
  EXPECT_EQ(r->events[1].event.primitive, -1);
  EXPECT_EQ(r->events[1].event.reported, -1);
  const std::string md = FormatMarkdown(*r);
  EXPECT_NE(md.find("| 1 | 30-33 | unknown (said: something else) |"), std::string::npos) << md;
}

// A person steering from the subject's page (web_human): a hold shorter than the page's
// self_report_min_hold_s is a tap the page never asked about, and no event of the analysis (the
// 0.4 s run at steps 30..33 under the default 1 s); the 1 s run at 10..19 is one. With the
// minimum at 0.3 s both are events.
TEST(Analyze, ATapShorterThanThePagesMinimumHoldIsNoEvent) {
  const std::string person = "graph: unit\nclock: stepped\ncomponents:\n  web: {type: web}\n"
                             "  human: {type: web_human, inputs: {pointer: web/pointer}, outputs: {input: human/input}}\n";
  auto r = BuildReport(WriteExperiment(TempPath("tap.mcap"), true, {{"yaml", person}}), std::cerr);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->events.size(), 1u);
  EXPECT_EQ(r->events[0].event.start_step, 10);
  EXPECT_EQ(r->events[0].event.end_step, 20);
  const auto metrics = RunMetrics(*r);
  EXPECT_EQ(std::find_if(metrics.begin(), metrics.end(), [](const auto& m) { return m.first == "events"; })->second, 1.0);
  std::string shorter = person;
  shorter.replace(shorter.find("{type: web}"), 11, "{type: web, params: {self_report_min_hold_s: 0.3}}");
  auto both = BuildReport(WriteExperiment(TempPath("tap03.mcap"), true, {{"yaml", shorter}}), std::cerr);
  ASSERT_TRUE(both.ok()) << both.status().ToString();
  EXPECT_EQ(both->events.size(), 2u);
  // Without a subject's page (no web_human) every engaged run is an event, as before.
  auto plain = BuildReport(WriteExperiment(TempPath("tap_plain.mcap"), true, {{"yaml", "graph: unit\nclock: stepped\n"}}), std::cerr);
  ASSERT_TRUE(plain.ok()) << plain.status().ToString();
  EXPECT_EQ(plain->events.size(), 2u);
}

TEST(Analyze, WithoutObserverTheReportSaysWhatIsMissing) {
  Report r = Analyse(WriteExperiment(TempPath("a.mcap"), /*with_observer=*/false));
  ASSERT_EQ(r.timeline.missing_topics.size(), 1u);
  EXPECT_EQ(r.timeline.missing_topics[0], "observer/labels");
  EXPECT_TRUE(r.confusion.empty());
  EXPECT_TRUE(std::isnan(r.events[0].mean_congruence));
  const std::string md = FormatMarkdown(r);
  EXPECT_NE(md.find("missing topics (their columns are empty): `observer/labels`"), std::string::npos) << md;
  EXPECT_NE(md.find("Not available"), std::string::npos) << md;
}

// What `dyad bag info` says of losses and health is in the report, before the numbers it may skew.
TEST(Analyze, TheTransportSectionComesBeforeTheScores) {
  Report r = Analyse(WriteExperiment(TempPath("a.mcap"), /*with_observer=*/true));
  EXPECT_EQ(FormatMarkdown(r).find("## Transport"), std::string::npos);  // not read: not shown
  r.transport = "losses:      per writer\n  robot/state  lab/robot  10 samples, 1..13: 3 missing\n";
  const std::string md = FormatMarkdown(r);
  const auto at = md.find("## Transport: what the recording lost, what the runtime healed\n\n```\nlosses:");
  ASSERT_NE(at, std::string::npos) << md;
  EXPECT_NE(md.find("3 missing\n```\n"), std::string::npos) << md;
  EXPECT_LT(at, md.find("| ")) << md;
  // After the summary's bullets, not among them (a heading there put the last bullets under it).
  EXPECT_LT(md.find("- congruence P(C_t): "), at) << md;
  EXPECT_LT(md.find("- engaged steps: "), at) << md;
}

TEST(Analyze, CellParsersRejectWhatIsNotANumber) {
  double v = 0;
  EXPECT_TRUE(ParseNumber("-1.5e3", &v));
  EXPECT_EQ(v, -1500);
  EXPECT_FALSE(ParseNumber("12x", &v));
  EXPECT_FALSE(ParseNumber("", &v));
  std::vector<double> list;
  EXPECT_TRUE(ParseNumberList("[0.25,0.75]", &list));
  EXPECT_EQ(list, (std::vector<double>{0.25, 0.75}));
  EXPECT_TRUE(ParseNumberList("[]", &list));
  EXPECT_TRUE(list.empty());
  EXPECT_FALSE(ParseNumberList("[1,,2]", &list));
  EXPECT_FALSE(ParseNumberList("1,2", &list));
}

int RunCli(std::vector<std::string> args, std::string* err = nullptr) {
  const auto r = dyad::testing::RunCommand(dyad::cli::AddAnalyzeCommands, std::move(args));
  if (err) *err = r.err;
  return r.code;
}

std::string Head(const std::string& path, size_t n) {
  std::ifstream in(path, std::ios::binary);
  std::string s(n, '\0');
  in.read(s.data(), static_cast<std::streamsize>(n));
  return s.substr(0, static_cast<size_t>(in.gcount()));
}

// The graph's data set path is relative to the graph file's folder, which the recording keeps.
TEST(AnalyzeCli, TheGraphsRelativeDatasetIsFoundFromTheRecordedFolder) {
  std::string yaml = kGraph;
  yaml.replace(yaml.find("/nonexistent/dataset"), 20, "data/set");
  const std::string rec = WriteExperiment(TempPath("rel.mcap"), true, {{"yaml", yaml}, {"folder", "/lab/graphs"}});
  std::string err;
  EXPECT_EQ(RunCli({"analyze", rec, "-o", TempPath("rel_report")}, &err), 0) << err;
  EXPECT_NE(err.find("the graph's dataset /lab/graphs/data/set is not a folder from here"), std::string::npos) << err;
}

// The CLI end to end through the `dyad` executable (it finds share/dyad/plot_report.py).
TEST(AnalyzeCli, WritesTablesAndPngPlots) {
  const std::string rec = WriteExperiment(TempPath("exp.mcap"));
  const std::string out = TempPath("report");
  const std::string cmd = std::string(DYAD_BIN_DIR) + "/dyad analyze " + rec + " -o " + out + " > " + out + ".log 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << Head(out + ".log", 4000);
  for (const char* f : {"report.md", "events.csv", "confusion.csv", "timeline.csv", "graph.yaml"}) {
    EXPECT_TRUE(std::filesystem::exists(out + "/" + f)) << f;
  }
  for (const char* f : {"workspace.png", "nelbo.png", "congruence.png"}) {
    EXPECT_EQ(Head(out + "/" + f, 8), "\x89PNG\r\n\x1a\n") << f;
  }
  EXPECT_NE(Head(out + ".log", 4000).find("not a folder from here"), std::string::npos);  // graph's dataset
  std::ifstream timeline(out + "/timeline.csv");
  int lines = 0;
  for (std::string line; std::getline(timeline, line);) ++lines;
  EXPECT_EQ(lines, 41);
}

// A recording cut short (a crash, a full disk) is said in the report's first lines, before any
// number; so is one shorter than the run's planned duration (--duration). Numbers in the tables
// read back to the doubles the analysis computed.
TEST(AnalyzeCli, AnIncompleteRecordingIsSaidInTheReportsFirstLines) {
  const std::string whole = WriteExperiment(TempPath("whole.mcap"));
  std::ostringstream warnings;
  auto full = BuildReport(whole, warnings);
  ASSERT_TRUE(full.ok()) << full.status().ToString();
  EXPECT_EQ(IncompleteReason(*full), "");
  EXPECT_EQ(FormatMarkdown(*full).find("**Incomplete recording"), std::string::npos);
  full->planned_s = 4.2;  // 40 steps of 100 ms: 4 s, 95% of 4.2 s is 3.99 s
  EXPECT_EQ(IncompleteReason(*full), "");
  full->planned_s = 5;
  EXPECT_EQ(IncompleteReason(*full), "shorter than planned: 40 steps of 100 ms (4 s) of the 5 s planned");
  EXPECT_EQ(FormatMarkdown(*full).rfind("# Experiment report\n\n**Incomplete recording: shorter than planned", 0), 0u)
      << FormatMarkdown(*full);
  // The last bytes gone: the reader recovers what it can, the report says so first.
  const std::string cut = TempPath("cut.mcap");
  std::filesystem::copy_file(whole, cut);
  std::filesystem::resize_file(cut, std::filesystem::file_size(whole) - 10);
  auto part = BuildReport(cut, warnings);
  ASSERT_TRUE(part.ok()) << part.status().ToString();
  EXPECT_EQ(IncompleteReason(*part).rfind("cut short", 0), 0u) << IncompleteReason(*part);
  std::string err;
  const std::string out = TempPath("cut_report");
  EXPECT_EQ(RunCli({"analyze", cut, "-o", out, "--no-plots"}, &err), 0) << err;
  EXPECT_NE(err.find("incomplete recording: cut short"), std::string::npos) << err;
  const auto md = Lines(out + "/report.md");
  ASSERT_GE(md.size(), 3u);
  EXPECT_EQ(md[2].rfind("**Incomplete recording: cut short", 0), 0u) << md[2];
  ASSERT_EQ(Lines(out + "/incomplete.txt").size(), 1u);  // what a sweep's table reads
  EXPECT_EQ(Lines(out + "/incomplete.txt")[0], IncompleteReason(*part));
  ASSERT_TRUE(WriteReport(*full, out).ok());  // planned 5 s: incomplete too
  full->planned_s = 0;
  ASSERT_TRUE(WriteReport(*full, out).ok());
  EXPECT_FALSE(std::filesystem::exists(out + "/incomplete.txt")) << "a whole run's report keeps an earlier one's";
  EXPECT_EQ(RunCli({"analyze", whole, "-o", TempPath("short_report"), "--no-plots", "--duration", "60"}, &err), 0) << err;
  EXPECT_NE(err.find("incomplete recording: shorter than planned: 40 steps of 100 ms (4 s) of the 60 s planned"), std::string::npos)
      << err;
  // Exact numbers: every event's mean congruence reads back to the double computed.
  const auto events = Lines(out + "/events.csv");
  ASSERT_EQ(events.size(), part->events.size() + 1);
  for (size_t i = 0; i < part->events.size(); ++i) {
    std::stringstream row(events[i + 1]);
    std::string cell;
    for (int k = 0; k < 5; ++k) std::getline(row, cell, ',');
    EXPECT_EQ(std::strtod(cell.c_str(), nullptr), part->events[i].mean_congruence) << events[i + 1];
  }
}

TEST(AnalyzeCli, BadInputExitsTwoNamingTheFile) {
  std::string err;
  EXPECT_EQ(RunCli({"analyze", TempPath("missing.mcap")}, &err), 2);
  EXPECT_NE(err.find(TempPath("missing.mcap")), std::string::npos) << err;
  const std::string text = TempPath("text.mcap");
  std::ofstream(text) << "not a recording\n";
  EXPECT_EQ(RunCli({"analyze", text}, &err), 2);
  EXPECT_NE(err.find("not an MCAP file"), std::string::npos) << err;
  const std::string rec = WriteExperiment(TempPath("exp.mcap"));
  EXPECT_EQ(RunCli({"analyze", rec, "-o", TempPath("r"), "--dataset", TempPath("nope")}, &err), 2);
  EXPECT_NE(err.find("--dataset"), std::string::npos) << err;
}

// Live parameter changes: human/input at 10 Hz for 20 steps; on dyad/params, mixer.gain applied
// 1.0 s after the first human sample (the mixer had made 9 steps: the answer's own step count is
// not the timeline's step) and a refusal, which changed nothing. On experiment/notes, a note at
// step 5 (web's clock 0.2 s ahead: another process).
std::string WriteParamChanges(const std::string& path) {
  auto writer = mcap::Writer::Open(path);
  EXPECT_TRUE(writer.ok());
  EXPECT_TRUE(writer->AddMetadata("dyad.graph", {{"yaml", kGraph}}).ok());
  Channel<msg::HumanInput> human(*writer, "human/input");
  Channel<msg::ParamChange> params(*writer, "dyad/params");
  Channel<msg::Annotation> notes(*writer, "experiment/notes");
  auto answer = [](const std::string& op, const std::string& value, uint64_t step) {
    msg::ParamChange a;
    a.header().source("dyad/main");
    a.graph_name("unit"); a.component_name("mixer"); a.param_name("gain"); a.op(op); a.value(value);
    a.request_id(op); a.step(step);
    return a;
  };
  for (int t = 0; t < 20; ++t) {
    msg::HumanInput h; h.x(t); h.y(-t);
    human.Write(h, t);
    if (t == 5) {
      msg::Annotation n;
      n.header().source("web");
      n.author("experimenter");
      n.text("coughed, then | \"laughed\"");
      notes.Write(n, t);
    }
    if (t == 10) {
      msg::ParamChange applied = answer("applied", "0.2", 9);
      applied.old_value("0.9"); applied.who("dyad param set (ana@lab-pc)");
      params.Write(applied, t);
    }
    if (t == 14) {
      msg::ParamChange refused = answer("refused", "7", 13);
      refused.who("experimenter page"); refused.reason("7 is above the maximum 1");
      params.Write(refused, t);
    }
  }
  EXPECT_TRUE(writer->Close().ok());
  return path;
}

TEST(AnalyzeParams, AnAppliedChangeIsPlacedOnTheTimelinesStepGrid) {
  std::ostringstream warnings;
  auto r = BuildReport(WriteParamChanges(TempPath("p.mcap")), warnings);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(warnings.str(), "");
  ASSERT_EQ(r->param_changes.size(), 1u);  // the refusal is not a change
  const ParamChangeEvent& c = r->param_changes[0];
  EXPECT_EQ(c.step, 10);
  EXPECT_DOUBLE_EQ(c.time_s, 1.0);
  EXPECT_EQ(c.component, "mixer");
  EXPECT_EQ(c.param, "gain");
  EXPECT_EQ(c.old_value, "0.9");
  EXPECT_EQ(c.value, "0.2");
  EXPECT_EQ(c.who, "dyad param set (ana@lab-pc)");
  ASSERT_TRUE(r->timeline.t0_ns.has_value());
  EXPECT_EQ(*r->timeline.t0_ns, 1'000'000'000);

  const std::string dir = TempPath("report");
  ASSERT_TRUE(WriteReport(*r, dir).ok());
  EXPECT_EQ(Lines(dir + "/params.csv"), (std::vector<std::string>{"step,time_s,component,param,old_value,value,who",
                                                                    "10,1,mixer,gain,0.9,0.2,dyad param set (ana@lab-pc)"}));
  const std::string md = FormatMarkdown(*r);
  const auto section = md.find("## Live parameter changes\n\n| time | component.param | old -> new | who |\n");
  ASSERT_NE(section, std::string::npos) << md;
  EXPECT_NE(md.find("| 1.000 s (step 10) | mixer.gain | 0.9 -> 0.2 | dyad param set (ana@lab-pc) |\n", section),
            std::string::npos) << md;
  EXPECT_NE(md.find("applied at the component's step boundary", section), std::string::npos) << md;
  EXPECT_EQ(md.find("| 7"), std::string::npos) << md;  // refused: not shown
}

// The experimenter's notes: on the step grid, in the report (escaped for its table), in notes.csv.
TEST(AnalyzeNotes, TheExperimentersNotesAreOnTheTimelineInTheReportAndInTheirTable) {
  std::ostringstream warnings;
  auto r = BuildReport(WriteParamChanges(TempPath("p.mcap")), warnings);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->notes.size(), 1u);
  EXPECT_EQ(r->notes[0].step, 5);
  EXPECT_DOUBLE_EQ(r->notes[0].time_s, 0.5);
  EXPECT_EQ(r->notes[0].author, "experimenter");
  const std::string md = FormatMarkdown(*r);
  const auto section = md.find("## The experimenter's notes\n\n| time | who | note |\n");
  ASSERT_NE(section, std::string::npos) << md;
  EXPECT_NE(md.find("| 0.500 s (step 5) | experimenter | coughed, then \\| \"laughed\" |\n", section), std::string::npos) << md;
  const std::string dir = TempPath("report");
  ASSERT_TRUE(WriteReport(*r, dir).ok());
  EXPECT_EQ(Lines(dir + "/notes.csv"),
            (std::vector<std::string>{"step,time_s,author,text", "5,0.5,experimenter,\"coughed, then | \"\"laughed\"\"\""}));
  // Placed as any stamp of its writer's process: web's clock 200 ms ahead moves it 2 steps back.
  auto reader = mcap::Reader::Open(r->recording);
  ASSERT_TRUE(reader.ok());
  auto tables = ReadTables(*reader, {});
  ASSERT_TRUE(tables.ok());
  ExperimentPlan plan = r->plan;
  plan.process_of["web"] = "lab";
  auto timeline = BuildTimeline(*tables, plan, {{"lab", 200'000'000}});
  ASSERT_TRUE(timeline.ok()) << timeline.status().ToString();
  auto notes = ExperimenterNotes(*tables, plan, *timeline);
  ASSERT_TRUE(notes.ok()) << notes.status().ToString();
  ASSERT_EQ(notes->size(), 1u);
  EXPECT_EQ((*notes)[0].step, 3);
  // No notes: no section, and an earlier report's notes.csv is gone (the plots would draw it).
  Report without = *r;
  without.notes.clear();
  ASSERT_TRUE(WriteReport(without, dir).ok());
  EXPECT_FALSE(std::filesystem::exists(dir + "/notes.csv"));
  EXPECT_EQ(FormatMarkdown(without).find("experimenter's notes"), std::string::npos);
}

// The answer is stamped by its writer's process ("dyad/main"): when the timeline moves stamps of
// that process onto the recorder's clock, the change moves with them.
TEST(AnalyzeParams, AChangeGetsTheClockCorrectionOfItsWritersProcess) {
  auto reader = mcap::Reader::Open(WriteParamChanges(TempPath("p.mcap")));
  ASSERT_TRUE(reader.ok());
  auto tables = ReadTables(*reader, {});
  ASSERT_TRUE(tables.ok()) << tables.status().ToString();
  auto plan = PlanFromGraphYaml(kGraph);
  ASSERT_TRUE(plan.ok());
  auto timeline = BuildTimeline(*tables, *plan, {{"main", 200'000'000}});  // main's clock 2 steps ahead
  ASSERT_TRUE(timeline.ok()) << timeline.status().ToString();
  auto changes = AppliedParamChanges(*tables, *plan, *timeline);
  ASSERT_TRUE(changes.ok()) << changes.status().ToString();
  ASSERT_EQ(changes->size(), 1u);
  EXPECT_EQ((*changes)[0].step, 8);
  EXPECT_DOUBLE_EQ((*changes)[0].time_s, 0.8);
}

// No dyad/params: no list, no warning, no file, no section; a params.csv of an earlier report in
// the same folder is removed (the plots would draw it). Cells with commas and quotes are quoted.
TEST(AnalyzeParams, WithoutChangesThereIsNoTableAndCellsAreQuoted) {
  std::ostringstream warnings;
  auto r = BuildReport(WriteExperiment(TempPath("a.mcap")), warnings);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_TRUE(r->param_changes.empty());
  EXPECT_EQ(warnings.str(), "");
  EXPECT_EQ(FormatMarkdown(*r).find("Live parameter changes"), std::string::npos);
  const std::string dir = TempPath("report");
  Report with = *r;
  with.param_changes.push_back({12, 1.2, "mind", "meta_prior", "[1, 1]", "[0.5, 2]", "page \"lab\""});
  ASSERT_TRUE(WriteReport(with, dir).ok());
  EXPECT_EQ(Lines(dir + "/params.csv").at(1), "12,1.2,mind,meta_prior,\"[1, 1]\",\"[0.5, 2]\",\"page \"\"lab\"\"\"");
  ASSERT_TRUE(WriteReport(*r, dir).ok());
  EXPECT_FALSE(std::filesystem::exists(dir + "/params.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/report.md"));
}

// `dyad analyze` end to end with a change and a note: params.csv and notes.csv are written and
// plot_report.py draws them.
TEST(AnalyzeCli, DrawsThePlotsWithParameterChanges) {
  const std::string rec = WriteParamChanges(TempPath("p.mcap"));
  const std::string out = TempPath("report");
  const std::string cmd = std::string(DYAD_BIN_DIR) + "/dyad analyze " + rec + " -o " + out + " > " + out + ".log 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << Head(out + ".log", 4000);
  EXPECT_EQ(Lines(out + "/params.csv").size(), 2u);
  EXPECT_EQ(Lines(out + "/notes.csv").size(), 2u);
  for (const char* f : {"nelbo.png", "congruence.png"}) EXPECT_EQ(Head(out + "/" + f, 8), "\x89PNG\r\n\x1a\n") << f;
}

}  // namespace
}  // namespace dyad::analyze


namespace dyad::analyze {
namespace {

// Demonstrations: the recording's engaged segments (steps 10-19 and 30-33 of WriteExperiment,
// human at (t, -t)) become primitives resampled to T steps by linear interpolation.
TEST(Demonstrations, EngagedSegmentsBecomeResampledPrimitives) {
  auto reader = mcap::Reader::Open(WriteExperiment(TempPath("d.mcap")));
  ASSERT_TRUE(reader.ok());
  auto tables = ReadTables(*reader, {"human/input"});
  ASSERT_TRUE(tables.ok());
  DemonstrationOptions o;
  o.steps = 5;
  o.min_samples = 4;
  auto d = DemonstrationsFromTable(tables->at("human/input"), o);
  ASSERT_TRUE(d.ok()) << d.status().ToString();
  ASSERT_EQ(d->dataset.size(), 2);
  EXPECT_EQ(d->skipped, 0);
  const double first[] = {10, 12.25, 14.5, 16.75, 19};  // 10 samples 10..19 onto 5 points
  const double second[] = {30, 30.75, 31.5, 32.25, 33};
  for (int k = 0; k < 5; ++k) {
    EXPECT_NEAR(d->dataset.sequences[0](0, k), first[k], 1e-12);
    EXPECT_NEAR(d->dataset.sequences[0](1, k), -first[k], 1e-12);
    EXPECT_NEAR(d->dataset.sequences[1](0, k), second[k], 1e-12);
  }
  // 9 periods of 100 ms over 4 intervals for the first, 3 over 4 for the second.
  EXPECT_NEAR(d->dataset.sampling_period_ms, (225.0 + 75.0) / 2, 1e-9);
  o.min_samples = 5;  // the 4-sample segment is not a demonstration
  auto d2 = DemonstrationsFromTable(tables->at("human/input"), o);
  ASSERT_TRUE(d2.ok());
  EXPECT_EQ(d2->dataset.size(), 1);
  EXPECT_EQ(d2->skipped, 1);
}

TEST(Demonstrations, CliWritesAnNrlDataSetTheLoaderReads) {
  const std::string rec = WriteExperiment(TempPath("d.mcap"));
  const std::string out = TempPath("demo_set");
  auto r = dyad::testing::RunCommand(dyad::cli::AddAnalyzeCommands,
                               {"dataset", "from-recording", rec, "--out", out, "--steps", "72", "--min-samples", "4"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("2 primitive(s) of 72 steps"), std::string::npos) << r.out;
  auto data = pvrnn::LoadNrlDataset(out);
  ASSERT_TRUE(data.ok()) << data.status().ToString();
  EXPECT_EQ(data->size(), 2);
  EXPECT_EQ(data->steps(), 72);
  EXPECT_NEAR((*data).sequences[0](0, 71), 19, 1e-6);
}

TEST(Demonstrations, CliRefusesWhatHasNoDemonstration) {
  const std::string rec = WriteExperiment(TempPath("d.mcap"));
  auto r = dyad::testing::RunCommand(dyad::cli::AddAnalyzeCommands,
                               {"dataset", "from-recording", rec, "--out", TempPath("x"), "--min-samples", "50"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("no engaged segment of at least 50 samples (2 shorter ones)"), std::string::npos) << r.err;
  r = dyad::testing::RunCommand(dyad::cli::AddAnalyzeCommands, {"dataset", "from-recording", rec, "--out", TempPath("x"), "--topic", "robot/state"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("has no x, y and engaged fields"), std::string::npos) << r.err;
  r = dyad::testing::RunCommand(dyad::cli::AddAnalyzeCommands, {"dataset", "from-recording", TempPath("missing.mcap"), "--out", TempPath("x")});
  EXPECT_EQ(r.code, 2);
}

// A HumanInput table of engaged circles of radius 10 (`laps` each, `per_lap` samples a lap,
// `period_ms` apart), separated by one disengaged sample.
TopicTable Circles(const std::vector<std::pair<double, int>>& segments, int per_lap, double period_ms) {
  TopicTable t;
  t.columns = {"header.stamp_ns", "x", "y", "engaged"};
  double stamp = 1e9;
  auto add = [&](double x, double y, bool engaged) {
    t.rows.push_back({std::to_string(static_cast<long long>(stamp)), std::to_string(x), std::to_string(y), engaged ? "true" : "false"});
    stamp += period_ms * 1e6;
  };
  for (const auto& [laps, offset] : segments) {
    const int n = static_cast<int>(laps * per_lap);
    for (int i = 0; i <= n; ++i) {
      const double a = 2 * M_PI * i / per_lap;
      add(offset + 10 * std::cos(a), 10 * std::sin(a), true);
    }
    add(0, 0, false);
  }
  return t;
}

TEST(Demonstrations, SeveralLapsInOneHoldAndAnotherPaceAreSaid) {
  DemonstrationOptions o;
  // One lap of 71 intervals (72 samples) -> no warning; two laps in one hold -> said.
  auto one = DemonstrationsFromTable(Circles({{1, 0}}, 71, 100), o);
  ASSERT_TRUE(one.ok()) << one.status().ToString();
  EXPECT_EQ(one->segments.at(0).laps, 1);
  EXPECT_TRUE(one->warnings.empty()) << one->warnings.front();
  EXPECT_NEAR(one->dataset.sampling_period_ms, 100, 1e-6);
  auto two = DemonstrationsFromTable(Circles({{2, 0}}, 71, 100), o);
  ASSERT_TRUE(two.ok());
  EXPECT_EQ(two->segments.at(0).laps, 2);
  ASSERT_EQ(two->warnings.size(), 2u);  // two laps, and 143 samples squeezed into 72 steps
  EXPECT_NE(two->warnings[0].find("primitive 0 (segment 0): holds 2 laps of its shape"), std::string::npos) << two->warnings[0];
  EXPECT_NE(two->warnings[1].find("drawn in 143 samples 100 ms apart, resampled to steps 200 ms apart"), std::string::npos)
      << two->warnings[1];
  EXPECT_NE(two->warnings[1].find("--steps 143 keeps it"), std::string::npos) << two->warnings[1];
  // Half a lap again (an open arc): one lap, and the pace of 108 samples onto 72 steps is said.
  auto arc = DemonstrationsFromTable(Circles({{0.5, 0}}, 214, 100), o);
  ASSERT_TRUE(arc.ok());
  EXPECT_EQ(arc->segments.at(0).laps, 1);
  ASSERT_EQ(arc->warnings.size(), 1u);
  EXPECT_NE(arc->warnings[0].find("resampled to steps 151 ms apart"), std::string::npos) << arc->warnings[0];
}

TEST(Demonstrations, SegmentsChooseWhichBecomesWhichPrimitive) {
  DemonstrationOptions o;
  o.choose = {2, 0, 2};  // skip 1, reorder, reuse
  const TopicTable table = Circles({{1, 0}, {1, 100}, {1, 200}}, 71, 100);
  auto d = DemonstrationsFromTable(table, o);
  ASSERT_TRUE(d.ok()) << d.status().ToString();
  ASSERT_EQ(d->segments.size(), 3u);
  ASSERT_EQ(d->dataset.size(), 3);
  EXPECT_NEAR(d->dataset.sequences[0](0, 0), 210, 1e-4);  // segment 2 starts at x = 200 + 10
  EXPECT_NEAR(d->dataset.sequences[1](0, 0), 10, 1e-4);
  EXPECT_NEAR(d->dataset.sequences[2](0, 0), 210, 1e-4);
  EXPECT_NEAR(d->segments[1].start_s, 7.3, 1e-9);  // 73 samples of 100 ms before it
  o.choose = {3};
  auto bad = DemonstrationsFromTable(table, o);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("--segments: no segment 3; the recording has 3: 0 (at 0.0 s, 7.1 s long), 1 (at 7.3 s"),
            std::string::npos)
      << bad.status().message();
}

TEST(Demonstrations, CliTakesSegmentsAndDrawsAPreview) {
  const std::string rec = WriteExperiment(TempPath("d.mcap"));
  const std::string out = TempPath("chosen"), png = TempPath("preview.png");
  auto r = dyad::testing::RunCommand(dyad::cli::AddAnalyzeCommands, {"dataset", "from-recording", rec, "--out", out, "--min-samples",
                                                                     "4", "--segments", "1,0", "--preview", png,
                                                                     "--names", "zigzag,long stroke"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("   0  at     1.0 s    0.9 s    10 samples  1 lap -> primitive 1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("   1  at     3.0 s    0.3 s     4 samples  1 lap -> primitive 0"), std::string::npos) << r.out;
  auto data = pvrnn::LoadNrlDataset(out);
  ASSERT_TRUE(data.ok());
  EXPECT_NEAR(data->sequences[0](0, 0), 30, 1e-6);  // segment 1 (steps 30-33) first
  EXPECT_EQ(data->names, (std::vector<std::string>{"zigzag", "long stroke"}));
  std::ifstream f(png, std::ios::binary);
  char magic[4] = {};
  f.read(magic, 4);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG") << "no preview at " << png << "\n" << r.err;
  const std::string not_written = TempPath("wrong");
  auto wrong = dyad::testing::RunCommand(dyad::cli::AddAnalyzeCommands, {"dataset", "from-recording", rec, "--out", not_written,
                                                                         "--min-samples", "4", "--names", "only one"});
  EXPECT_EQ(wrong.code, 2);
  EXPECT_NE(wrong.err.find("--names gives 1 names for 2 primitive(s)"), std::string::npos) << wrong.err;
  EXPECT_FALSE(std::filesystem::exists(not_written + "/dataset.d")) << "nothing is written";
}

}  // namespace
}  // namespace dyad::analyze
