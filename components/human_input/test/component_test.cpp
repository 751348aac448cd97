// The human_synthetic and human_replay components: through a fake context (no DDS) and, once
// each, loaded by name and run by a real `dyad run`.
#include <gtest/gtest.h>

#include "dyad/testing/dds_domain.hpp"
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "dyad/pvrnn/analytic_dataset.hpp"
#include "dyad/testing/csv.hpp"
#include "dyad/testing/fake_context.hpp"
#include "human_input.hpp"

namespace dyad::human_input {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("dyad_human_input_" + std::to_string(getpid()) + "_" + name);
  fs::create_directories(d);
  return d;
}

std::string AnalyticDir() {
  static const std::string dir = [] {
    const fs::path d = TempDir("analytic");
    EXPECT_TRUE(pvrnn::WriteNrlDataset(pvrnn::MakeAnalyticDataset(), d.string()).ok());
    return d.string();
  }();
  return dir;
}

std::vector<msg::HumanInput> RunSynthetic(const std::string& events, double noise, int64_t lag, uint64_t seed, int steps) {
  testing::FakeContext ctx(&HumanSynthetic::Describe,
                           {{"dataset", AnalyticDir()}, {"events", events}, {"noise_std", noise}, {"lag", lag}}, seed);
  auto& out = ctx.Capture<msg::HumanInput>("out");
  HumanSynthetic c;
  EXPECT_TRUE(c.Configure(ctx).ok());
  for (int k = 0; k < steps; ++k) EXPECT_TRUE(c.Step({.now_ns = k * 100'000'000LL, .index = static_cast<uint64_t>(k)}).ok());
  return out.samples;
}

TEST(HumanSyntheticComponent, PublishesTheTraceOfTheDataSetDuringEvents) {
  const auto data = pvrnn::MakeAnalyticDataset();
  const auto s = RunSynthetic("[{start: 5, end: 15, primitive: 3}]", 0.0, 0, 1, 20);
  ASSERT_EQ(s.size(), 20u);
  for (int k = 0; k < 20; ++k) {
    const bool in_event = k >= 5 && k < 15;
    EXPECT_EQ(s[k].engaged(), in_event) << k;
    if (in_event) {
      EXPECT_DOUBLE_EQ(s[k].x(), data.sequences[3](0, k - 5)) << k;
      EXPECT_DOUBLE_EQ(s[k].y(), data.sequences[3](1, k - 5)) << k;
    }
  }
  EXPECT_DOUBLE_EQ(s[19].x(), s[14].x());
  EXPECT_EQ(s[19].header().sequence_number(), 20u);
}

