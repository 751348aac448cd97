// dyad's NRL mode (engine nrl, preset "nrl") against NRL itself (issue 44, test (a)): on the
// committed trace of NRL's online ER (test/data/nrl/nrl_er_fixed.csv, made by
// bench/pvrnn/nrl_reference.sh from oist-cnru/NRL 42395a2 with its noise set to 0; MacawBot,
// VCBot settings, start on the head, a fixed executed trajectory), dyad's NRL mode with noise off
// is fed the same executed positions and must reproduce, at every step inside NRL's own
// reproducibility horizon, the intention within 1e-4 workspace units and e_postdict's loss,
// reconstruction and regulation within 1e-4 relative. The horizon: NRL's own builds (CMake
// defaults, -O3, -O3 -march=native) agree within 5e-5 only through run index 12 (the first
// 13 steps: free generation for 4, then 9 postdictions with 8 slides; docs/pvrnn.md); beyond it
// float rounding is amplified by Adam with epsilon 1e-20 and NRL's builds diverge from each other.
// The largest deviation per quantity is printed (the note quotes it).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "dyad/pvrnn/error_regression.hpp"
#include "dyad/pvrnn/nrl_import.hpp"
#include "dyad/pvrnn/nrl_regression.hpp"
#include "test_paths.hpp"

namespace dyad::pvrnn {
namespace {

using testing::VcbotDir;

constexpr int kHorizon = 13;  // run indices 0..12: inside NRL's own reproducibility horizon
constexpr int kHead = 1;

struct TraceRow {
  int step = 0;
  double executed[2] = {0, 0};
  double intention[2] = {0, 0};
  std::optional<double> loss, reconstruction, regulation;
  std::vector<double> a;  // the kept A: per layer, slot (oldest first): mu..., log sigma...
};

std::vector<TraceRow> ReadTrace(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::vector<TraceRow> rows;
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    TraceRow r;
    r.step = std::stoi(cells.at(0));
    r.executed[0] = std::stod(cells.at(1)), r.executed[1] = std::stod(cells.at(2));
    r.intention[0] = std::stod(cells.at(3)), r.intention[1] = std::stod(cells.at(4));
    if (cells.size() > 5 && !cells[5].empty()) {
      r.loss = std::stod(cells[5]), r.reconstruction = std::stod(cells[6]), r.regulation = std::stod(cells[7]);
      for (size_t i = 8; i < cells.size(); ++i) r.a.push_back(std::stod(cells[i]));
    }
    rows.push_back(r);
  }
  return rows;
}

double Relative(double got, double want) { return std::abs(got - want) / std::max(std::abs(want), 1e-30); }

struct Deviations {
  double intention = 0, loss = 0, reconstruction = 0, regulation = 0, a = 0;
  int postdictions = 0;
};

class NrlMode : public ::testing::Test {
 protected:
  void SetUp() override {
    DYAD_REQUIRE_VCBOT();
    auto m = ImportNrlModel(
        {VcbotDir() + "/model/MacawBot", VcbotDir() + "/config/properties_MacawBot.d", VcbotDir() + "/dataset/Macaw"});
    ASSERT_TRUE(m.ok()) << m.status().message();
    model_ = std::move(m.value());
    trace_ = ReadTrace(std::string(DYAD_PVRNN_TEST_DATA_DIR) + "/nrl/nrl_er_fixed.csv");
    ASSERT_GE(trace_.size(), static_cast<size_t>(kHorizon));
  }

  static ErrorRegressionOptions NrlNoNoise() {
    ErrorRegressionOptions o = ErrorRegressionOptions::Preset("nrl").value();
    o.noise = NoiseMode::kOff;  // the traces were made with NRL's noise set to 0
    return o;
  }

