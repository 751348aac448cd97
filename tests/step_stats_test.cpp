#include <gtest/gtest.h>

#include <random>

#include "exec/step_stats.hpp"

namespace dyad {
namespace {

TEST(StepStats, BucketsCoverTheirValues) {
  for (int64_t v : {0LL, 1LL, 15LL, 16LL, 17LL, 1000LL, 123456789LL, 1LL << 40}) {
    const int b = StepStats::Bucket(v);
    EXPECT_GE(StepStats::BucketUpper(b), v) << v;
    if (b > 0) {
      EXPECT_LT(StepStats::BucketUpper(b - 1), v) << v;
    }
  }
}

TEST(StepStats, PercentileWithinSixPercentOfExact) {
  StepStats s;
  std::mt19937 rng(3);
  std::lognormal_distribution<double> dist(10.0, 1.0);
  std::vector<int64_t> v;
  for (int i = 0; i < 10000; ++i) {
    v.push_back(static_cast<int64_t>(dist(rng)));
    s.Record(v.back(), 0, false);
  }
  std::sort(v.begin(), v.end());
  const double exact = static_cast<double>(v[static_cast<size_t>(std::ceil(0.99 * v.size())) - 1]) * 1e-9;
  const auto snap = s.Get();
  EXPECT_EQ(snap.steps, 10000u);
  EXPECT_NEAR(snap.p99_s, exact, exact * 0.0625);
  EXPECT_GE(snap.p99_s, exact);
  EXPECT_DOUBLE_EQ(snap.max_s, static_cast<double>(v.back()) * 1e-9);
}

TEST(StepStats, CountsMissesAndJitter) {
  StepStats s;
  s.Record(10, 100, false);
  s.Record(10, 300, true);
  const auto snap = s.Get();
  EXPECT_EQ(snap.deadline_misses, 1u);
  EXPECT_DOUBLE_EQ(snap.jitter_mean_s, 200e-9);
  EXPECT_DOUBLE_EQ(snap.jitter_max_s, 300e-9);
}

}  // namespace
}  // namespace dyad
