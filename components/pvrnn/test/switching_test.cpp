// The study's switching experiment with the MacawBot model (issue 4): the robot starts drawing
// the head (primitive 1) while the human replays the beak (primitive 2) for 100 steps through the
// compliance blend (executed = previous + clip(0.9 * beak + 0.1 * robot - previous, +-5) per
// axis), then lets go (executed = previous + clip(robot - previous, +-5)) for 100 steps.
//
// "Follows" a primitive: the robot's last 8 intended positions are nearest (RMS) to 8 consecutive
// steps of that primitive in the data set (any phase; of the 7). Reported per (preset, optimiser): the step
// the intention first follows the beak, the share of the human's 100 steps it follows the beak
// and in how many bursts, and the share of the 100 steps after release it follows the head.
// The robot first draws one head alone (72 steps, kLeadIn) so that the window has left the
// initial state (see WithoutLeadIn... below). Set DYAD_SWITCH_TRACE=1 to print every step.
// Reference implementation (issue 4): VCBot settings switch after 7-41 steps, in bursts, and
// mostly return to the head after release; window 15 / lr 0.1 never switches.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "dyad/pvrnn/dataset.hpp"
#include "dyad/pvrnn/error_regression.hpp"
#include "dyad/pvrnn/nrl_import.hpp"
#include "test_paths.hpp"

namespace dyad::pvrnn {
namespace {

using testing::VcbotDir;

constexpr int kLeadIn = 72;  // the robot draws one head alone before the human engages
constexpr int kHead = 1, kBeak = 2, kHumanSteps = 100, kReleaseSteps = 100, kRecent = 8;

struct SwitchFigures {
  int first_follow = -1;     // human-phase step at which the robot first follows the beak (-1: never)
  int beak_steps = 0;        // human-phase steps following the beak
  int bursts = 0;            // separate runs of following the beak in the human phase
  int head_after_release = 0;  // release-phase steps following the head
  double ms_median = 0;
};

class Switching : public ::testing::Test {
 protected:
  void SetUp() override {
    DYAD_REQUIRE_VCBOT();
    auto m = ImportNrlModel({VcbotDir() + "/model/MacawBot", VcbotDir() + "/config/properties_MacawBot.d",
                             VcbotDir() + "/dataset/Macaw"});
    ASSERT_TRUE(m.ok()) << m.status().message();
    model_ = std::move(m.value());
    auto d = LoadNrlDataset(VcbotDir() + "/dataset/Macaw");
    ASSERT_TRUE(d.ok()) << d.status().message();
    data_ = std::move(d.value());
  }

  // The primitive whose stretch of kRecent consecutive data-set steps (any phase, cyclic) is
  // nearest (RMS) to the robot's last kRecent intended positions. Shapes, not just places: the
  // head and the beak touch, so a position alone is often ambiguous.
  int Nearest(const std::vector<Eigen::Vector2d>& recent) const {
    int best = -1;
    double best_d = std::numeric_limits<double>::infinity();
    const int n = static_cast<int>(recent.size());
    for (int p = 0; p < data_.size(); ++p) {
      const Eigen::MatrixXd& seq = data_.sequences[p];
      const int T = static_cast<int>(seq.cols());
      for (int phase = 0; phase < T; ++phase) {
        double sum = 0;
        for (int i = 0; i < n; ++i) sum += (seq.col((phase + i) % T) - recent[i]).squaredNorm();
        if (sum < best_d) best_d = sum, best = p;
      }
    }
    return best;
  }

