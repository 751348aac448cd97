// `dyad train-observer` and `dyad evaluate-observer` through their CLI: the exit codes and
// messages docs/components.md promises (0 ok, 1 failure such as --min-diagonal, 2 bad input),
// on an untrained MacawBot-shaped model and the analytic data set.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "dyad/observer/observer_file.hpp"
#include "dyad/pvrnn/analytic_dataset.hpp"
#include "dyad/pvrnn/dataset.hpp"
#include "dyad/pvrnn/model_file.hpp"
#include "dyad/testing/cli.hpp"
#include "observer_commands.hpp"

namespace dyad::cli {
namespace {

namespace fs = std::filesystem;

const fs::path& Dir() {
  static const fs::path dir = [] {
    fs::path d = fs::temp_directory_path() / ("dyad_observer_commands_" + std::to_string(getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    EXPECT_TRUE(pvrnn::SaveModel(pvrnn::Model::Initialize(pvrnn::ModelSpec::MacawBot(), 72, 7, 3),
                                 (d / "m.dpvrnn").string()).ok());
    EXPECT_TRUE(pvrnn::WriteNrlDataset(pvrnn::MakeAnalyticDataset(), (d / "data").string()).ok());
    return d;
  }();
  return dir;
}

using dyad::testing::CliRun;

CliRun Cli(std::vector<std::string> args) { return dyad::testing::RunCommand(AddObserverCommands, std::move(args)); }

std::string Model() { return (Dir() / "m.dpvrnn").string(); }

TEST(TrainObserverCli, WritesTheFileAndExitsOneBelowMinDiagonal) {
  const std::string out = (Dir() / "sub" / "o.dobs").string();
  // An untrained model and 1 epoch cannot reach a diagonal of 1.01: exit 1, file written anyway.
  const CliRun r = Cli({"train-observer", Model(), "-o", out, "--epochs", "1", "--steps", "40", "--drop", "5",
                     "--min-diagonal", "1.01"});
  EXPECT_EQ(r.code, 1) << r.out << r.err;
  EXPECT_NE(r.err.find("is below --min-diagonal 1.0100"), std::string::npos) << r.err;
  auto file = observer::LoadObserver(out);
  ASSERT_TRUE(file.ok()) << file.status().message();
  EXPECT_EQ(file->provenance.steps, 40);
  EXPECT_EQ(file->provenance.drop, 5);
  EXPECT_EQ(file->classifier.spec().classes, 7);
}

TEST(TrainObserverCli, BadInputExitsTwoNamingTheOption) {
  const std::string out = (Dir() / "bad.dobs").string();
  CliRun r = Cli({"train-observer", Model(), "-o", out, "--seeds", "1,2", "--validation-seeds", "2,9"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--validation-seeds: seed 2 is also a training seed"), std::string::npos) << r.err;
  r = Cli({"train-observer", Model(), "-o", out, "--steps", "20", "--drop", "20"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--drop 20"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--steps 20"), std::string::npos) << r.err;
  r = Cli({"train-observer", (Dir() / "none.dpvrnn").string(), "-o", out});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("none.dpvrnn"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(EvaluateObserverCli, PrintsOneTablePerNoiseLevel) {
  const std::string obs = (Dir() / "eval.dobs").string();
  ASSERT_EQ(Cli({"train-observer", Model(), "-o", obs, "--epochs", "1", "--steps", "40", "--drop", "5"}).code, 0);
  const CliRun r = Cli({"evaluate-observer", obs, "--dataset", (Dir() / "data").string(), "--noise", "0,1"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("noise std 0 "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("noise std 1 "), std::string::npos) << r.out;
}

// A bad --noise anywhere in the list is rejected before any table is printed.
TEST(EvaluateObserverCli, NegativeNoiseIsRejectedBeforeAnyOutput) {
  const std::string obs = (Dir() / "eval2.dobs").string();
  ASSERT_EQ(Cli({"train-observer", Model(), "-o", obs, "--epochs", "1", "--steps", "40", "--drop", "5"}).code, 0);
  const CliRun r = Cli({"evaluate-observer", obs, "--dataset", (Dir() / "data").string(), "--noise", "1,-1"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--noise -1: must be >= 0"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
}

}  // namespace
}  // namespace dyad::cli
