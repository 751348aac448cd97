// tools/study/bootstrap.hpp: a percentile bootstrap confidence interval of a mean, for the
// per-condition summaries of `dyad study analyze` (trials are few and their distribution unknown).
//
//   MeanInterval ci = BootstrapMean({0.61, 0.72, 0.58}, /*seed=*/7);   // ci.mean, ci.low, ci.high
//
// Contract: NaN values are left out (a trial without the measure); `n` counts the rest. With none,
// every field but n is NaN. The interval is the (1-level)/2 and (1+level)/2 quantiles (type 1:
// the smallest resampled mean at or above that fraction) of the means of `resamples` resamples
// with replacement, drawn from one std::mt19937_64 seeded with `seed` (indices from its raw
// output, not a library's distribution): the same values and seed give the same interval on any
// machine. One value: [it, it]. `level` outside (0, 1) is taken as 0.95; `resamples` < 1 as 1.
#pragma once

#include <cstdint>
#include <vector>

namespace dyad::study {

struct MeanInterval {
  double mean, low, high;
  int n = 0;
};

MeanInterval BootstrapMean(const std::vector<double>& values, uint64_t seed, int resamples = 4000, double level = 0.95);

}  // namespace dyad::study