  SwitchFigures Run(const ErrorRegressionOptions& o, int lead_in = kLeadIn, double gain = 0.9) {
    auto er = ErrorRegression<float>::Create(model_, o).value();
    EXPECT_TRUE(er->Reset(kHead, 1).ok());
    const Eigen::MatrixXd& beak = data_.sequences[kBeak];
    Eigen::Vector2d executed(er->intention()[0], er->intention()[1]);
    std::vector<Eigen::Vector2d> recent;
    std::vector<double> ms;
    SwitchFigures f;
    bool following = false;
    for (int i = -lead_in; i < kHumanSteps + kReleaseSteps; ++i) {
      const int t = i;
      const Eigen::Vector2d robot(er->intention()[0], er->intention()[1]);
      recent.push_back(robot);
      if (recent.size() > kRecent) recent.erase(recent.begin());
      const int cls = Nearest(recent);
      if (t < 0) {
      } else if (t < kHumanSteps) {
        if (cls == kBeak && f.first_follow < 0) f.first_follow = t;
        if (cls == kBeak) ++f.beak_steps;
        if (cls == kBeak && !following) ++f.bursts;
        following = cls == kBeak;
      } else if (cls == kHead) {
        ++f.head_after_release;
      }
      const Eigen::Vector2d target =
          t >= 0 && t < kHumanSteps ? Eigen::Vector2d(gain * beak.col(t % beak.cols()) + (1 - gain) * robot) : robot;
      executed += (target - executed).cwiseMax(-5.0).cwiseMin(5.0);
      const StepResult& r = er->Step(executed.data());
      if (t >= 0) ms.push_back(1e3 * r.optimisation_s);
      if (std::getenv("DYAD_SWITCH_TRACE") != nullptr)
        std::printf("t %3d robot %6.1f %6.1f executed %6.1f %6.1f class %2d loss %.4f -> %.4f\n", t, robot.x(),
                    robot.y(), executed.x(), executed.y(), cls, r.initial_loss, r.loss.loss);
    }
    std::nth_element(ms.begin(), ms.begin() + ms.size() / 2, ms.end());
    f.ms_median = ms[ms.size() / 2];
    return f;
  }

  static void Print(const char* name, const SwitchFigures& f) {
    std::printf("%-40s first follows beak at step %3d | beak %3d/100 steps in %2d bursts | head after release %3d/100 | %.3f ms/step\n",
                name, f.first_follow, f.beak_steps, f.bursts, f.head_after_release, f.ms_median);
  }

