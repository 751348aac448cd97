// `dyad sweep` on small stepped graphs: bad sweep files are refused at their line, the runs and
// their table do not depend on the number of workers, a failing run is recorded and the sweep
// goes on, a rerun resumes (finished runs skipped, failed ones tried again).
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>

#include "dyad/testing/child_process.hpp"
#include "dyad/testing/cli.hpp"
#include "run_status.hpp"
#include "sweep_commands.hpp"
#include "sweep_slurm.hpp"

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
  int Sweep(const std::vector<std::string>& args, std::string* out = nullptr, std::vector<std::string> env = {}) {
    std::vector<std::string> argv = {std::string(DYAD_BIN_DIR) + "/dyad", "sweep"};
    argv.insert(argv.end(), args.begin(), args.end());
    dyad::testing::ChildProcess p(argv, dir_, "sweep" + std::to_string(runs_++), std::move(env));
    const int code = p.Wait(300);
    if (out) *out = p.out() + p.err();
    return code;
  }
  // The run ids of a sweep, in its order (from --dry-run).
  std::vector<std::string> Ids(const fs::path& file) {
    std::string out;
    EXPECT_EQ(Sweep({file.string(), "--dry-run"}, &out), 0) << out;
    std::vector<std::string> ids;
    std::istringstream lines(out);
    for (std::string line; std::getline(lines, line);)
      if (line.size() > 17 && line[16] == ' ' && line.find_first_not_of("0123456789abcdef") == 16) ids.push_back(line.substr(0, 16));
    return ids;
  }
  fs::path dir_;
  int runs_ = 0;
};

