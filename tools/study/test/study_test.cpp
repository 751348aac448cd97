// A study file: its counterbalanced plan (a balanced Latin square, checked by its definition),
// blind labels, trial files, and every bad input at its line.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "dyad/testing/cli.hpp"
#include "latin_square.hpp"
#include "study_commands.hpp"
#include "study_file.hpp"

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
                                      "  sink: {type: counter_sink, rate_hz: 10, inputs: {in: c}}\n";
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

}  // namespace
}  // namespace dyad::study
