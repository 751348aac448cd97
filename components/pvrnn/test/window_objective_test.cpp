// The issue-4 building block: window loss and its gradient w.r.t. the window's A only.
#include "dyad/pvrnn/window_objective.hpp"

#include <gtest/gtest.h>

#include <random>

#include "dyad/pvrnn/model.hpp"
#include "dyad/pvrnn/softmax_encoding.hpp"
#include "finite_difference.hpp"

namespace dyad::pvrnn {
namespace {

struct WindowSetup {
  Model model = Model::Initialize(ModelSpec::MacawBot(), 72, 7, 9);
  Weights<double> w = model.weights;
  int window = 5;
  Eigen::MatrixXd targets, eps;
  NetworkState<double> start;
  WindowSetup() {
    std::mt19937_64 rng(2);
    std::normal_distribution<double> n01;
    Eigen::MatrixXd pos(2, window);
    for (int t = 0; t < window; ++t) pos.col(t) << 10 * n01(rng), 10 * n01(rng);
    targets = EncodePositions(model.spec.output, pos);
    eps = Eigen::MatrixXd(5, window);
    for (int i = 0; i < eps.size(); ++i) eps.data()[i] = n01(rng);
    start = NetworkState<double>::Zero(50, 1);
    for (int i = 0; i < 50; ++i) start.h(i, 0) = 0.3 * n01(rng);
    start.d = start.h.array().tanh().matrix();
  }
};

TEST(WindowObjective, GradientWithRespectToAMatchesFiniteDifferences) {
  WindowSetup s;
  WindowObjective<double> f(s.w, s.window);
  f.SetWindow(s.targets, s.start, s.eps, {1e-5, 1e-5});
  AdaptiveVariables<double> a(5, s.window, 1), g(5, s.window, 1);
  std::mt19937_64 rng(4);
  std::normal_distribution<double> n01;
  for (int i = 0; i < a.flat().size(); ++i) a.flat()[i] = 0.3 * n01(rng);
  f.Evaluate(a, &g);
  Eigen::VectorXd numeric(a.flat().size());
  for (int i = 0; i < a.flat().size(); ++i)
    numeric[i] = testing::CentralDifference(a.flat()[i], [&] { return f.Evaluate(a, nullptr).loss; });
  const double rel = testing::RelativeError(g.flat(), numeric);
  EXPECT_LT(rel, 1e-6);
}

TEST(WindowObjective, WeightsAreNotTouched) {
  WindowSetup s;
  const Eigen::VectorXd before = s.w.flat();
  WindowObjective<double> f(s.w, s.window);
  f.SetWindow(s.targets, s.start, s.eps, {0.01, 0.01});
  AdaptiveVariables<double> a(5, s.window, 1), g(5, s.window, 1);
  f.Evaluate(a, &g);
  EXPECT_EQ(s.w.flat(), before);
}

// Plain gradient steps on A lower the window loss (the optimiser of issue 4 will be Adam/Ceres).
TEST(WindowObjective, GradientStepsLowerTheWindowLoss) {
  WindowSetup s;
  const Weights<float> wf = s.w.Cast<float>();
  WindowObjective<float> g_obj(wf, s.window);
  g_obj.SetWindow(s.targets.cast<float>(), {s.start.h.cast<float>(), s.start.d.cast<float>()},
                  s.eps.cast<float>(), {1e-4, 1e-4});
  AdaptiveVariables<float> a(5, s.window, 1), g(5, s.window, 1);
  const double first = g_obj.Evaluate(a, &g).loss;
  double last = first;
  for (int it = 0; it < 30; ++it) {
    a.flat() -= 0.05f * g.flat();
    last = g_obj.Evaluate(a, &g).loss;
  }
  EXPECT_LT(last, first);
}

TEST(WindowObjective, StatesAfterEachStepAreExposedForSliding) {
  WindowSetup s;
  WindowObjective<double> f(s.w, s.window);
  f.SetWindow(s.targets, s.start, s.eps, {0.01, 0.01});
  AdaptiveVariables<double> a(5, s.window, 1);
  f.Evaluate(a, nullptr);
  EXPECT_EQ(f.pass().h_at(-1), s.start.h);
  EXPECT_EQ(f.pass().d_at(0), f.pass().h_at(0).array().tanh().matrix());
}

}  // namespace
}  // namespace dyad::pvrnn