  Model model_;
  Dataset data_;
};

ErrorRegressionOptions With(ErrorRegressionOptions o, OptimizerKind k) {
  o.optimizer = k;
  return o;
}

// The study's settings: with both optimisers the robot follows the beak after a few steps of
// the human's push and returns to the head after release.
TEST_F(Switching, VcbotSettingsFollowTheBeakWithinBoundedStepsAndReturnToTheHead) {
  for (auto kind : {OptimizerKind::kAdam, OptimizerKind::kCeres}) {
    const SwitchFigures f = Run(With(ErrorRegressionOptions::Vcbot(), kind));
    Print((std::string("vcbot / ") + ToString(kind)).c_str(), f);
    EXPECT_GE(f.first_follow, 1) << ToString(kind);
    EXPECT_LE(f.first_follow, 45) << ToString(kind);
    EXPECT_GE(f.beak_steps, 50) << ToString(kind);
    EXPECT_GE(f.head_after_release, 50) << ToString(kind);
  }
}

// Window 15 / lr 0.1 / the training meta-prior: Adam never lets the human switch it (as the
// reference implementation); Ceres, a stronger optimiser at the same iteration count, is reported.
TEST_F(Switching, ReferenceSettingsKeepTheHeadWithAdam) {
  const SwitchFigures adam = Run(ErrorRegressionOptions::Reference());
  Print("reference / adam", adam);
  EXPECT_EQ(adam.first_follow, -1);
  const SwitchFigures ceres = Run(With(ErrorRegressionOptions::Reference(), OptimizerKind::kCeres));
  Print("reference / ceres", ceres);
}

// Without a lead-in the growing window still reaches back to the zero initial state, where
// the first steps' A choose the primitive: the robot re-selects the beak at once.
TEST_F(Switching, WithoutLeadInTheWindowReselectsThePrimitiveAtOnce) {
  const SwitchFigures f = Run(ErrorRegressionOptions::Vcbot(), /*lead_in=*/0);
  Print("vcbot / adam, no lead-in", f);
  EXPECT_LE(f.first_follow, 3);
}

// The head as drawn by the data set, pushed 10 units right from step 20: both optimisers lower
// the window loss of every solve (best iterate vs start point), clearly so (>= 30%) when the push
// arrives. (Each later solve starts from the previous optimum, so it has less left to gain; a
// shifted head is outside the model's repertoire, so the loss stays well above zero.)
TEST_F(Switching, BothOptimisersLowerTheWindowLossOnAPushedPrimitive) {
  for (auto kind : {OptimizerKind::kAdam, OptimizerKind::kCeres}) {
    auto er = ErrorRegression<float>::Create(model_, With(ErrorRegressionOptions::Vcbot(), kind)).value();
    ASSERT_TRUE(er->Reset(kHead, 1).ok());
    double first = 0, best = 0, push_drop = 0;
    for (int t = 0; t < 60; ++t) {
      const Eigen::Vector2d xy = data_.sequences[kHead].col(t) + Eigen::Vector2d(t >= 20 ? 10.0 : 0.0, 0.0);
      const StepResult& r = er->Step(xy.data());
      EXPECT_LE(r.loss.loss, r.initial_loss);
      if (std::getenv("DYAD_SWITCH_TRACE")) std::printf("t %d %.4f -> %.4f\n", t, r.initial_loss, r.loss.loss);
      if (t >= 20) first += r.initial_loss, best += r.loss.loss;
      if (t == 20) push_drop = 1 - r.loss.loss / r.initial_loss;
    }
    std::printf("%s: window loss at the push -%.0f%%, summed over the pushed steps %.4f -> %.4f\n", ToString(kind),
                100 * push_drop, first, best);
    EXPECT_GE(push_drop, 0.3) << ToString(kind);
    EXPECT_LT(best, first) << ToString(kind);
  }
}

// An undisturbed robot draws the head throughout (the classifier's baseline).
TEST_F(Switching, WithoutTheHumanTheRobotKeepsTheHead) {
  const SwitchFigures f = Run(ErrorRegressionOptions::Vcbot(), kLeadIn, /*gain=*/0.0);
  EXPECT_EQ(f.beak_steps, 0);
  EXPECT_EQ(f.head_after_release, 100);
}

// Not a check: prints the figures for presets x a_init x noise x optimiser, with and without the
// lead-in and the human (how the defaults and the docs' statements were chosen). Run with
// DYAD_SWITCH_EXPLORE=1 dyad_pvrnn_test --gtest_filter=Switching.Explore
TEST_F(Switching, Explore) {
  if (std::getenv("DYAD_SWITCH_EXPLORE") == nullptr) GTEST_SKIP() << "exploration; set DYAD_SWITCH_EXPLORE=1 to run";
  for (int lead : {0, kLeadIn})
    for (double gain : {0.0, 0.9})
      for (const char* preset : {"vcbot", "reference"})
        for (auto init : {AInit::kZero, AInit::kCopy, AInit::kPrior})
          for (auto noise : {NoiseMode::kOff, NoiseMode::kFixed, NoiseMode::kResample})
            for (auto opt : {OptimizerKind::kAdam, OptimizerKind::kCeres}) {
              ErrorRegressionOptions o = *ErrorRegressionOptions::Preset(preset);
              o.a_init = init;
              o.noise = noise;
              o.optimizer = opt;
              char name[96];
              std::snprintf(name, sizeof name, "lead %2d g %.1f %-9s %-5s %-8s %-5s", lead, gain, preset, ToString(init),
                            ToString(noise), ToString(opt));
              Print(name, Run(o, lead, gain));
            }
}

}  // namespace
}  // namespace dyad::pvrnn
