// BPTT gradients against central finite differences, in double, eps (noise) held fixed.
#include <gtest/gtest.h>

#include <random>

#include "dyad/pvrnn/posterior_pass.hpp"
#include "dyad/pvrnn/softmax_encoding.hpp"
#include "finite_difference.hpp"

namespace dyad::pvrnn {
namespace {

using Md = MatrixT<double>;

struct Problem {
  ModelSpec spec;
  int steps = 6, sequences = 3;
  std::unique_ptr<NetworkLayout> layout;
  Weights<double> w;
  AdaptiveVariables<double> a;
  Md eps, targets;
  NetworkState<double> start;
  std::vector<double> meta_prior;
};

// Three layers so that the structural zeros (layer 0 <-> layer 2) are exercised too.
Problem MakeProblem(uint64_t seed) {
  Problem p;
  p.spec.layers = {{5, 2, 2.0, 0.3}, {4, 1, 4.0, 0.5}, {3, 2, 6.0, 1.0}};
  p.spec.output.dofs = {{-1, 1}, {0, 3}};
  p.spec.output.dsoft = 0.5;
  p.spec.output.sigma = 0.3;
  p.layout = std::make_unique<NetworkLayout>(p.spec);
  std::mt19937_64 rng(seed);
  p.w = Weights<double>::Random(*p.layout, rng);
  p.w.flat() *= 1.5;  // larger weights: a less linear regime
  p.w.ApplyMask();
  const int tz = p.layout->total_z(), td = p.layout->total_d(), cols = p.steps * p.sequences;
  std::normal_distribution<double> n01;
  p.a = AdaptiveVariables<double>(tz, p.steps, p.sequences);
  for (int i = 0; i < p.a.flat().size(); ++i) p.a.flat()[i] = 0.5 * n01(rng);
  p.eps = Md(tz, cols);
  for (int i = 0; i < p.eps.size(); ++i) p.eps.data()[i] = n01(rng);
  Eigen::MatrixXd pos(2, cols);
  std::uniform_real_distribution<double> u(0, 1);
  for (int j = 0; j < cols; ++j) pos.col(j) << -1 + 2 * u(rng), 3 * u(rng);
  p.targets = EncodePositions(p.spec.output, pos);
  p.start = NetworkState<double>::Zero(td, p.sequences);
  for (int i = 0; i < p.start.h.size(); ++i) p.start.h.data()[i] = 0.5 * n01(rng);
  p.start.d = p.start.h.array().tanh().matrix();
  p.meta_prior = {0.3, 0.5, 1.0};
  return p;
}

double Loss(Problem& p, PosteriorPass<double>& pass) {
  return pass.Forward(p.w, p.a, p.eps, p.targets, p.start, p.meta_prior).loss;
}

using testing::CentralDifference;
using testing::RelativeError;

TEST(Gradient, EveryWeightGroupMatchesCentralDifferences) {
  Problem p = MakeProblem(7);
  PosteriorPass<double> pass(*p.layout, p.steps, p.sequences);
  Loss(p, pass);
  Weights<double> gw(*p.layout);
  AdaptiveVariables<double> ga(p.layout->total_z(), p.steps, p.sequences);
  pass.Backward(&gw, &ga);
  for (const auto& g : p.layout->groups()) {
    auto view = p.w.Group(g);
    Eigen::VectorXd analytic(g.rows * g.cols), numeric(g.rows * g.cols);
    const auto gview = gw.Group(g);
    for (int c = 0; c < g.cols; ++c) {
      for (int r = 0; r < g.rows; ++r) {
        numeric[c * g.rows + r] = CentralDifference(view(r, c), [&] { return Loss(p, pass); });
        analytic[c * g.rows + r] = gview(r, c);
      }
    }
    EXPECT_LT(RelativeError(analytic, numeric), 1e-6) << g.name;
    EXPECT_GT(analytic.norm(), 0.0) << g.name << " has a zero gradient: not exercised";
  }
}

TEST(Gradient, AdaptiveVariablesMatchCentralDifferences) {
  Problem p = MakeProblem(11);
  PosteriorPass<double> pass(*p.layout, p.steps, p.sequences);
  Loss(p, pass);
  AdaptiveVariables<double> ga(p.layout->total_z(), p.steps, p.sequences);
  pass.Backward(nullptr, &ga);
  const int half = static_cast<int>(p.a.flat().size() / 2);
  for (int part = 0; part < 2; ++part) {
    Eigen::VectorXd analytic(half), numeric(half);
    for (int i = 0; i < half; ++i) {
      numeric[i] = CentralDifference(p.a.flat()[part * half + i], [&] { return Loss(p, pass); });
      analytic[i] = ga.flat()[part * half + i];
    }
    EXPECT_LT(RelativeError(analytic, numeric), 1e-6) << (part == 0 ? "A_mu" : "A_logsigma");
  }
}

TEST(Gradient, StartStateGradientMatchesCentralDifferences) {
  Problem p = MakeProblem(13);
  PosteriorPass<double> pass(*p.layout, p.steps, p.sequences);
  Loss(p, pass);
  AdaptiveVariables<double> ga(p.layout->total_z(), p.steps, p.sequences);
  pass.Backward(nullptr, &ga);
  for (auto* which : {&p.start.h, &p.start.d}) {
    Eigen::VectorXd analytic(which->size()), numeric(which->size());
    const Md& g = which == &p.start.h ? pass.grad_start_h() : pass.grad_start_d();
    for (int i = 0; i < which->size(); ++i) {
      numeric[i] = CentralDifference(which->data()[i], [&] { return Loss(p, pass); });
      analytic[i] = g.data()[i];
    }
    EXPECT_LT(RelativeError(analytic, numeric), 1e-6) << (which == &p.start.h ? "h" : "d");
  }
}

TEST(Gradient, StructuralZerosGetNoGradient) {
  Problem p = MakeProblem(3);
  PosteriorPass<double> pass(*p.layout, p.steps, p.sequences);
  Loss(p, pass);
  Weights<double> gw(*p.layout);
  AdaptiveVariables<double> ga(p.layout->total_z(), p.steps, p.sequences);
  pass.Backward(&gw, &ga);
  const auto r = gw.R();
  for (int i = 0; i < r.size(); ++i) {
    if (!p.layout->r_mask()[i]) {
      EXPECT_EQ(r.data()[i], 0.0);
    }
  }
}

}  // namespace
}  // namespace dyad::pvrnn
