#include "bootstrap.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace dyad::study {

MeanInterval BootstrapMean(const std::vector<double>& values, uint64_t seed, int resamples, double level) {
  std::vector<double> x;
  for (double v : values)
    if (!std::isnan(v)) x.push_back(v);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  MeanInterval ci{nan, nan, nan, static_cast<int>(x.size())};
  if (x.empty()) return ci;
  double sum = 0;
  for (double v : x) sum += v;
  ci.mean = sum / static_cast<double>(x.size());
  // The index from the engine's raw output (its sequence is the standard's; a distribution's
  // algorithm is the library's): the modulo bias is below 1e-15 for any sample a study has.
  std::mt19937_64 rng(seed);
  std::vector<double> means(static_cast<size_t>(std::max(resamples, 1)));
  for (double& m : means) {
    double s = 0;
    for (size_t i = 0; i < x.size(); ++i) s += x[static_cast<size_t>(rng() % x.size())];
    m = s / static_cast<double>(x.size());
  }
  std::sort(means.begin(), means.end());
  // Type 1: the k-th smallest, k = ceil(q * n); q * n is rounded first (0.025 * 4000 is
  // 100.00000000000009 in doubles, and ceil would make it 101).
  auto quantile = [&](double q) {
    const double n = static_cast<double>(means.size());
    const double at = std::round(std::clamp(q, 0.0, 1.0) * n * 1e6) / 1e6;
    const auto k = static_cast<size_t>(std::ceil(at));
    return means[std::min(means.size() - 1, k == 0 ? 0 : k - 1)];
  };
  if (!(level > 0 && level < 1)) level = 0.95;  // documented range; NaN too
  ci.low = quantile((1 - level) / 2);
  ci.high = quantile((1 + level) / 2);
  return ci;
}

}  // namespace dyad::study
