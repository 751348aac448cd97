// The scripted human: tracing, disengagement, lag, noise determinism.
#include <gtest/gtest.h>

#include "dyad/human_input/synthetic_human.hpp"

namespace dyad::human_input {
namespace {

// Two primitives of 4 steps: primitive p at step t is (10p + t, -t).
pvrnn::Dataset Tiny() {
  pvrnn::Dataset d;
  for (int p = 0; p < 2; ++p) {
    Eigen::MatrixXd s(2, 4);
    for (int t = 0; t < 4; ++t) s.col(t) << 10.0 * p + t, -t;
    d.sequences.push_back(s);
  }
  return d;
}

std::vector<InterventionEvent> Events() { return {{3, 9, 1}, {12, 14, 0}}; }

TEST(SyntheticHuman, TracesThePrimitiveDuringEventsAndLoopsIt) {
  SyntheticHuman h(Tiny(), Events(), {});
  std::vector<HumanSample> s;
  for (int k = 0; k < 16; ++k) s.push_back(h.Step(k));
  for (int k = 3; k < 9; ++k) {
    EXPECT_TRUE(s[k].engaged) << k;
    EXPECT_EQ(s[k].event, 0);
    EXPECT_DOUBLE_EQ(s[k].x, 10.0 + (k - 3) % 4) << k;  // loops after 4 steps
    EXPECT_DOUBLE_EQ(s[k].y, -((k - 3) % 4)) << k;
  }
  EXPECT_DOUBLE_EQ(s[12].x, 0.0);
  EXPECT_DOUBLE_EQ(s[13].x, 1.0);
  EXPECT_EQ(s[13].event, 1);
}

TEST(SyntheticHuman, IsDisengagedOutsideEventsAtTheLastPosition) {
  SyntheticHuman h(Tiny(), Events(), {.noise_std = 0.3, .lag = 0, .seed = 5});
  std::vector<HumanSample> s;
  for (int k = 0; k < 16; ++k) s.push_back(h.Step(k));
  for (int k : {0, 1, 2}) {  // before the first event: the first event's primitive's start point
    EXPECT_FALSE(s[k].engaged);
    EXPECT_EQ(s[k].event, -1);
    EXPECT_DOUBLE_EQ(s[k].x, 10.0);
    EXPECT_DOUBLE_EQ(s[k].y, 0.0);
  }
  for (int k : {9, 10, 11}) {  // after event 0: where the (noisy) trace ended, no new noise
    EXPECT_FALSE(s[k].engaged);
    EXPECT_EQ(s[k].x, s[8].x);
    EXPECT_EQ(s[k].y, s[8].y);
  }
  EXPECT_FALSE(s[14].engaged);
  EXPECT_EQ(s[15].x, s[13].x);
}

TEST(SyntheticHuman, LagDelaysTheTraceByThatManySteps) {
  SyntheticHuman plain(Tiny(), Events(), {});
  SyntheticHuman lagged(Tiny(), Events(), {.noise_std = 0, .lag = 2, .seed = 1});
  std::vector<HumanSample> a, b;
  for (int k = 0; k < 9; ++k) {
    a.push_back(plain.Step(k));
    b.push_back(lagged.Step(k));
  }
  // Engaged at the same steps; holds the first point for `lag` steps, then follows 2 behind.
  for (int k = 3; k < 9; ++k) EXPECT_TRUE(b[k].engaged);
  EXPECT_DOUBLE_EQ(b[3].x, 10.0);
  EXPECT_DOUBLE_EQ(b[4].x, 10.0);
  for (int k = 5; k < 9; ++k) {
    EXPECT_DOUBLE_EQ(b[k].x, a[k - 2].x) << k;
    EXPECT_DOUBLE_EQ(b[k].y, a[k - 2].y) << k;
  }
}

TEST(SyntheticHuman, NoiseIsDeterministicPerSeedWithTheRequestedSpread) {
  auto run = [](uint64_t seed) {
    SyntheticHuman h(Tiny(), {{0, 4000, 0}}, {.noise_std = 2.0, .lag = 0, .seed = seed});
    std::vector<double> dx;
    for (int k = 0; k < 4000; ++k) dx.push_back(h.Step(k).x - (k % 4));
    return dx;
  };
  const auto a = run(7), b = run(7), c = run(8);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  double m = 0, v = 0;
  for (double d : a) m += d;
  m /= a.size();
  for (double d : a) v += (d - m) * (d - m);
  EXPECT_NEAR(std::sqrt(v / a.size()), 2.0, 0.1);
  EXPECT_NEAR(m, 0.0, 0.15);
}

}  // namespace
}  // namespace dyad::human_input
