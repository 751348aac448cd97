// The learner with a fake context: demonstrations fed as HumanInput samples, the real `dyad train`
// as its trainer (a small model, a few hundred epochs), the data set and model read back from disk.
#include "learner.hpp"

#include <signal.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "dyad/pvrnn/dataset.hpp"
#include "dyad/pvrnn/model_file.hpp"
#include "dyad/testing/cdr.hpp"
#include "dyad/testing/fake_context.hpp"

namespace dyad::learner {
namespace {

namespace fs = std::filesystem;
using testing::FakeContext;

using testing::Cdr;

class LearnerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("dyad_learner_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    WriteConfig("epochs: 300\n");
  }
  void TearDown() override { fs::remove_all(dir_); }

  void WriteConfig(const std::string& extra) {
    std::ofstream(dir_ / "train.yaml") << "dataset: unused\nlayers:\n  - {d: 6, z: 1, tau: 2, w: 0.01}\n"
                                          "encoding: {dofs: [[-50, 50], [-50, 50]], dsoft: 10, sigma: 0.2}\n"
                                          "adam: {lr: 0.01, beta1: 0.9, beta2: 0.999}\nseed: 1\nscalar: float\nlog_every: 50\n"
                                          "output: unused.dpvrnn\n"
                                       << extra;
  }

  std::unique_ptr<FakeContext> MakeContext(std::map<std::string, ParamValue> params) {
    params.emplace("train", (dir_ / "train.yaml").string());
    params.emplace("out", (dir_ / "runs").string());
    params.emplace("trainer", std::string(DYAD_EXE));
    auto ctx = std::make_unique<FakeContext>(&Learner::Describe, params);
    ctx->set_graph_yaml("components: {mind: {type: deliberator}, learner: {type: learner}}\n");
    ctx->stepped_clock = true;
    human_ = &ctx->Feed<msg::HumanInput>("human");
    model_ = &ctx->Feed<msg::ModelInfo>("model");
    status_ = &ctx->Capture<msg::LearnerStatus>("status");
    requests_ = &ctx->Capture<msg::ParamChange>("requests");
    return ctx;
  }

  // One engaged segment: `n` samples of a circle of radius r around (cx, 0), then one released.
  void Draw(double cx, double r, int n) {
    for (int i = 0; i <= n; ++i) {
      msg::HumanInput h;
      h.header().stamp_ns(t_ns_);
      t_ns_ += 100'000'000;
      const double a = 2 * M_PI * i / n;
      h.x(cx + r * std::cos(a));
      h.y(r * std::sin(a));
      h.engaged(i < n);
      human_->queue.push_back(h);
    }
  }

  // One demonstration, then "learn all" and the step that applies it (under the stepped clock
  // the training ends inside that step).
  void DrawOneAndLearnIt(Learner& learner, FakeContext& ctx) {
    Draw(0, 10, 20);
    StepOnce(learner, ctx);
    ASSERT_TRUE(ctx.SetLive("learn", std::string("all")).ok());
    StepOnce(learner, ctx);
  }

  void StepOnce(Learner& learner, FakeContext& ctx, int64_t dt_ns = 100'000'000) {
    ctx.clock_.now += dt_ns;
    ctx.PollInputs();
    ASSERT_TRUE(learner.Step({ctx.clock_.now, step_++, 100'000'000}).ok());
  }

