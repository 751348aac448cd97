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
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

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

  // jitter_seed > 0: N(0, 1e-5) added to every executed position the robot receives (seeded), as
  // bench/pvrnn/nrl_er_harness.cpp --jitter 1e-5 --seed S does for NRL's ensemble.
  SwitchFigures Run(const ErrorRegressionOptions& o, int lead_in = kLeadIn, double gain = 0.9, unsigned jitter_seed = 0,
                    uint64_t noise_seed = 1) {
    auto er = ErrorRegression<float>::Create(model_, o).value();
    EXPECT_TRUE(er->Reset(kHead, noise_seed).ok());
    const Eigen::MatrixXd& beak = data_.sequences[kBeak];
    Eigen::Vector2d executed(er->intention()[0], er->intention()[1]);
    std::vector<Eigen::Vector2d> recent;
    std::vector<double> ms;
    std::mt19937 rng(jitter_seed);
    std::normal_distribution<double> jitter(0.0, 1e-5);
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
      Eigen::Vector2d sent = executed;
      if (jitter_seed > 0) sent += Eigen::Vector2d(jitter(rng), jitter(rng));
      const StepResult& r = er->Step(sent.data());
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

// Issue 44, test (b): over an ensemble of slightly perturbed inputs (20 closed-loop runs, N(0, 1e-5)
// jitter on the executed positions, seeds 1..20) dyad's NRL mode (noise off) switches like NRL
// itself: the step it first follows the beak and its beak steps of 100 are indistinguishable from
// NRL's ensemble (test/data/nrl/nrl_ensemble.csv: NRL -O3 and -O3 -march=native, made by
// NRL_ENSEMBLE=20 bench/pvrnn/nrl_reference.sh) by a Mann-Whitney rank-sum test (normal
// approximation with the tie correction). Its false-alarm rate is calibrated on NRL against
// itself: over 2000 random 20/20 splits of NRL's 40 runs, the critical p is the 5th percentile of
// the splits' p-values (a difference of builds alone is rejected 5 % of the time).
struct EnsembleRun {
  int first = 0, beak = 0;
};

// Two-sided p of the Mann-Whitney U test, normal approximation with the tie correction.
double MannWhitneyP(const std::vector<double>& a, const std::vector<double>& b) {
  std::vector<std::pair<double, int>> all;
  for (double v : a) all.push_back({v, 0});
  for (double v : b) all.push_back({v, 1});
  std::sort(all.begin(), all.end());
  const double n1 = static_cast<double>(a.size()), n2 = static_cast<double>(b.size()), n = n1 + n2;
  double rank_a = 0, ties = 0;
  for (size_t i = 0; i < all.size();) {
    size_t j = i;
    while (j < all.size() && all[j].first == all[i].first) ++j;
    const double rank = (static_cast<double>(i + j) + 1) / 2, t = static_cast<double>(j - i);
    for (size_t k = i; k < j; ++k)
      if (all[k].second == 0) rank_a += rank;
    ties += t * t * t - t;
    i = j;
  }
  const double u = rank_a - n1 * (n1 + 1) / 2, mean = n1 * n2 / 2;
  const double var = n1 * n2 / 12 * ((n + 1) - ties / (n * (n - 1)));
  if (var <= 0) return 1.0;
  const double z = (std::abs(u - mean) - 0.5) / std::sqrt(var);  // continuity correction
  return std::erfc(std::max(z, 0.0) / std::sqrt(2.0));
}

std::vector<double> Column(const std::vector<EnsembleRun>& runs, bool first) {
  std::vector<double> out;
  for (const EnsembleRun& r : runs) out.push_back(first ? (r.first < 0 ? 100 : r.first) : r.beak);  // never: past the push
  return out;
}

// The 5th percentile of the p-values of random 20/20 splits of `pool` (NRL against itself).
double CriticalP(const std::vector<double>& pool, size_t n) {
  std::mt19937 rng(44);
  std::vector<double> ps, v = pool;
  for (int k = 0; k < 2000; ++k) {
    std::shuffle(v.begin(), v.end(), rng);
    ps.push_back(MannWhitneyP({v.begin(), v.begin() + n}, {v.begin() + n, v.end()}));
  }
  std::sort(ps.begin(), ps.end());
  return ps[ps.size() / 20];
}

std::vector<EnsembleRun> ReadNrlEnsemble(const std::string& build) {
  std::ifstream in(std::string(DYAD_PVRNN_TEST_DATA_DIR) + "/nrl/nrl_ensemble.csv");
  std::vector<EnsembleRun> out;
  std::string line;
  std::getline(in, line);  // build,seed,first_follow,beak_steps,bursts,head_after_release
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string b, seed, first, beak;
    std::getline(ss, b, ',');
    std::getline(ss, seed, ',');
    std::getline(ss, first, ',');
    std::getline(ss, beak, ',');
    if (b == build) out.push_back({first == "never" ? -1 : std::stoi(first), std::stoi(beak)});
  }
  return out;
}