// Steps are 100 ms apart: event 5..14 is released at step 15 (1.5 s); with a delay of 0.25 s its
// self-report comes at the first step from 1.75 s on (step 18: a response of 0.3 s).
TEST(HumanSyntheticComponent, ReportsWhatItDrewAfterEachReleaseWithTheSegmentsTimes) {
  testing::FakeContext ctx(&HumanSynthetic::Describe,
                           {{"dataset", AnalyticDir()},
                            {"events", std::string("[{start: 5, end: 15, primitive: 3}, {start: 30, end: 40, primitive: 1}]")},
                            {"self_report_delay", 0.25}});
  ctx.Capture<msg::HumanInput>("out");
  auto& reports = ctx.Capture<msg::SelfReport>("self_report");
  HumanSynthetic c;
  ASSERT_TRUE(c.Configure(ctx).ok());
  std::vector<uint64_t> published_at;
  for (uint64_t k = 0; k < 45; ++k) {
    const size_t before = reports.samples.size();
    ASSERT_TRUE(c.Step({.now_ns = static_cast<int64_t>(k) * 100'000'000LL, .index = k}).ok());
    if (reports.samples.size() > before) published_at.push_back(k);
  }
  ASSERT_EQ(reports.samples.size(), 2u);
  EXPECT_EQ(published_at, (std::vector<uint64_t>{18, 43}));
  const msg::SelfReport& r = reports.samples[0];
  EXPECT_EQ(r.choice(), 3);
  EXPECT_EQ(r.segment_start_ns(), 500'000'000LL);
  EXPECT_EQ(r.segment_end_ns(), 1'500'000'000LL);
  EXPECT_NEAR(r.response_s(), 0.3, 1e-12);
  EXPECT_EQ(reports.samples[1].choice(), 1);
  EXPECT_EQ(reports.samples[1].segment_start_ns(), 3'000'000'000LL);
  EXPECT_EQ(reports.samples[1].header().sequence_number(), 2u);
}

TEST(HumanSyntheticComponent, SameSeedSameTrackOtherSeedOtherNoise) {
  const std::string ev = "[{start: 0, end: 50, primitive: 1}]";
  const auto a = RunSynthetic(ev, 1.0, 2, 11, 50), b = RunSynthetic(ev, 1.0, 2, 11, 50), c = RunSynthetic(ev, 1.0, 2, 12, 50);
  int same_ab = 0, same_ac = 0;
  for (size_t k = 0; k < a.size(); ++k) {
    same_ab += a[k].x() == b[k].x() && a[k].y() == b[k].y();
    same_ac += a[k].x() == c[k].x();
  }
  EXPECT_EQ(same_ab, 50);
  EXPECT_EQ(same_ac, 0);
}

TEST(HumanSyntheticComponent, BadEventsFailConfigureNamingTheEvent) {
  testing::FakeContext ctx(&HumanSynthetic::Describe,
                           {{"dataset", AnalyticDir()},
                            {"events", std::string("[{start: 0, end: 9, primitive: 0}, {start: 5, end: 20, primitive: 1}]")}});
  HumanSynthetic c;
  const Status s = c.Configure(ctx);
  EXPECT_EQ(s.message(), "events[1]: steps 5..19 overlap events[0] (steps 0..8)");
  testing::FakeContext ctx2(&HumanSynthetic::Describe, {{"dataset", std::string("/nonexistent/set")}});
  HumanSynthetic c2;
  EXPECT_NE(c2.Configure(ctx2).message().find("dataset: /nonexistent/set"), std::string::npos);
}

TEST(HumanReplayComponent, PublishesOneRowPerStepAndStopsAtTheEnd) {
  const fs::path csv = TempDir("replay") / "h.csv";
  std::ofstream(csv) << "log_time,x,y,engaged\n0,1,2,false\n1,3,4,true\n2,5,6,true\n";
  testing::FakeContext ctx(&HumanReplay::Describe, {{"file", csv.string()}});
  auto& out = ctx.Capture<msg::HumanInput>("out");
  HumanReplay c;
  ASSERT_TRUE(c.Configure(ctx).ok());
  for (uint64_t k = 0; k < 3; ++k) {
    EXPECT_TRUE(ctx.stop_reason.empty());
    ASSERT_TRUE(c.Step({.now_ns = 0, .index = k}).ok());
  }
  EXPECT_EQ(ctx.stop_reason, "human_replay: replayed all 3 rows");
  ASSERT_EQ(out.samples.size(), 3u);
  EXPECT_DOUBLE_EQ(out.samples[1].x(), 3);
  EXPECT_DOUBLE_EQ(out.samples[2].y(), 6);
  EXPECT_FALSE(out.samples[0].engaged());
  EXPECT_TRUE(out.samples[1].engaged());
  ASSERT_TRUE(c.Step({.now_ns = 0, .index = 3}).ok());  // a step after the end publishes nothing
  EXPECT_EQ(out.samples.size(), 3u);
}

// `dyad run` with the plugin found by type name: replay ends the run by itself; a synthetic human
// with bad events stops it before the first step with the event named.
int RunDyad(const fs::path& dir, const std::string& graph, std::string* err, const std::string& args = "") {
  const fs::path g = dir / "g.yaml", e = dir / "err.txt";
  std::ofstream(g) << graph;
  const std::string cmd = std::string(DYAD_EXE) + " run " + g.string() + " --quiet " + args + " > /dev/null 2> " + e.string();
  const int rc = std::system(cmd.c_str());
  std::ifstream in(e);
  err->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

TEST(HumanInputPlugin, LoadsByTypeNameAndRunsInDyad) {
  const fs::path dir = TempDir("run");
  const fs::path csv = dir / "h.csv";
  std::ofstream(csv) << "x,y,engaged\n1,2,false\n3,4,true\n";
  const std::string domain = std::to_string(dyad::testing::DomainForThisProcess());
  std::string err;
  EXPECT_EQ(RunDyad(dir,
                    "graph: replay\nclock: stepped\ndomain_id: " + domain +
                        "\ncomponents:\n"
                        "  human: {type: human_replay, rate_hz: 10, params: {file: " + csv.string() +
                        "}, outputs: {out: human/input}}\n"
                        "  synth: {type: human_synthetic, rate_hz: 10, params: {dataset: " + AnalyticDir() +
                        ", events: [{start: 0, end: 5, primitive: 2}]}, outputs: {out: human/synthetic}}\n",
                    &err),
            0)
      << err;
  EXPECT_NE(RunDyad(dir,
                    "graph: bad\nclock: stepped\ndomain_id: " + domain +
                        "\ncomponents:\n"
                        "  synth: {type: human_synthetic, rate_hz: 10, params: {dataset: " + AnalyticDir() +
                        ", events: [{start: 0, end: 5, primitive: 9}]}, outputs: {out: human/input}}\n",
                    &err),
            0);
  EXPECT_NE(err.find("events[0].primitive = 9"), std::string::npos) << err;
}

// A stepped rehearsal at 10 Hz: the event of steps 2..9 is released at step 10 (1.0 s) and
// answered 0.3 s later; the graph's recorder keeps the answer, read back through
// `dyad bag export --csv`.
TEST(HumanInputPlugin, ARecorderKeepsTheSelfReportsOfARun) {
  const fs::path dir = TempDir("self_report");
  const fs::path mcap = dir / "run.mcap", csv = dir / "csv";
  std::string err;
  ASSERT_EQ(RunDyad(dir,
                    "graph: rehearsal\nclock: stepped\ndomain_id: " + std::to_string(dyad::testing::DomainForThisProcess()) +
                        "\ncomponents:\n"
                        "  synth: {type: human_synthetic, rate_hz: 10, params: {dataset: " + AnalyticDir() +
                        ", events: [{start: 2, end: 10, primitive: 4}], self_report_delay: 0.3},\n"
                        "          outputs: {out: human/input, self_report: human/self_report}}\n"
                        "  rec: {type: recorder, rate_hz: 10, params: {file: " + mcap.string() + ", topics: [human/self_report]}}\n",
                    &err, "--steps 20"),
            0)
      << err;
  const std::string cmd = std::string(DYAD_EXE) + " bag export " + mcap.string() + " --csv " + csv.string() + " > /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  const auto rows = dyad::testing::ReadCsv(csv / "human_self_report.csv");
  ASSERT_EQ(rows.size(), 1u) << "in " << csv;
  EXPECT_EQ(rows[0].at("choice"), "4");
  EXPECT_EQ(rows[0].at("segment_start_ns"), "200000000");
  EXPECT_EQ(rows[0].at("segment_end_ns"), "1000000000");
  EXPECT_NEAR(std::stod(rows[0].at("response_s")), 0.3, 1e-9);
  EXPECT_EQ(rows[0].at("header.source"), "synth");
}

}  // namespace
}  // namespace dyad::human_input