  fs::path dir_;
  int64_t t_ns_ = 1'000'000'000;
  uint64_t step_ = 0;
  testing::QueueReader<msg::HumanInput>* human_ = nullptr;
  testing::QueueReader<msg::ModelInfo>* model_ = nullptr;
  testing::CapturingWriter<msg::LearnerStatus>* status_ = nullptr;
  testing::CapturingWriter<msg::ParamChange>* requests_ = nullptr;
};

TEST_F(LearnerTest, CutsTheChosenDemonstrationsTrainsAndSwapsTheModelIn) {
  auto ctx = MakeContext({});
  Learner learner;
  ASSERT_TRUE(learner.Configure(*ctx).ok());
  Draw(-20, 10, 20);
  Draw(0, 5, 4);  // too short: not a demonstration
  Draw(20, 8, 30);
  Draw(0, 15, 25);
  StepOnce(learner, *ctx);
  const msg::LearnerStatus& idle = status_->samples.back();
  EXPECT_EQ(idle.state(), "idle");
  EXPECT_EQ(idle.component_name(), "under_test");
  ASSERT_EQ(idle.segment_start_s().size(), 3u);
  EXPECT_NEAR(idle.segment_start_s()[1], 2.6, 1e-9);  // 21 + 5 samples of 0.1 s after the first
  EXPECT_NEAR(idle.segment_duration_s()[1], 2.9, 1e-9);

  ASSERT_TRUE(ctx->SetLive("learn", std::string("2,0")).ok());
  StepOnce(learner, *ctx);  // the stepped clock waited for the trainer: trained, swap asked
  ASSERT_EQ(requests_->samples.size(), 1u);
  const msg::ParamChange& ask = requests_->samples[0];
  const msg::LearnerStatus& swapping = status_->samples.back();
  EXPECT_EQ(swapping.state(), "swapping") << swapping.message();
  EXPECT_EQ(swapping.run(), 1u);
  EXPECT_EQ(swapping.chosen(), (std::vector<int32_t>{2, 0}));
  EXPECT_EQ(swapping.epoch(), 300u);
  EXPECT_EQ(swapping.epochs(), 300u);
  EXPECT_TRUE(std::isfinite(swapping.loss()));
  EXPECT_EQ(ask.component_name(), "mind");
  EXPECT_EQ(ask.param_name(), "model");
  EXPECT_EQ(ask.op(), "set");
  EXPECT_EQ(YAML::Load(ask.value()).as<std::string>(), swapping.model()) << ask.value();  // a YAML string, read back
  EXPECT_EQ(fs::path(swapping.model()).parent_path(), fs::path(swapping.folder()));
  EXPECT_EQ(fs::path(swapping.folder()).parent_path(), dir_ / "runs");

  // Read back: the data set holds demonstration 2 then 0, 72 steps each, ends kept exactly.
  auto data = pvrnn::LoadNrlDataset(swapping.folder() + "/dataset");
  ASSERT_TRUE(data.ok()) << data.status().message();
  ASSERT_EQ(data->size(), 2);
  EXPECT_EQ(data->sequences[0].cols(), 72);
  EXPECT_NEAR(data->sequences[0](0, 0), 15, 1e-6);   // (0 + 15 cos 0, 0)
  EXPECT_NEAR(data->sequences[1](0, 0), -10, 1e-6);  // (-20 + 10, 0)
  auto model = pvrnn::LoadModel(swapping.model());
  ASSERT_TRUE(model.ok()) << model.status().message();

  // The deliberator says it steers with it: done.
  msg::ModelInfo other, info;
  other.path("/elsewhere/model.dpvrnn");
  info.path(swapping.model());
  info.step(42);
  model_->queue.push_back(other);
  model_->queue.push_back(info);
  StepOnce(learner, *ctx);
  const msg::LearnerStatus& done = status_->samples.back();
  EXPECT_EQ(done.state(), "done");
  EXPECT_NE(done.message().find("from step 42"), std::string::npos) << done.message();
  EXPECT_TRUE(std::isnan(done.since_demonstration_s())) << "no wall-clock times under the stepped clock";
  EXPECT_EQ(fs::path(done.folder()).filename(), "learn-1") << "no time in the folder's name under the stepped clock";
  EXPECT_TRUE(learner.Deactivate().ok());
}

TEST_F(LearnerTest, RefusesWhatItCannotLearnSayingWhy) {
  auto ctx = MakeContext({});
  Learner learner;
  ASSERT_TRUE(learner.Configure(*ctx).ok());
  EXPECT_NE(ctx->SetLive("learn", std::string("all")).message().find("no engaged segment of at least 10 samples"), std::string::npos);
  Draw(0, 10, 20);
  Draw(0, 10, 8);  // not a demonstration
  StepOnce(learner, *ctx);
  EXPECT_NE(ctx->SetLive("learn", std::string("0,1")).message().find("learn: no segment 1; the session has 1"), std::string::npos);
  EXPECT_NE(ctx->SetLive("learn", std::string("two")).message().find("say \"all\""), std::string::npos);
  EXPECT_NE(ctx->SetLive("learn", std::string("0,")).message().find("say \"all\""), std::string::npos);
  EXPECT_EQ(ctx->SetLive("swap_in", std::string("yes")).message(), "no trained model waits for its swap (the learner is idle)");
  EXPECT_FALSE(fs::exists(dir_ / "runs")) << "a refused run leaves nothing";
  EXPECT_TRUE(requests_->samples.empty());
}

TEST_F(LearnerTest, BadParamsAreSaidByName) {
  Learner a;
  auto ctx = MakeContext({{"target", std::string("brain.model")}});
  EXPECT_EQ(a.Configure(*ctx).message(), "params.target: no component 'brain' in the graph");
  Learner b;
  ctx = MakeContext({{"target", std::string("mind")}});
  EXPECT_EQ(b.Configure(*ctx).message(), "params.target: must be COMPONENT.PARAM, got \"mind\"");
  Learner c;
  ctx = MakeContext({{"train", (dir_ / "nope.yaml").string()}});
  EXPECT_NE(c.Configure(*ctx).message().find("params.train: " + (dir_ / "nope.yaml").string()), std::string::npos);
  Learner d;
  ctx = MakeContext({{"trainer", (dir_ / "no-dyad").string()}});
  EXPECT_EQ(d.Configure(*ctx).message(), "params.trainer: no dyad executable at \"" + (dir_ / "no-dyad").string() + "\"");
}

TEST_F(LearnerTest, AFailingTrainerIsSaidAndNothingIsSwapped) {
  WriteConfig("epochs: 300\nbogus_key: 1\n");
  auto ctx = MakeContext({});
  Learner learner;
  ASSERT_TRUE(learner.Configure(*ctx).ok());
  DrawOneAndLearnIt(learner, *ctx);
  const msg::LearnerStatus& failed = status_->samples.back();
  EXPECT_EQ(failed.state(), "failed");
  EXPECT_NE(failed.message().find("the trainer exited with code 2: error: "), std::string::npos) << failed.message();
  EXPECT_NE(failed.message().find("bogus_key"), std::string::npos) << failed.message();
  EXPECT_TRUE(requests_->samples.empty());
  // The next run may start (and fails the same way).
  EXPECT_TRUE(ctx->SetLive("learn", std::string("all")).ok());
}

TEST_F(LearnerTest, OnTheButtonTheModelWaitsForSwapIn) {
  auto ctx = MakeContext({{"swap", std::string("button")}, {"epochs", int64_t{50}}});
  Learner learner;
  ASSERT_TRUE(learner.Configure(*ctx).ok());
  DrawOneAndLearnIt(learner, *ctx);
  EXPECT_EQ(status_->samples.back().state(), "trained");
  EXPECT_EQ(status_->samples.back().epochs(), 50u);
  EXPECT_TRUE(requests_->samples.empty());
  ASSERT_TRUE(ctx->SetLive("swap_in", std::string("now")).ok());
  StepOnce(learner, *ctx);
  ASSERT_EQ(requests_->samples.size(), 1u);
  EXPECT_EQ(status_->samples.back().state(), "swapping");
}

// The wall clock: the trainer runs beside the steps; stopping the graph stops it.
TEST_F(LearnerTest, OnTheWallClockTheTrainingRunsBesideTheStepsAndStopsWithTheGraph) {
  WriteConfig("epochs: 100000000\n");
  auto ctx = MakeContext({});
  ctx->stepped_clock = false;
  Learner learner;
  ASSERT_TRUE(learner.Configure(*ctx).ok());
  Draw(0, 10, 20);
  StepOnce(learner, *ctx);
  ASSERT_TRUE(ctx->SetLive("learn", std::string("all")).ok()) << "asked from the test's thread";
  for (int i = 0; i < 200 && status_->samples.back().epoch() == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    StepOnce(learner, *ctx);
  }
  const msg::LearnerStatus& training = status_->samples.back();
  EXPECT_EQ(training.state(), "training");
  EXPECT_GT(training.epoch(), 0u) << "the log shows progress while it trains";
  EXPECT_EQ(training.epochs(), 100000000u);
  EXPECT_NE(ctx->SetLive("learn", std::string("all")).message().find("one run at a time"), std::string::npos);
  EXPECT_TRUE(learner.Deactivate().ok());
  std::string log;
  std::getline(std::ifstream(training.folder() + "/train.log"), log, '\0');
  EXPECT_NE(log.find("interrupted"), std::string::npos) << log;  // stopped as by Ctrl-C: its checkpoint saved
}

// Stopping the graph right after a run started stops its trainer. The trainer's pid used to be
// set by the thread that started it, and a Deactivate before that skipped the stop and waited
// the whole training out (here: a trainer that would take 20 s, and says so when it ends).
TEST_F(LearnerTest, ADeactivateRightAfterTheStartStopsTheTraining) {
  const fs::path trainer = dir_ / "slow-trainer", finished = dir_ / "finished";
  std::ofstream(trainer) << "#!/bin/sh\nsleep 20\ntouch '" << finished.string() << "'\n";
  fs::permissions(trainer, fs::perms::owner_all);
  auto ctx = MakeContext({{"trainer", trainer.string()}});
  ctx->stepped_clock = false;
  Learner learner;
  ASSERT_TRUE(learner.Configure(*ctx).ok());
  Draw(0, 10, 20);
  StepOnce(learner, *ctx);
  ASSERT_TRUE(ctx->SetLive("learn", std::string("all")).ok());
  EXPECT_TRUE(learner.Deactivate().ok());
  EXPECT_FALSE(fs::exists(finished)) << "the training was waited out, not stopped";
}

// The deliberator refuses the model (on dyad/params, answering the learner's request): the run
// fails with its reason and the next one may start; an answer to another request changes nothing.
TEST_F(LearnerTest, ARefusedSwapFailsTheRunWithTheReason) {
  auto ctx = MakeContext({});
  Learner learner;
  ASSERT_TRUE(learner.Configure(*ctx).ok());
  DrawOneAndLearnIt(learner, *ctx);
  ASSERT_EQ(requests_->samples.size(), 1u);
  msg::ParamChange answer;
  answer.op("refused");
  answer.request_id("someone else's");
  answer.reason("not this one");
  ctx->Deliver("dyad/params", Cdr(answer));
  StepOnce(learner, *ctx);
  EXPECT_EQ(status_->samples.back().state(), "swapping");
  answer.request_id(requests_->samples[0].request_id());
  answer.reason("params.model: needs 2 layers");
  ctx->Deliver("dyad/params", Cdr(answer));
  StepOnce(learner, *ctx);
  EXPECT_EQ(status_->samples.back().state(), "failed");
  EXPECT_EQ(status_->samples.back().message(), "mind.model refused the model: params.model: needs 2 layers");
  EXPECT_TRUE(ctx->SetLive("learn", std::string("all")).ok());
}

TEST_F(LearnerTest, ASwapNobodyAnswersFailsAfterAMinute) {
  auto ctx = MakeContext({});
  Learner learner;
  ASSERT_TRUE(learner.Configure(*ctx).ok());
  DrawOneAndLearnIt(learner, *ctx);
  StepOnce(learner, *ctx, 59'000'000'000);
  EXPECT_EQ(status_->samples.back().state(), "swapping");
  StepOnce(learner, *ctx, 2'000'000'000);
  EXPECT_EQ(status_->samples.back().state(), "failed");
  EXPECT_NE(status_->samples.back().message().find("no word in 60 s from mind"), std::string::npos);
}

// The runtime may commit a live param on a thread that then ends; the trainer must not end with
// it (PR_SET_PDEATHSIG follows the thread that forked).
TEST_F(LearnerTest, TheTrainerOutlivesTheThreadThatAskedForIt) {
  WriteConfig("epochs: 3000\n");
  auto ctx = MakeContext({});
  ctx->stepped_clock = false;
  Learner learner;
  ASSERT_TRUE(learner.Configure(*ctx).ok());
  Draw(0, 10, 20);
  StepOnce(learner, *ctx);
  Status asked;
  std::thread([&] { asked = ctx->SetLive("learn", std::string("all")); }).join();
  ASSERT_TRUE(asked.ok()) << asked.message();
  StepOnce(learner, *ctx);
  for (int i = 0; i < 600 && status_->samples.back().state() == "training"; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    StepOnce(learner, *ctx);
  }
  const msg::LearnerStatus swapping = status_->samples.back();
  EXPECT_EQ(swapping.state(), "swapping") << swapping.message();
  EXPECT_EQ(swapping.epoch(), 3000u);
  EXPECT_GT(swapping.elapsed_s(), 0);
  // On the wall clock "done" says how long after the last demonstration the new model steers.
  msg::ModelInfo info;
  info.path(swapping.model());
  model_->queue.push_back(info);
  StepOnce(learner, *ctx);
  EXPECT_EQ(status_->samples.back().state(), "done");
  EXPECT_GT(status_->samples.back().since_demonstration_s(), swapping.elapsed_s()) << "the request came after the demonstration";
}

TEST(TrainingLog, TakesEpochsAndLossFromLinesAsTheyComplete) {
  const fs::path f = fs::temp_directory_path() / ("dyad_training_log_" + std::to_string(::getpid()));
  std::ofstream(f) << "training /a to b/data (2 sequences x 72 steps) from epoch 0 to 500, float, seed 1\nepoch 10/500  RE_Q 3  loss ";
  TrainingLog log;
  log.Update(f.string());
  EXPECT_EQ(log.epochs, 500);
  EXPECT_EQ(log.epoch, 0);
  EXPECT_TRUE(std::isnan(log.loss));
  std::ofstream(f, std::ios::app) << "12.5  2.1 ms/epoch  ETA 1s\nerror: something\nlater\n";
  log.Update(f.string());
  EXPECT_EQ(log.epoch, 10);
  EXPECT_DOUBLE_EQ(log.loss, 12.5);
  EXPECT_EQ(log.last_line, "later");
  EXPECT_EQ(log.last_error, "error: something");
  fs::remove(f);
}

}  // namespace
}  // namespace dyad::learner