// Not asserted (one run of a chaotic system): the NRL mode's single closed-loop runs next to NRL's
// (docs/pvrnn.md: noise 0, the committed nrl_er_closed.csv: first follows the beak at step 24, 28
// steps in 4 bursts, head 84 after release; NRL's published noise, seed 0: 22, 24 in 5, 92).
TEST_F(Switching, NrlModeSingleRuns) {
  ErrorRegressionOptions o = ErrorRegressionOptions::Preset("nrl").value();
  o.noise = NoiseMode::kOff;
  Print("nrl mode, noise off (NRL: 24, 28 in 4, 84)", Run(o));
  o.noise = NoiseMode::kResample;
  Print("nrl mode, NRL's noise, seed 0 (NRL: 22, 24 in 5, 92)", Run(o, kLeadIn, 0.9, 0, 0));
}

TEST_F(Switching, NrlModeSwitchesLikeNrlOverAnEnsemble) {
  const std::vector<EnsembleRun> o3 = ReadNrlEnsemble("O3"), native = ReadNrlEnsemble("O3-native");
  ASSERT_EQ(o3.size(), 20u);
  ASSERT_EQ(native.size(), 20u);
  ErrorRegressionOptions o = ErrorRegressionOptions::Preset("nrl").value();
  o.noise = NoiseMode::kOff;            // as NRL's traces
  std::vector<EnsembleRun> mode, dyad;  // the NRL mode, and dyad's default engine (vcbot)
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const SwitchFigures f = Run(o, kLeadIn, 0.9, seed), g = Run(ErrorRegressionOptions::Vcbot(), kLeadIn, 0.9, seed);
    mode.push_back({f.first_follow, f.beak_steps});
    dyad.push_back({g.first_follow, g.beak_steps});
  }
  for (bool first : {true, false}) {
    std::vector<double> pool = Column(o3, first);
    for (double v : Column(native, first)) pool.push_back(v);
    const double critical = CriticalP(pool, 20);
    const double p_builds = MannWhitneyP(Column(o3, first), Column(native, first));
    const double p_mode = MannWhitneyP(Column(mode, first), Column(o3, first));
    const double p_dyad = MannWhitneyP(Column(dyad, first), Column(o3, first));
    std::vector<double> m = Column(mode, first), r = Column(o3, first);
    std::nth_element(m.begin(), m.begin() + 10, m.end());
    std::nth_element(r.begin(), r.begin() + 10, r.end());
    std::printf(
        "%s: NRL mode median %.0f, NRL -O3 median %.0f; p (mode vs NRL -O3) %.3f, p (NRL -O3 vs -O3 -march=native) %.3f, "
        "p (vcbot preset vs NRL -O3) %.2g, critical p %.3f\n",
        first ? "first follows beak" : "beak steps of 100", m[10], r[10], p_mode, p_builds, p_dyad, critical);
    EXPECT_GT(p_builds, critical) << "NRL's two builds should not be told apart";
    EXPECT_GT(p_mode, critical) << (first ? "first follows beak" : "beak steps");
    EXPECT_LT(p_dyad, critical) << "the test should tell dyad's default engine from NRL";
  }
}

}  // namespace
}  // namespace dyad::pvrnn
