// `dyad sweep` on small stepped graphs: bad sweep files are refused at their line, the runs and
// their table do not depend on the number of workers, a failing run is recorded and the sweep
// goes on, a rerun resumes (finished runs skipped, failed ones tried again).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "dyad/testing/child_process.hpp"
#include "dyad/testing/cli.hpp"
#include "sweep_commands.hpp"

namespace dyad::cli {
namespace {

namespace fs = std::filesystem;
using dyad::testing::ReadFile;

class SweepTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("dyad_sweep_" + std::to_string(getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // Counters from a source to a sink and the recorder: a run takes a fraction of a second.
    std::ofstream(dir_ / "g.yaml") << "graph: swept\nclock: wall\n"
                                      "components:\n"
                                      "  src: {type: counter_source, rate_hz: 10, outputs: {out: c}}\n"
                                      "  sink: {type: counter_sink, rate_hz: 10, inputs: {in: c}}\n"
                                      "  recorder: {type: recorder, rate_hz: 10, params: {file: x.mcap}}\n";
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  fs::path Write(const std::string& text, const std::string& name = "s.yaml") {
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  }
  // The dyad executable, as a user runs it (its runs are processes of their own).
  int Sweep(const std::vector<std::string>& args, std::string* out = nullptr) {
    std::vector<std::string> argv = {std::string(DYAD_BIN_DIR) + "/dyad", "sweep"};
    argv.insert(argv.end(), args.begin(), args.end());
    dyad::testing::ChildProcess p(argv, dir_, "sweep" + std::to_string(runs_++));
    const int code = p.Wait(300);
    if (out) *out = p.out() + p.err();
    return code;
  }
  fs::path dir_;
  int runs_ = 0;
};

TEST_F(SweepTest, BadSweepFilesAreRefusedAtTheirLineAndNothingRuns) {
  const std::string head = "sweep: s\ngraph: g.yaml\nduration: 1\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {head + "grids: {src.start: [1]}\n", "s.yaml:4:1: grids: unknown key"},
      {head + "grid: {}\n", "s.yaml:4:7: grid: an empty grid"},
      {head + "grid: {src.start: 1}\n", "s.yaml:4:19: grid.src.start: must be a non-empty list of values"},
      {head + "grid: {src.start: [1]}\nruns: [{src.start: 2}]\n", "s.yaml:5:7: runs: give grid or runs, not both"},
      {head + "grid:\n  src.nope: [1, 2]\n", "s.yaml:5:14: grid.src.nope: does not validate"},
      {head + "grid:\n  src.start: [1, -5, x]\n", "s.yaml:5:22: grid.src.start: does not validate"},
      {head + "grid: {src.start: [1]}\nseeds: [1, 1]\n", "s.yaml:5:8: seeds: a seed is repeated"},
      {"sweep: s\ngraph: nowhere.yaml\nduration: 0\ngrid: {a: [1]}\n", "s.yaml:2:8: graph: no such file"},
  };
  for (const auto& [text, expected] : cases) {
    const fs::path file = Write(text);
    auto r = dyad::testing::RunCommand(AddSweepCommands, {"sweep", file.string(), "-o", (dir_ / "out").string()});
    EXPECT_EQ(r.code, 2) << text;
    EXPECT_NE(r.err.find(expected), std::string::npos) << "for\n" << text << "expected '" << expected << "' in:\n" << r.err;
  }
  EXPECT_FALSE(fs::exists(dir_ / "out")) << "a refused sweep ran something";
}

TEST_F(SweepTest, TheTableIsTheSameWithOneWorkerOrTwo) {
  const fs::path file = Write("sweep: s\ngraph: g.yaml\nduration: 2\ngrid:\n  src.start: [0, 100]\n  src.noise: [0, 2]\nseeds: [1, 2]\n");
  std::string out;
  ASSERT_EQ(Sweep({file.string(), "-o", (dir_ / "one").string(), "-j", "1", "--no-plots"}, &out), 0) << out;
  EXPECT_NE(out.find("8 ran, 0 done before, 0 failed"), std::string::npos) << out;
  ASSERT_EQ(Sweep({file.string(), "-o", (dir_ / "two").string(), "-j", "2", "--no-plots"}, &out), 0) << out;
  const std::string one = ReadFile(dir_ / "one" / "sweep.csv"), two = ReadFile(dir_ / "two" / "sweep.csv");
  EXPECT_EQ(one, two);
  // Header, then the grid's order (first key slowest), then seeds: 8 rows.
  EXPECT_EQ(one.rfind("run,status,src.start,src.noise,seed,steps,", 0), 0u) << one;
  EXPECT_EQ(std::count(one.begin(), one.end(), '\n'), 9);
  const size_t a = one.find(",ok,0,0,1,"), b = one.find(",ok,0,0,2,"), c = one.find(",ok,100,2,2,");
  EXPECT_TRUE(a < b && b < c && c != std::string::npos) << one;
}

TEST_F(SweepTest, AFailingRunIsRecordedTheRestRunAndARerunResumes) {
  // The sink cannot open a file in a missing folder: that run fails when it starts, not at validation.
  const fs::path file = Write("sweep: s\ngraph: g.yaml\nduration: 1\ngrid:\n  sink.file: [ok.txt, missing/x.txt, ok2.txt]\n");
  std::string out;
  EXPECT_EQ(Sweep({file.string(), "-o", (dir_ / "o").string(), "-j", "2", "--no-plots"}, &out), 1) << out;
  EXPECT_NE(out.find("2 ran, 0 done before, 1 failed"), std::string::npos) << out;
  const std::string csv = ReadFile(dir_ / "o" / "sweep.csv");
  EXPECT_NE(csv.find(",failed,missing/x.txt,1,"), std::string::npos) << csv;
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 4) << csv;
  size_t failed_files = 0;
  for (const auto& run : fs::directory_iterator(dir_ / "o" / "runs"))
    if (fs::exists(run.path() / "failed.txt")) {
      ++failed_files;
      EXPECT_NE(ReadFile(run.path() / "failed.txt").find("cannot open for writing"), std::string::npos);
    }
  EXPECT_EQ(failed_files, 1u);
  // The folder exists now: the rerun skips the two finished runs and tries the failed one again.
  fs::create_directories(dir_ / "missing");
  EXPECT_EQ(Sweep({file.string(), "-o", (dir_ / "o").string(), "-j", "2", "--no-plots"}, &out), 0) << out;
  EXPECT_NE(out.find("1 ran, 2 done before, 0 failed"), std::string::npos) << out;
  EXPECT_EQ(ReadFile(dir_ / "o" / "sweep.csv").find("failed"), std::string::npos);
}

}  // namespace
}  // namespace dyad::cli