  // The largest deviations from the trace over run indices [0, steps), through ErrorRegression
  // (the path the deliberator, dyad regress and dyad sweep take).
  Deviations Compare(const ErrorRegressionOptions& o, int steps, bool print_each) {
    return Compare(o, trace_, steps, print_each);
  }
  Deviations Compare(const ErrorRegressionOptions& o, const std::vector<TraceRow>& trace, int steps, bool print_each) {
    auto er = ErrorRegression<float>::Create(model_, o).value();
    EXPECT_TRUE(er->Reset(kHead, 0).ok());
    Deviations dev;
    for (int i = 0; i < steps; ++i) {
      const TraceRow& row = trace[i];
      const double di =
          std::max(std::abs(er->intention()[0] - row.intention[0]), std::abs(er->intention()[1] - row.intention[1]));
      dev.intention = std::max(dev.intention, di);
      const StepResult& r = er->Step(row.executed);
      double dl = 0;
      if (row.loss) {
        EXPECT_TRUE(r.regressed || o.engine == Engine::kDyad) << "index " << i;
        ++dev.postdictions;
        dl = Relative(r.loss.loss, *row.loss);
        dev.loss = std::max(dev.loss, dl);
        dev.reconstruction = std::max(dev.reconstruction, Relative(r.loss.reconstruction, *row.reconstruction));
        dev.regulation = std::max(dev.regulation, Relative(r.loss.regulation, *row.regulation));
      } else if (o.engine == Engine::kNrl) {
        EXPECT_FALSE(r.regressed) << "index " << i << ": NRL generates freely until the window is full";
      }
      if (print_each)
        std::printf("  index %3d (step %4d): intention %.3g, loss %.3g rel (%.6g %.6g %.6g vs %.6g)\n", i, row.step, di, dl,
                    r.loss.loss, r.loss.reconstruction, r.loss.regulation, row.loss.value_or(0));
    }
    return dev;
  }

