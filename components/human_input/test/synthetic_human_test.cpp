// The scripted human: tracing, disengagement, lag, noise determinism, self-reports.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

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

// Seven primitives (as the study's data set has) of 4 steps each.
pvrnn::Dataset Seven() {
  pvrnn::Dataset d;
  for (int p = 0; p < 7; ++p) d.sequences.push_back(Eigen::MatrixXd::Constant(2, 4, p));
  return d;
}

TEST(SyntheticHuman, ReleasesEachEventAtItsEndAndReportsItsPrimitive) {
  // Back to back: event 1 ends where event 2 starts, at step 16.
  SyntheticHuman h(Tiny(), {{3, 9, 1}, {12, 16, 0}, {16, 18, 1}}, {});
  std::vector<std::pair<int64_t, ReleasedEvent>> released;
  for (int64_t k = 0; k < 25; ++k)
    for (const ReleasedEvent& r : h.Step(k).released) released.push_back({k, r});
  ASSERT_EQ(released.size(), 3u);
  const std::vector<std::array<int64_t, 4>> want = {{9, 0, 1, 1}, {16, 1, 0, 0}, {18, 2, 1, 1}};  // step, event, truth, answer
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(released[i].first, want[i][0]) << i;
    EXPECT_EQ(released[i].second.event, want[i][1]) << i;
    EXPECT_EQ(released[i].second.primitive, want[i][2]) << i;
    EXPECT_EQ(released[i].second.answer, want[i][3]) << i;
  }
}

// 4000 one-step events: the wrong answers' share is the configured probability (within 4 standard
// deviations of the binomial), a wrong answer is never the truth, and the six others are about
// equally likely.
TEST(SyntheticHuman, WrongSelfReportsComeAtTheConfiguredRateSpreadOverTheOtherPrimitives) {
  std::vector<InterventionEvent> events;
  for (int i = 0; i < 4000; ++i) events.push_back({2 * i, 2 * i + 1, i % 7});
  for (const double p : {0.0, 0.2, 1.0}) {
    SyntheticHuman h(Seven(), events, {.noise_std = 0, .lag = 0, .seed = 3, .report_error = p});
    int reports = 0, wrong = 0;
    std::array<int, 7> offset{};  // (answer - truth) mod 7 of the wrong answers
    for (int64_t k = 0; k <= 8000; ++k)
      for (const ReleasedEvent& r : h.Step(k).released) {
        ++reports;
        if (r.answer == r.primitive) continue;
        ++wrong;
        ASSERT_GE(r.answer, 0);
        ASSERT_LT(r.answer, 7);
        ++offset[static_cast<size_t>((r.answer - r.primitive + 7) % 7)];
      }
    ASSERT_EQ(reports, 4000);
    EXPECT_NEAR(wrong / 4000.0, p, 4 * std::sqrt(p * (1 - p) / 4000)) << p;
    EXPECT_EQ(offset[0], 0);
    for (int o = 1; o < 7 && wrong > 0; ++o) EXPECT_NEAR(offset[static_cast<size_t>(o)], wrong / 6.0, wrong / 6.0 * 0.3) << p << " offset " << o;
  }
}

TEST(SyntheticHuman, AskingForWrongReportsLeavesTheTrackAsItWas) {
  SyntheticHuman a(Tiny(), Events(), {.noise_std = 1.0, .lag = 1, .seed = 9});
  SyntheticHuman b(Tiny(), Events(), {.noise_std = 1.0, .lag = 1, .seed = 9, .report_error = 0.7});
  for (int64_t k = 0; k < 40; ++k) {
    const HumanSample x = a.Step(k), y = b.Step(k);
    EXPECT_EQ(x.x, y.x) << k;
    EXPECT_EQ(x.y, y.y) << k;
    EXPECT_EQ(x.released.size(), y.released.size()) << k;
  }
}

}  // namespace
}  // namespace dyad::human_input
