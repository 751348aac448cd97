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
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<size_t> pick(0, x.size() - 1);
  std::vector<double> means(static_cast<size_t>(std::max(resamples, 1)));
  for (double& m : means) {
    double s = 0;
    for (size_t i = 0; i < x.size(); ++i) s += x[pick(rng)];
    m = s / static_cast<double>(x.size());
  }
  std::sort(means.begin(), means.end());
  auto quantile = [&](double q) {
    const auto k = static_cast<size_t>(std::ceil(q * static_cast<double>(means.size())));
    return means[std::min(means.size() - 1, k == 0 ? 0 : k - 1)];
  };
  ci.low = quantile((1 - level) / 2);
  ci.high = quantile((1 + level) / 2);
  return ci;
}

}  // namespace dyad::study