  Model model_;
  std::vector<TraceRow> trace_;
};

TEST_F(NrlMode, ReproducesNrlsTraceInsideNrlsOwnHorizon) {
  const Deviations dev = Compare(NrlNoNoise(), kHorizon, false);
  std::printf(
      "NRL mode vs NRL (nrl_er_fixed.csv), run indices 0..%d, %d postdictions: largest deviation: intention %.3g "
      "units, loss %.3g, reconstruction %.3g, regulation %.3g (relative)\n",
      kHorizon - 1, dev.postdictions, dev.intention, dev.loss, dev.reconstruction, dev.regulation);
  EXPECT_EQ(dev.postdictions, kHorizon - 4);
  EXPECT_LT(dev.intention, 1e-4);
  EXPECT_LT(dev.loss, 1e-4);
  EXPECT_LT(dev.reconstruction, 1e-4);
  EXPECT_LT(dev.regulation, 1e-4);
}

// The window's A as NRL keeps it (one Adam step past the best loss) matches too; A is where
// rounding shows first (NRL's builds differ by up to 3.8e-3 in A inside the horizon).
TEST_F(NrlMode, KeepsNrlsA) {
  NrlRegression er(model_, NrlNoNoise(), {1e-5, 1e-5});
  er.Reset(kHead, 0);
  double dev = 0;
  for (int i = 0; i < kHorizon; ++i) {
    const TraceRow& row = trace_[i];
    er.Step(row.executed);
    if (!row.loss) continue;
    size_t c = 0;
    for (int l = 0; l < 2; ++l)
      for (int s = 0; s < 5; ++s) {
        for (float v : er.kept_mu(l, s)) dev = std::max(dev, std::abs(v - row.a.at(c++)));
        for (float v : er.kept_log_sigma(l, s)) dev = std::max(dev, std::abs(v - row.a.at(c++)));
      }
    ASSERT_EQ(c, row.a.size());
  }
  std::printf("NRL mode vs NRL, run indices 0..%d: largest deviation of the kept A %.3g\n", kHorizon - 1, dev);
  EXPECT_LT(dev, 1e-2);
}

// The test discriminates: dyad's default engine (vcbot preset) regresses from step 0, from the
// prior's A, with Adam restarted every step, and misses NRL's trace inside the same horizon.
TEST_F(NrlMode, TheDefaultPresetDoesNotReproduceNrl) {
  ErrorRegressionOptions o = ErrorRegressionOptions::Vcbot();
  const Deviations dev = Compare(o, kHorizon, false);
  std::printf("vcbot preset (dyad engine) vs NRL, run indices 0..%d: intention %.3g units, loss %.3g relative\n", kHorizon - 1,
              dev.intention, dev.loss);
  EXPECT_GT(std::max(dev.intention, dev.loss), 1e-4);
}

// Beyond the horizon NRL does not reproduce itself; printed for the note (DYAD_NRL_TRACE=1 prints
// every step), not asserted.
TEST_F(NrlMode, PrintsTheDeviationBeyondTheHorizon) {
  const int steps = std::min<int>(40, static_cast<int>(trace_.size()));
  const Deviations dev = Compare(NrlNoNoise(), steps, std::getenv("DYAD_NRL_TRACE") != nullptr);
  std::printf("NRL mode vs NRL, run indices 0..%d: largest deviation: intention %.3g units, loss %.3g relative\n", steps - 1,
              dev.intention, dev.loss);
}

// NRL's noise (std::normal_distribution<float> over std::default_random_engine seeded 0, drawn for
// prior and posterior in every pass and in generation): with the same standard library the mode
// draws the same numbers in the same order. Trace: the first 30 steps of NRL's fixed trajectory
// with its published noise (NRL_NOISE=1 bench/pvrnn/nrl_reference.sh; nrl_er_fixed_noise.csv).
// The horizon is one step shorter than without noise (run indices 0..11, 8 postdictions): at index
// 12 the intention is 1.6e-4 apart (the loss terms 2e-9); NRL's own horizon with noise was not
// measured (its builds were compared with noise 0). The intention's horizon depends on the
// compiler, as NRL's own does: built with clang 14 -O1 (the sanitizer build), the intention is
// 1.7e-4 apart already at index 7 (0.9e-3 at 11) while the loss terms stay within 1e-5 relative
// through index 11. So the intention is held to 1e-4 over indices 0..6 (the free steps and the
// first three postdictions), the loss terms over 0..11, with either compiler.
TEST_F(NrlMode, ReproducesNrlsNoiseWithTheSameStandardLibrary) {
#ifndef __GLIBCXX__
  GTEST_SKIP() << "NRL's draws are libstdc++'s";
#endif
  const std::vector<TraceRow> trace = ReadTrace(std::string(DYAD_PVRNN_TEST_DATA_DIR) + "/nrl/nrl_er_fixed_noise.csv");
  constexpr int kNoiseHorizon = kHorizon - 1;
  ASSERT_GE(trace.size(), static_cast<size_t>(kNoiseHorizon));
  const Deviations dev =
      Compare(ErrorRegressionOptions::Preset("nrl").value(), trace, kNoiseHorizon, std::getenv("DYAD_NRL_TRACE") != nullptr);
  std::printf(
      "NRL mode with NRL's noise vs NRL (nrl_er_fixed_noise.csv), run indices 0..%d: intention %.3g units, loss %.3g, "
      "reconstruction %.3g, regulation %.3g (relative)\n",
      kNoiseHorizon - 1, dev.intention, dev.loss, dev.reconstruction, dev.regulation);
  EXPECT_LT(dev.loss, 1e-4);
  EXPECT_LT(dev.reconstruction, 1e-4);
  EXPECT_LT(dev.regulation, 1e-4);
  constexpr int kNoiseIntentionHorizon = 7;
  const Deviations early = Compare(ErrorRegressionOptions::Preset("nrl").value(), trace, kNoiseIntentionHorizon, false);
  std::printf("... run indices 0..%d: intention %.3g units\n", kNoiseIntentionHorizon - 1, early.intention);
  EXPECT_LT(early.intention, 1e-4);
}

TEST(NrlModeOptions, RefusesWhatNrlDoesNotHave) {
  ErrorRegressionOptions o = ErrorRegressionOptions::Preset("nrl").value();
  EXPECT_EQ(o.engine, Engine::kNrl);
  EXPECT_EQ(o.adam.epsilon, 1e-20);
  EXPECT_TRUE(o.Validate(2).ok());
  o.optimizer = OptimizerKind::kCeres;
  EXPECT_NE(o.Validate(2).message().find("optimizer"), std::string::npos) << o.Validate(2).message();
  o.optimizer = OptimizerKind::kAdam;
  o.noise = NoiseMode::kFixed;
  EXPECT_NE(o.Validate(2).message().find("noise"), std::string::npos) << o.Validate(2).message();
  EXPECT_EQ(ParseEngine("nrl"), Engine::kNrl);
  EXPECT_EQ(ParseEngine("dyad"), Engine::kDyad);
  EXPECT_FALSE(ParseEngine("NRL").has_value());
}

}  // namespace
}  // namespace dyad::pvrnn