// The processes whose command line names `text` (the test's folder: its sweeps and their runs).
std::vector<int> ProcessesNaming(const std::string& text) {
  std::vector<int> pids;
  std::error_code ec;
  for (fs::directory_iterator it("/proc", ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::string cmdline = ReadFile(it->path() / "cmdline");
    std::replace(cmdline.begin(), cmdline.end(), '\0', ' ');
    if (cmdline.find(text) != std::string::npos) pids.push_back(std::stoi(name));
  }
  return pids;
}

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
      {head + "grid:\n  src.start: [0.5, 0.5, 0.9]\n", "s.yaml:5:20: grid.src.start: the value 0.5 is repeated"},
      {head + "grid: {src.start: [1], seed: [1, 2]}\nseeds: [3]\n", "s.yaml:4:30: grid.seed: give the seeds once"},
      {head + "runs: [{src.start: 1, seed: 2}]\n", "s.yaml:4:29: runs[0].seed: the seeds are the sweep's: give seeds:"},
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

// A run that ended itself before its duration (the source stops the run after 3 samples) is
// marked incomplete in the table, with its reason in its report, and left out of the plots.
TEST_F(SweepTest, ARunShorterThanItsDurationIsMarkedIncomplete) {
  const fs::path file = Write("sweep: s\ngraph: g.yaml\nduration: 3\ngrid:\n  src.limit: [0, 3]\n");
  std::string out;
  EXPECT_EQ(Sweep({file.string(), "-o", (dir_ / "o").string(), "--no-plots"}, &out), 0) << out;
  const std::string csv = ReadFile(dir_ / "o" / "sweep.csv");
  EXPECT_NE(csv.find(",ok,0,1,"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",incomplete,3,1,"), std::string::npos) << csv;
  size_t incomplete = 0;
  for (const auto& run : fs::directory_iterator(dir_ / "o" / "runs"))
    if (fs::exists(run.path() / "report" / "incomplete.txt")) {
      ++incomplete;
      EXPECT_NE(ReadFile(run.path() / "report" / "incomplete.txt").find("(no experiment steps) of the 3 s planned"), std::string::npos)
          << ReadFile(run.path() / "report" / "incomplete.txt");
    }
  EXPECT_EQ(incomplete, 1u);
}

// The cache key is the run as it runs: a rerun after a duration change runs every run again.
TEST_F(SweepTest, ARerunWithAnotherDurationRunsEveryRunAgain) {
  const std::string grid = "grid: {src.start: [0, 100]}\n";
  std::string out;
  ASSERT_EQ(Sweep({Write("sweep: s\ngraph: g.yaml\nduration: 1\n" + grid).string(), "-o", (dir_ / "o").string(), "--no-plots"}, &out), 0)
      << out;
  EXPECT_NE(out.find("2 ran, 0 done before, 0 failed"), std::string::npos) << out;
  const std::string short_csv = ReadFile(dir_ / "o" / "sweep.csv");
  ASSERT_EQ(Sweep({Write("sweep: s\ngraph: g.yaml\nduration: 3\n" + grid).string(), "-o", (dir_ / "o").string(), "--no-plots"}, &out), 0)
      << out;
  EXPECT_NE(out.find("2 ran, 0 done before, 0 failed"), std::string::npos) << out;
  EXPECT_NE(ReadFile(dir_ / "o" / "sweep.csv"), short_csv) << "the table kept the shorter runs' metrics";
  ASSERT_EQ(Sweep({(dir_ / "s.yaml").string(), "-o", (dir_ / "o").string(), "--no-plots"}, &out), 0) << out;
  EXPECT_NE(out.find("0 ran, 2 done before, 0 failed"), std::string::npos) << out;
}

// A file a run reads (a path parameter's) changed: the runs that read it run again, the others
// not; a change in a graph the run's graph extends reruns them all.
TEST_F(SweepTest, AChangedInputFileRerunsExactlyTheRunsThatReadIt) {
  std::string track = "x,y,engaged\n";
  for (int i = 0; i < 100; ++i) track += "0.1,0.2,1\n";
  Write(track, "a.csv");
  Write(track, "b.csv");
  Write("extends: g.yaml\ncomponents:\n  player: {type: human_replay, rate_hz: 10, params: {file: a.csv}, outputs: {out: h}}\n",
        "over.yaml");
  const fs::path file = Write("sweep: s\ngraph: over.yaml\nduration: 1\ngrid: {player.file: [a.csv, b.csv]}\nseeds: [1, 2]\n");
  const fs::path o = dir_ / "o";
  std::string out;
  ASSERT_EQ(Sweep({file.string(), "-o", o.string(), "--no-plots"}, &out), 0) << out;
  EXPECT_NE(out.find("4 ran, 0 done before, 0 failed"), std::string::npos) << out;
  const std::vector<std::string> before = Ids(file);
  Write("x,y,engaged\n" + track.substr(12, 10 * 50), "a.csv");  // the same length of header, other rows
  ASSERT_EQ(Sweep({file.string(), "-o", o.string(), "--no-plots"}, &out), 0) << out;
  EXPECT_NE(out.find("2 ran, 2 done before, 0 failed"), std::string::npos) << out;
  const std::vector<std::string> after = Ids(file);
  ASSERT_EQ(after.size(), 4u);
  EXPECT_NE(after[0], before[0]);  // a.csv, seeds 1 and 2
  EXPECT_NE(after[1], before[1]);
  EXPECT_EQ(after[2], before[2]);  // b.csv
  EXPECT_EQ(after[3], before[3]);
  // The graph it extends: every run.
  Write(ReadFile(dir_ / "g.yaml") + "  other: {type: counter_sink, rate_hz: 10, inputs: {in: c}}\n", "g.yaml");
  ASSERT_EQ(Sweep({file.string(), "-o", o.string(), "--no-plots"}, &out), 0) << out;
  EXPECT_NE(out.find("4 ran, 0 done before, 0 failed"), std::string::npos) << out;
}

// `seed` in the grid is the seeds (not overridden by the default seeds: [1]), one column.
TEST_F(SweepTest, SeedInTheGridIsTheSeeds) {
  const fs::path file = Write("sweep: s\ngraph: g.yaml\nduration: 1\ngrid: {src.start: [0], seed: [3, 4]}\n");
  std::string out;
  ASSERT_EQ(Sweep({file.string(), "--dry-run"}, &out), 0) << out;
  EXPECT_NE(out.find("--set src.start=0 --set seed=3\n"), std::string::npos) << out;
  EXPECT_NE(out.find("--set src.start=0 --set seed=4\n"), std::string::npos) << out;
  EXPECT_EQ(out.find("seed=1"), std::string::npos) << out;
  ASSERT_EQ(Sweep({file.string(), "-o", (dir_ / "o").string(), "--no-plots"}, &out), 0) << out;
  const std::string csv = ReadFile(dir_ / "o" / "sweep.csv");
  EXPECT_EQ(csv.rfind("run,status,src.start,seed,steps,", 0), 0u) << csv;
  EXPECT_NE(csv.find(",ok,0,3,"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",ok,0,4,"), std::string::npos) << csv;
}

// A run whose folder cannot be made (a file where it should be; the tests run as root, so
// permissions cannot do it) fails with the reason; the other runs go on.
TEST_F(SweepTest, ARunWhoseFolderCannotBeMadeFailsAndTheSweepGoesOn) {
  const fs::path file = Write("sweep: s\ngraph: g.yaml\nduration: 1\ngrid: {src.start: [0, 100, 7]}\n");
  const std::vector<std::string> ids = Ids(file);
  ASSERT_EQ(ids.size(), 3u);
  fs::create_directories(dir_ / "o" / "runs");
  std::ofstream(dir_ / "o" / "runs" / ids[1]) << "not a folder\n";
  std::string out;
  EXPECT_EQ(Sweep({file.string(), "-o", (dir_ / "o").string(), "-j", "2", "--no-plots"}, &out), 1) << out;
  EXPECT_NE(out.find("2 ran, 0 done before, 1 failed"), std::string::npos) << out;
  EXPECT_NE(out.find(ids[1] + " src.start=100 seed=1: FAILED (cannot make its folder " + (dir_ / "o" / "runs" / ids[1]).string() + ": "),
            std::string::npos)
      << out;
}

// SIGTERM: no run starts, the one under way stops (its whole process group), the finished one
// is kept, what is missing is said, exit 130, no process of the sweep is left. A rerun skips the
// finished run; SIGINT stops it the same way, even when the sweep was started with SIGINT
// ignored (a script's background job). A sweep killed outright (SIGKILL) leaves no run behind
// either (each has SIGINT as its parent-death signal).
TEST_F(SweepTest, AStopSignalEndsEveryRunKeepsTheFinishedAndSaysWhatIsMissing) {
  // The sink ends a run after `expect` samples; expect 0: the run lasts its (long) duration.
  const fs::path file = Write("sweep: s\ngraph: g.yaml\nduration: 1000000\ngrid: {sink.expect: [5, 0, 6]}\n");
  const std::vector<std::string> ids = Ids(file);
  ASSERT_EQ(ids.size(), 3u);
  const fs::path runs = dir_ / "o" / "runs";
  auto stop_when_second_runs = [&](int signal, const std::string& tag, std::string* out) {
    std::vector<std::string> argv = {std::string(DYAD_BIN_DIR) + "/dyad", "sweep", file.string(), "-o", (dir_ / "o").string(), "-j", "1",
                                     "--no-plots"};
    dyad::testing::ChildProcess p(argv, dir_, tag);
    for (int i = 0; i < 600 && !(fs::exists(runs / ids[0] / "metrics.json") && fs::exists(runs / ids[1] / "run.log")); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    EXPECT_GE(ProcessesNaming(runs.string()).size(), 1u) << "the second run is not running";
    p.Signal(signal);
    const int code = p.Wait(60);
    *out = p.out() + p.err();
    return code;
  };
  std::string out;
  EXPECT_EQ(stop_when_second_runs(SIGTERM, "term", &out), 130) << out;
  EXPECT_NE(out.find("stopped by SIGTERM: 1 ran, 0 done before, 0 failed, 2 runs missing:\n  " + ids[1] + " sink.expect=0 seed=1\n  " +
                     ids[2] + " sink.expect=6 seed=1\n"),
            std::string::npos)
      << out;
  std::vector<int> left = ProcessesNaming(dir_.string());
  EXPECT_TRUE(left.empty()) << left.size() << " processes of the sweep left";
  for (int pid : left) kill(pid, SIGKILL);
  EXPECT_TRUE(fs::exists(runs / ids[0] / "metrics.json"));
  EXPECT_FALSE(fs::exists(runs / ids[1] / "metrics.json"));
  EXPECT_FALSE(fs::exists(runs / ids[1] / "failed.txt")) << "a stopped run is missing, not failed";
  EXPECT_FALSE(fs::exists(runs / ids[2])) << "a run started after the stop";
  EXPECT_NE(ReadFile(dir_ / "o" / "sweep.csv").find(ids[1] + ",missing,"), std::string::npos);

  fs::remove(runs / ids[1] / "run.log");
  struct sigaction ignore {}, old {};
  ignore.sa_handler = SIG_IGN;
  sigaction(SIGINT, &ignore, &old);  // inherited by the sweep, as a script's background job
  const int code = stop_when_second_runs(SIGINT, "int", &out);
  sigaction(SIGINT, &old, nullptr);
  EXPECT_EQ(code, 130) << out;
  EXPECT_NE(out.find("stopped by SIGINT: 0 ran, 1 done before, 0 failed, 2 runs missing:"), std::string::npos) << out;
  left = ProcessesNaming(dir_.string());
  EXPECT_TRUE(left.empty()) << left.size() << " processes of the sweep left";
  for (int pid : left) kill(pid, SIGKILL);

  // The sweep killed outright: its run gets its parent-death signal and ends too.
  fs::remove(runs / ids[1] / "run.log");
  EXPECT_EQ(stop_when_second_runs(SIGKILL, "kill", &out), 128 + SIGKILL) << out;
  for (int i = 0; i < 300 && !ProcessesNaming(dir_.string()).empty(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  left = ProcessesNaming(dir_.string());
  EXPECT_TRUE(left.empty()) << left.size() << " processes of the sweep outlived it";
  for (int pid : left) kill(pid, SIGKILL);
}

// A study's condition as the base: the study's graph with the condition's overrides first (the
// sweep's own set: and grid after them), and the bad ways to name it.
TEST_F(SweepTest, AStudysConditionIsTheBase) {
  Write("study: st\ngraph: g.yaml\nparticipants: [P01, P02]\nconditions:\n  high: {src.start: 100}\n  low: {src.start: 0}\n",
        "st.yaml");
  const fs::path file = Write("sweep: s\nstudy: st.yaml\ncondition: high\nduration: 1\ngrid: {src.noise: [0, 1]}\n");
  std::string out;
  ASSERT_EQ(Sweep({file.string(), "--dry-run"}, &out), 0) << out;
  EXPECT_NE(out.find(" --set src.start=100 --set clock=stepped --set recorder.overwrite=true --set src.noise=0 --set seed=1\n"),
            std::string::npos)
      << out;
  ASSERT_EQ(Sweep({file.string(), "-o", (dir_ / "o").string(), "--no-plots"}, &out), 0) << out;
  EXPECT_NE(out.find("2 ran, 0 done before, 0 failed"), std::string::npos) << out;
  const std::string head = "sweep: s\nduration: 1\ngrid: {src.noise: [0]}\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {head + "study: st.yaml\ncondition: middle\n", "s.yaml:5:12: condition: the study st has no condition 'middle' (it has: high, low)"},
      {head + "graph: g.yaml\nstudy: st.yaml\ncondition: high\n", "s.yaml:5:8: study: give graph or study (with its condition), not both"},
      {head + "graph: g.yaml\ncondition: high\n", "s.yaml:5:12: condition: a condition is a study's: give study too"},
      {head + "study: nowhere.yaml\ncondition: high\n", "s.yaml:4:8: study: no such file"},
  };
  for (const auto& [text, expected] : cases) {
    EXPECT_EQ(Sweep({Write(text).string(), "--dry-run"}, &out), 2) << text;
    EXPECT_NE(out.find(expected), std::string::npos) << "for\n" << text << "expected '" << expected << "' in:\n" << out;
  }
}

// The demo graph with models the sweep trains (20 epochs: a fraction of a second each).
class TrainingSweepTest : public SweepTest {
 protected:
  void SetUp() override {
#ifdef DYAD_SANITIZED
    // Under sanitizers these tests cost a minute of CI (a model and an observer trained, then
    // the sweep's own) for code the other sweep tests and the trainer's tests run there already.
    GTEST_SKIP() << "trains models and runs the demo: left to the Release suite";
#endif
    SweepTest::SetUp();
    std::string out;
    ASSERT_EQ(Dyad({"generate", "dataset", "--out", (dir_ / "data").string()}, &out), 0) << out;
    // The observer the graph needs (trained on a model of its own).
    ASSERT_EQ(Dyad({"train", std::string(DYAD_SOURCE_DIR) + "/configs/train/demo.yaml", "--set", "dataset=" + (dir_ / "data").string(),
                    "--set", "output=" + (dir_ / "m.dpvrnn").string(), "--set", "epochs=20", "--set", "log_every=10"},
                   &out),
              0)
        << out;
    ASSERT_EQ(Dyad({"train-observer", (dir_ / "m.dpvrnn").string(), "-o", (dir_ / "o.dobs").string(), "--epochs", "20"}, &out), 0) << out;
  }
  int Dyad(const std::vector<std::string>& args, std::string* out) {
    std::vector<std::string> argv = {std::string(DYAD_BIN_DIR) + "/dyad"};
    argv.insert(argv.end(), args.begin(), args.end());
    dyad::testing::ChildProcess p(argv, dir_, "dyad" + std::to_string(runs_++));
    const int code = p.Wait(300);
    *out = p.out() + p.err();
    return code;
  }
  fs::path WriteSweep(const std::string& train_extra, const std::string& grid = "grid: {mixer.gain: [0.5]}\n") {
    const std::string repo = DYAD_SOURCE_DIR;
    return Write("sweep: t\ngraph: " + repo + "/configs/demo.yaml\nduration: 10\n"
                 "set: {human.dataset: " + (dir_ / "data").string() + ", observer.model: " + (dir_ / "o.dobs").string() + "}\n"
                 "train:\n  config: " + repo + "/configs/train/demo.yaml\n"
                 "  set: {dataset: " + (dir_ / "data").string() + ", epochs: 20, log_every: 10}\n" + train_extra + grid);
  }
};

TEST_F(TrainingSweepTest, OneModelPerTrainingValueCachedByContent) {
  const fs::path file = WriteSweep("  grid: {layers.0.w: [0.001, 0.01]}\n");
  std::string out;
  ASSERT_EQ(Sweep({file.string(), "-o", (dir_ / "o").string(), "--no-plots"}, &out), 0) << out;
  EXPECT_NE(out.find("2 runs of"), std::string::npos) << out;
  EXPECT_NE(out.find("with 2 trained models"), std::string::npos) << out;
  size_t models = 0;
  for (const auto& f : fs::directory_iterator(dir_ / "o" / "models")) models += f.path().extension() == ".dpvrnn";
  EXPECT_EQ(models, 2u);
  const std::string csv = ReadFile(dir_ / "o" / "sweep.csv");
  EXPECT_EQ(csv.rfind("run,status,train.layers.0.w,mixer.gain,seed,", 0), 0u) << csv;
  EXPECT_NE(csv.find(",ok,0.001,0.5,1,"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",ok,0.01,0.5,1,"), std::string::npos) << csv;
  // Again: nothing trains, nothing runs.
  ASSERT_EQ(Sweep({file.string(), "-o", (dir_ / "o").string(), "--no-plots"}, &out), 0) << out;
  EXPECT_EQ(out.find(": ok in"), std::string::npos) << "something ran again:\n" << out;
  EXPECT_NE(out.find("0 ran, 2 done before"), std::string::npos) << out;
  // The data set changed: new models, new runs (the old ones stay beside them).
  std::ofstream(dir_ / "data" / "notes.txt") << "a new file in the data set\n";
  ASSERT_EQ(Sweep({file.string(), "-o", (dir_ / "o").string(), "--no-plots"}, &out), 0) << out;
  EXPECT_NE(out.find("2 ran, 0 done before"), std::string::npos) << out;
  models = 0;
  for (const auto& f : fs::directory_iterator(dir_ / "o" / "models")) models += f.path().extension() == ".dpvrnn";
  EXPECT_EQ(models, 4u);
}

TEST_F(TrainingSweepTest, BadTrainingsAreRefusedAtTheirLine) {
  std::string out;
  const fs::path bad = WriteSweep("  model: mind.modl\n  grid:\n    layers.0.w: [0.001, -1]\n");
  EXPECT_EQ(Sweep({bad.string(), "-o", (dir_ / "o").string()}, &out), 2) << out;
  EXPECT_NE(out.find("s.yaml:8:10: train.model: the graph's mind has no parameter modl"), std::string::npos) << out;
  EXPECT_NE(out.find("s.yaml:10:25: train.grid.layers.0.w: does not train:\n--set layers.0.w=-1: layers[0].w: must be finite and >= 0"),
            std::string::npos)
      << out;
  const fs::path both = WriteSweep("", "grid: {mind.model: [x.dpvrnn]}\n");
  EXPECT_EQ(Sweep({both.string(), "-o", (dir_ / "o").string()}, &out), 2) << out;
  EXPECT_NE(out.find("grid.mind.model: the sweep trains the models of mind.model (train.model): sweep one or the other"),
            std::string::npos)
      << out;
  EXPECT_FALSE(fs::exists(dir_ / "o")) << "a refused sweep ran something";
}

// A Slurm task of runs does not train: a run without its model fails, saying which.
TEST_F(TrainingSweepTest, ARunWhoseModelDidNotTrainFailsSayingSo) {
  const fs::path file = WriteSweep("");
  std::string out;
  EXPECT_EQ(Sweep({file.string(), "-o", (dir_ / "o").string(), "--task", "0/1", "--no-plots"}, &out), 1) << out;
  bool said = false;
  for (const auto& run : fs::directory_iterator(dir_ / "o" / "runs"))
    said = said || ReadFile(run.path() / "failed.txt").find("was not trained") != std::string::npos;
  EXPECT_TRUE(said);
  ASSERT_EQ(Sweep({file.string(), "-o", (dir_ / "o").string(), "--train-only", "--task", "0/1"}, &out), 0) << out;
  EXPECT_NE(out.find("1 trained, 0 there before, 0 failed"), std::string::npos) << out;
  EXPECT_EQ(Sweep({file.string(), "-o", (dir_ / "o").string(), "--task", "0/1", "--no-plots"}, &out), 0) << out;
}

// The deliberator's preset is a parameter like any other: a sweep over dyad's error regression
// and NRL's (issue 44) runs both, and they are different robots (their N-ELBO, their following).
// A preset the deliberator lacks is refused at its line before anything runs.
TEST_F(TrainingSweepTest, APresetSweepRunsDyadsAndNrlsRegressionSideBySide) {
  const std::string repo = DYAD_SOURCE_DIR;
  const std::string head =
      "sweep: p\ngraph: " + repo + "/configs/demo.yaml\nduration: 10\nset: {human.dataset: " + (dir_ / "data").string() +
      ", observer.model: " + (dir_ / "o.dobs").string() + ", mind.model: " + (dir_ / "m.dpvrnn").string() + "}\n";
  std::string out;
  EXPECT_EQ(Sweep({Write(head + "grid:\n  mind.preset: [vcbot, nrl2]\n").string(), "--dry-run"}, &out), 2) << out;
  EXPECT_NE(out.find("s.yaml:6:24: grid.mind.preset: does not validate"), std::string::npos) << out;
  EXPECT_NE(out.find("must be one of: vcbot, reference, nrl, got 'nrl2'"), std::string::npos) << out;
  const fs::path file = Write(head + "grid:\n  mind.preset: [vcbot, nrl]\n");
  ASSERT_EQ(Sweep({file.string(), "-o", (dir_ / "o").string(), "--no-plots"}, &out), 0) << out;
  EXPECT_NE(out.find("2 ran, 0 done before, 0 failed"), std::string::npos) << out;
  std::istringstream csv(ReadFile(dir_ / "o" / "sweep.csv"));
  std::string header, line;
  std::getline(csv, header);
  ASSERT_EQ(header.rfind("run,status,mind.preset,seed,", 0), 0u) << header;
  std::map<std::string, std::vector<std::string>> metrics;  // preset -> its metrics (the cells after the seed)
  while (std::getline(csv, line)) {
    std::vector<std::string> cells;
    std::istringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    ASSERT_GT(cells.size(), 5u) << line;
    EXPECT_EQ(cells[1], "ok") << line;
    metrics[cells[2]].assign(cells.begin() + 4, cells.end());
  }
  ASSERT_EQ(metrics.size(), 2u);
  ASSERT_TRUE(metrics.count("vcbot") && metrics.count("nrl"));
  EXPECT_NE(metrics["vcbot"], metrics["nrl"]) << "the two presets ran the same robot";
  // Each run's log says which regression ran.
  int nrl = 0, vcbot = 0;
  for (const auto& run : fs::directory_iterator(dir_ / "o" / "runs")) {
    const std::string log = ReadFile(run.path() / "run.log");
    nrl += log.find(", preset nrl, window 5,") != std::string::npos;
    vcbot += log.find(", preset vcbot, window 5,") != std::string::npos;
  }
  EXPECT_EQ(nrl, 1);
  EXPECT_EQ(vcbot, 1);
}

TEST(SweepTask, ChunksHoldEveryRunOnceInOrder) {
  std::vector<sweep::SweepRun> runs(11);
  for (size_t i = 0; i < runs.size(); ++i) runs[i].id = std::to_string(i);
  for (int count : {1, 2, 3, 4, 11, 15}) {
    std::vector<std::string> seen;
    for (int i = 0; i < count; ++i) {
      const auto chunk = sweep::TaskChunk(runs, {i, count});
      EXPECT_LE(chunk.size(), runs.size() / static_cast<size_t>(count) + 1);
      for (const auto& r : chunk) seen.push_back(r.id);
    }
    ASSERT_EQ(seen.size(), runs.size()) << count << " tasks";
    for (size_t i = 0; i < runs.size(); ++i) EXPECT_EQ(seen[i], runs[i].id) << count << " tasks";
  }
  sweep::TaskSlice t;
  EXPECT_TRUE(sweep::ParseTask("3/4", &t).ok());
  EXPECT_EQ(t.index, 3);
  EXPECT_EQ(t.count, 4);
  for (const char* bad : {"4/4", "1/0", "-1/4", "1", "a/b", "1/4x", "", "/4"}) EXPECT_FALSE(sweep::ParseTask(bad, &t).ok()) << bad;
}

// What a Slurm array does, by hand: every task's chunk into one folder, then --collect.
TEST_F(SweepTest, TasksThenCollectGiveTheLocalTable) {
  const fs::path file = Write("sweep: s\ngraph: g.yaml\nduration: 1\ngrid:\n  src.start: [0, 100, 7]\nseeds: [1, 2]\n");
  std::string out;
  ASSERT_EQ(Sweep({file.string(), "-o", (dir_ / "local").string(), "--no-plots"}, &out), 0) << out;
  // Collected before any task ran, then with half of them: what is missing is said, exit 1.
  EXPECT_EQ(Sweep({file.string(), "-o", (dir_ / "tasks").string(), "--collect", "--no-plots"}, &out), 1) << out;
  EXPECT_NE(out.find("tasks: no runs in this folder"), std::string::npos) << out;
  for (int i = 0; i < 4; ++i) {
    if (i == 2) {
      EXPECT_FALSE(fs::exists(dir_ / "tasks" / "sweep.csv")) << "a task wrote the table (of its chunk only)";
      EXPECT_EQ(Sweep({file.string(), "-o", (dir_ / "tasks").string(), "--collect", "--no-plots"}, &out), 1) << out;
      EXPECT_NE(out.find("3 ok, 0 failed, 3 missing"), std::string::npos) << out;
      EXPECT_NE(ReadFile(dir_ / "tasks" / "sweep.csv").find(",missing,"), std::string::npos);
    }
    ASSERT_EQ(Sweep({file.string(), "-o", (dir_ / "tasks").string(), "--task", std::to_string(i) + "/4", "-j", "1"}, &out), 0) << out;
    EXPECT_NE(out.find(i % 2 == 0 ? "1 ran, 0 done before" : "2 ran, 0 done before"), std::string::npos) << out;
  }
  ASSERT_EQ(Sweep({file.string(), "-o", (dir_ / "tasks").string(), "--collect", "--no-plots"}, &out), 0) << out;
  EXPECT_NE(out.find("6 ok, 0 failed, 0 missing"), std::string::npos) << out;
  EXPECT_EQ(ReadFile(dir_ / "tasks" / "sweep.csv"), ReadFile(dir_ / "local" / "sweep.csv"));
  EXPECT_EQ(Sweep({file.string(), "--task", "4/4"}, &out), 2);
  EXPECT_NE(out.find("--task 4/4: want I/N with 0 <= I < N"), std::string::npos) << out;
}

// --slurm against a stand-in sbatch that logs its arguments: the scripts, then the array and the
// collect job after it. The real Slurm runs them in slurm_sweep_test.sh.
TEST_F(SweepTest, SlurmGetsAnArrayThenACollectJobThatWaitsForIt) {
  const fs::path file = Write("sweep: s\ngraph: g.yaml\nduration: 1\ngrid:\n  src.start: [0, 100, 7]\nseeds: [1, 2]\n");
  fs::create_directories(dir_ / "bin");
  Write("#!/bin/sh\necho \"$*\" >> " + (dir_ / "sbatch.calls").string() + "\necho 'sbatch: warning: a note'\n" +
            "n=$(wc -l < " + (dir_ / "sbatch.calls").string() + ")\necho \"$((41 + n));cluster\"\n",
        "bin/sbatch");
  fs::permissions(dir_ / "bin" / "sbatch", fs::perms::owner_all);
  const std::string path = "PATH=" + (dir_ / "bin").string() + ":/usr/bin:/bin";
  std::string out;
  ASSERT_EQ(Sweep({file.string(), "-o", (dir_ / "o").string(), "--slurm", "--tasks", "4", "--partition", "short", "--time",
                   "0:10:00", "--cpus-per-task", "2", "--sbatch-arg=--account=lab"},
                  &out, {path}),
            0)
      << out;
  EXPECT_NE(out.find("submitted: job 42 (4 array tasks"), std::string::npos) << out;
  EXPECT_NE(out.find("then job 43 writes"), std::string::npos) << out;
  const std::string calls = ReadFile(dir_ / "sbatch.calls");
  EXPECT_EQ(calls, "--parsable " + (dir_ / "o" / "slurm" / "runs.sbatch").string() + "\n--parsable --dependency=afterany:42 " +
                       (dir_ / "o" / "slurm" / "collect.sbatch").string() + "\n");
  const std::string runs = ReadFile(dir_ / "o" / "slurm" / "runs.sbatch");
  for (const std::string line : {"#SBATCH --array=0-3\n", "#SBATCH --partition=short\n", "#SBATCH --time=0:10:00\n",
                                 "#SBATCH --cpus-per-task=2\n", "#SBATCH --account=lab\n",
                                 " --task \"$SLURM_ARRAY_TASK_ID/4\" -j \"${SLURM_CPUS_PER_TASK:-1}\" -o "})
    EXPECT_NE(runs.find(line), std::string::npos) << line << " not in\n" << runs;
  EXPECT_NE(ReadFile(dir_ / "o" / "slurm" / "collect.sbatch").find(" --collect -o " + (dir_ / "o").string()), std::string::npos);
  // More tasks than runs: one per run.
  ASSERT_EQ(Sweep({file.string(), "-o", (dir_ / "p").string(), "--slurm", "--tasks", "50"}, &out, {path}), 0) << out;
  EXPECT_NE(ReadFile(dir_ / "p" / "slurm" / "runs.sbatch").find("#SBATCH --array=0-5\n"), std::string::npos);
}

TEST_F(SweepTest, SlurmNotReachableIsSaidInItsOwnWords) {
  const fs::path file = Write("sweep: s\ngraph: g.yaml\nduration: 1\ngrid:\n  src.start: [0]\n");
  std::string out;
  EXPECT_EQ(Sweep({file.string(), "-o", (dir_ / "o").string(), "--slurm"}, &out, {"PATH=" + (dir_ / "none").string()}), 1);
  EXPECT_NE(out.find("sbatch is not on PATH"), std::string::npos) << out;
  fs::create_directories(dir_ / "bin");
  Write("#!/bin/sh\necho 'sbatch: error: Batch job submission failed: Unable to contact slurm controller' >&2\nexit 1\n", "bin/sbatch");
  fs::permissions(dir_ / "bin" / "sbatch", fs::perms::owner_all);
  EXPECT_EQ(Sweep({file.string(), "-o", (dir_ / "o").string(), "--slurm"}, &out, {"PATH=" + (dir_ / "bin").string() + ":/usr/bin:/bin"}), 1);
  EXPECT_NE(out.find("failed (exit 1): sbatch: error: Batch job submission failed: Unable to contact slurm controller"), std::string::npos) << out;
  EXPECT_EQ(Sweep({file.string(), "--partition", "p"}, &out), 2) << "an option of --slurm without it";
  EXPECT_NE(out.find("--partition requires --slurm"), std::string::npos) << out;
}

// sweep.csv's status words, one table: each reads back to its value; another word is refused
// with the list (the plots pick rows by these words).
TEST(RunStatusWords, EveryStatusReadsBackAndOthersAreRefusedWithTheList) {
  using sweep::RunStatus;
  for (const RunStatus st : {RunStatus::kOk, RunStatus::kIncomplete, RunStatus::kFailed, RunStatus::kMissing}) {
    auto back = sweep::ParseRunStatus(sweep::ToString(st));
    ASSERT_TRUE(back.ok()) << sweep::ToString(st);
    EXPECT_EQ(*back, st);
  }
  EXPECT_EQ(sweep::ToString(RunStatus::kOk), "ok");  // what plot_sweep.py draws
  EXPECT_EQ(sweep::ParseRunStatus("done").status().message(), "must be ok, incomplete, failed or missing");
}

}  // namespace
}  // namespace dyad::cli
