#include "dyad/pvrnn/analytic_dataset.hpp"

#include <cmath>
#include <functional>

namespace dyad::pvrnn {

namespace {

constexpr int kSteps = 72;
constexpr double kPi = 3.14159265358979323846;

// Piecewise-linear closed polygon through `corners`, sampled at kSteps points with constant speed.
Eigen::MatrixXd Polygon(const std::vector<Eigen::Vector2d>& corners) {
  std::vector<double> cum{0};
  for (size_t i = 0; i < corners.size(); ++i)
    cum.push_back(cum.back() + (corners[(i + 1) % corners.size()] - corners[i]).norm());
  Eigen::MatrixXd out(2, kSteps);
  for (int t = 0; t < kSteps; ++t) {
    const double s = cum.back() * t / kSteps;
    size_t i = 0;
    while (i + 1 < cum.size() - 1 && cum[i + 1] <= s) ++i;
    const double f = (s - cum[i]) / (cum[i + 1] - cum[i]);
    out.col(t) = corners[i] + f * (corners[(i + 1) % corners.size()] - corners[i]);
  }
  return out;
}

Eigen::MatrixXd Curve(const std::function<Eigen::Vector2d(double)>& f) {
  Eigen::MatrixXd out(2, kSteps);
  for (int t = 0; t < kSteps; ++t) out.col(t) = f(2 * kPi * t / kSteps);
  return out;
}

}  // namespace

Dataset MakeAnalyticDataset() {
  Dataset d;
  d.name = "analytic";
  d.sampling_period_ms = 100;
  // circle
  d.sequences.push_back(Curve([](double u) { return Eigen::Vector2d(-20 + 18 * std::cos(u), 20 + 18 * std::sin(u)); }));
  // square
  d.sequences.push_back(Polygon({{10, 5}, {40, 5}, {40, 35}, {10, 35}}));
  // triangle
  d.sequences.push_back(Polygon({{-40, -40}, {-5, -40}, {-22, -5}}));
  // figure eight (lemniscate of Gerono)
  d.sequences.push_back(Curve([](double u) { return Eigen::Vector2d(25 + 18 * std::sin(u), -22 + 18 * std::sin(u) * std::cos(u)); }));
  // five-pointed star
  {
    std::vector<Eigen::Vector2d> c;
    for (int i = 0; i < 5; ++i) {
      const double a = kPi / 2 + i * 4 * kPi / 5;
      c.emplace_back(0 + 30 * std::cos(a), 0 + 30 * std::sin(a));
    }
    d.sequences.push_back(Polygon(c));
  }
  // heart
  d.sequences.push_back(Curve([](double u) {
    const double x = 16 * std::pow(std::sin(u), 3);
    const double y = 13 * std::cos(u) - 5 * std::cos(2 * u) - 2 * std::cos(3 * u) - std::cos(4 * u);
    return Eigen::Vector2d(1.4 * x, 1.4 * y + 5);
  }));
  // trefoil (three-leaved rose)
  d.sequences.push_back(Curve([](double u) {
    const double v = u / 2;  // the rose closes after half a turn
    const double r = 30 * std::cos(3 * v);
    return Eigen::Vector2d(r * std::cos(v), r * std::sin(v));
  }));
  d.names = {"circle", "square", "triangle", "figure eight", "star", "heart", "trefoil"};
  return d;
}

}  // namespace dyad::pvrnn
