// `dyad regress`: offline error regression over a CSV trajectory, run as a real process.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "dyad/pvrnn/model_file.hpp"

namespace fs = std::filesystem;

namespace {

struct Result {
  int exit_code = -1;
  std::string out, err;
};

class RegressCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("dyad_regress_test_" + std::to_string(getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    model_ = (dir_ / "m.dpvrnn").string();
    ASSERT_TRUE(dyad::pvrnn::SaveModel(dyad::pvrnn::Model::Initialize(dyad::pvrnn::ModelSpec::MacawBot(), 72, 7, 2), model_).ok());
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  std::string Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }
  static std::string Read(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }
  Result Run(const std::string& args) {
    const std::string cmd = std::string(DYAD_EXE) + " regress " + args + " > " + (dir_ / "out").string() + " 2> " +
                            (dir_ / "err").string();
    const int status = std::system(cmd.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, Read(dir_ / "out"), Read(dir_ / "err")};
  }
  std::string Circle(int steps) {
    std::string s;
    for (int t = 0; t < steps; ++t) s += std::to_string(20 * std::cos(t * 0.1)) + "," + std::to_string(20 * std::sin(t * 0.1)) + "\n";
    return s;
  }
  fs::path dir_;
  std::string model_;
};

TEST_F(RegressCommand, WritesOneRowPerExecutedStep) {
  const std::string traj = Write("t.csv", Circle(12));
  const std::string out = (dir_ / "r.csv").string();
  const Result r = Run(model_ + " " + traj + " -o " + out + " --window 4");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::istringstream lines(Read(out));
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line, "step,executed_x,executed_y,intended_x,intended_y,nelbo,reconstruction,regulation,iterations,evaluations,time_ms");
  std::getline(lines, line);
  EXPECT_EQ(line.rfind("-1,,,", 0), 0u) << line;
  int rows = 0;
  while (std::getline(lines, line)) {
    EXPECT_EQ(line.rfind(std::to_string(rows) + ",", 0), 0u) << line;
    EXPECT_NE(line.find(",15,16,"), std::string::npos) << line;  // 15 iterations, 16 evaluations (Adam)
    ++rows;
  }
  EXPECT_EQ(rows, 12);
}

TEST_F(RegressCommand, ReadsTheColumnsNamedXAndYOfABagExport) {
  const std::string traj = Write("state.csv",
                                 "log_time,publish_time,sequence,header.source,x,y,z\n"
                                 "1,1,1,drv,1.5,2.5,0\n2,2,2,drv,2.0,3.0,0\n3,3,3,drv,2.5,3.5,0\n");
  const Result r = Run(model_ + " " + traj + " --optimizer ceres --preset reference");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\n0,1.5,2.5,"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\n2,2.5,3.5,"), std::string::npos) << r.out;
}

// NRL's error regression (issue 44): free generation until the window holds W executed positions
// (no loss, no iterations), then 15 iterations per step.
TEST_F(RegressCommand, NrlPresetGeneratesFreelyUntilTheWindowIsFull) {
  const std::string traj = Write("t.csv", Circle(8));
  const Result r = Run(model_ + " " + traj + " --preset nrl --noise off");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::istringstream lines(r.out);
  std::string line;
  std::getline(lines, line);  // header
  std::getline(lines, line);  // the intention before step 0
  for (int step = 0; step < 8; ++step) {
    ASSERT_TRUE(std::getline(lines, line));
    EXPECT_EQ(line.rfind(std::to_string(step) + ",", 0), 0u) << line;
    if (step < 4) EXPECT_NE(line.find(",,,,0,0,"), std::string::npos) << line;
    else EXPECT_NE(line.find(",15,15,"), std::string::npos) << line;
  }
}

struct BadCase {
  std::string name, trajectory_text, extra_args, message;
};

TEST_F(RegressCommand, BadInputsExitWith2AndSayWhy) {
  const std::string good = Write("good.csv", Circle(3));
  const std::string not_model = Write("bad.dpvrnn", "nope");
  const std::vector<BadCase> cases = {
      {"not a number", "1,2\n3,x\n", "", ":2: x and y must be finite numbers, got '3', 'x'"},
      {"one column", "1,2\n3\n", "", ":2: expected at least 2 comma-separated values, got 1"},
      {"empty", "", "", ": no positions (expected x,y rows)"},
      {"header without y", "a,x,b\n1,2,3\n", "", ":1: header has no columns named x and y"},
      {"window 0", "", "--window 0", "--window: must be in 1..1000, got 0"},
      {"optimizer", "", "--optimizer lbfgs", "--optimizer lbfgs: must be adam or ceres"},
      {"meta-prior", "", "--meta-prior 1e-5", "--meta-prior: needs one value per layer (2), got 1"},
      {"lr", "", "--lr -2", "--lr: must be finite and > 0, got -2"},
      {"preset", "", "--preset fast", "--preset fast: must be vcbot, reference or nrl"},
      {"epsilon", "", "--epsilon 0", "--epsilon: must be finite and > 0, got 0"},
      {"nrl with ceres", "", "--preset nrl --optimizer ceres", "--optimizer: the nrl engine is NRL's Adam: must be adam"},
      {"nrl with fixed noise", "", "--preset nrl --noise fixed", "--noise: the nrl engine draws NRL's noise anew"},
      {"primitive", "", "--start-primitive 7", "--start-primitive 7: "},
  };
  for (const auto& c : cases) {
    std::string file = c.name;
    std::replace(file.begin(), file.end(), ' ', '_');
    const std::string traj = c.trajectory_text.empty() && c.name != "empty" ? good : Write(file + ".csv", c.trajectory_text);
    const Result r = Run(model_ + " " + traj + " " + c.extra_args);
    EXPECT_EQ(r.exit_code, 2) << c.name << ": " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.name << ": " << r.err;
  }
  Result r = Run(model_ + " " + (dir_ / "missing.csv").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("missing.csv: cannot open for reading"), std::string::npos) << r.err;
  r = Run(not_model + " " + good);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(not_model), std::string::npos) << r.err;
}

}  // namespace
