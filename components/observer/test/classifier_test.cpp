// The classifier net: shape rules, features, exact gradient, determinism; congruence helpers.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "dyad/observer/classifier.hpp"
#include "dyad/observer/evaluation.hpp"

namespace dyad::observer {
namespace {

ClassifierSpec Small() {
  ClassifierSpec s;
  s.window = 3;
  s.hidden = {6, 5};
  s.classes = 4;
  return s;
}

TEST(ClassifierSpec, DefaultsAreValidAndTheStudysShape) {
  const ClassifierSpec s;
  EXPECT_TRUE(s.Validate().ok());
  EXPECT_EQ(s.inputs(), 10);
  EXPECT_EQ(s.hidden, (std::vector<int>{150, 100}));
  EXPECT_EQ(s.classes, 7);
  EXPECT_EQ(s.num_parameters(), 10 * 150 + 150 + 150 * 100 + 100 + 100 * 7 + 7);
}

TEST(ClassifierSpec, ProblemsNameTheFieldAndValue) {
  ClassifierSpec s;
  s.window = 0;
  s.hidden = {150, 0};
  s.workspace = {{-50, 50}, {10, 10}};
  const auto p = s.Problems();
  ASSERT_EQ(p.size(), 3u);
  EXPECT_EQ(p[0].ToString(), "window: must be in 1..1000, got 0");
  EXPECT_EQ(p[1].ToString(), "hidden[1]: must be in 1..100000, got 0");
  EXPECT_EQ(p[2].field, "workspace[1]");
  EXPECT_FALSE(Classifier::Create(s, 1).ok());
}

TEST(Features, PositionsMapTheWorkspaceToMinusOneOneOldestFirst) {
  ClassifierSpec s;
  s.window = 2;
  s.workspace = {{-50, 50}, {0, 10}};
  Eigen::MatrixXd w(2, 2);
  w << -50, 50,  //
      5, 10;
  Eigen::VectorXd f(4);
  ComputeFeatures(s, w, f);
  EXPECT_EQ(f, (Eigen::VectorXd(4) << -1, 0, 1, 1).finished());
}

TEST(Features, DisplacementsAreStepDifferencesOverFivePercentOfTheRange) {
  ClassifierSpec s;
  s.window = 2;
  s.input = InputRepresentation::kDisplacements;
  ASSERT_EQ(s.positions_needed(), 3);
  Eigen::MatrixXd w(2, 3);
  w << 0, 5, 0,  //
      1, 1, 11;
  Eigen::VectorXd f(4);
  ComputeFeatures(s, w, f);
  EXPECT_EQ(f, (Eigen::VectorXd(4) << 1, 0, -1, 2).finished());
}

TEST(Classifier, GradientMatchesCentralFiniteDifferences) {
  auto c = Classifier::Create(Small(), 3);
  ASSERT_TRUE(c.ok());
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0, 1);
  const int batch = 9;
  Eigen::MatrixXd x = Eigen::MatrixXd::NullaryExpr(c->spec().inputs(), batch, [&] { return n(rng); });
  Eigen::MatrixXd y = Eigen::MatrixXd::Zero(c->spec().classes, batch);
  for (int j = 0; j < batch; ++j) y(j % c->spec().classes, j) = 1;
  y(0, 1) = 0.3;  // soft targets are allowed too
  // Move the biases off zero so their gradient paths are exercised with non-trivial values.
  c->parameters() += 0.1 * Eigen::VectorXd::NullaryExpr(c->parameters().size(), [&] { return n(rng); });
  Eigen::VectorXd g;
  c->Loss(x, y, &g);
  ASSERT_EQ(g.size(), c->parameters().size());
  const double h = 1e-6;
  double worst = 0;
  for (Eigen::Index i = 0; i < g.size(); ++i) {
    const double keep = c->parameters()(i);
    c->parameters()(i) = keep + h;
    const double up = c->Loss(x, y, nullptr);
    c->parameters()(i) = keep - h;
    const double down = c->Loss(x, y, nullptr);
    c->parameters()(i) = keep;
    const double fd = (up - down) / (2 * h);
    worst = std::max(worst, std::abs(fd - g(i)) / std::max(1e-3, std::abs(fd) + std::abs(g(i))));
  }
  EXPECT_LT(worst, 1e-6);
}

TEST(Classifier, ClassifyEqualsTheBatchForwardPass) {
  auto c = Classifier::Create(ClassifierSpec{}, 9);
  ASSERT_TRUE(c.ok());
  Eigen::MatrixXd w(2, 5);
  w << -30, -28, -25, -20, -14,  //
      10, 12, 13, 13, 12;
  Eigen::VectorXd f(10);
  ComputeFeatures(c->spec(), w, f);
  const Eigen::MatrixXd batch = c->Probabilities(f);
  Classifier::Workspace ws;
  Eigen::VectorXd p;
  c->Classify(w, &ws, &p);
  ASSERT_EQ(p.size(), 7);
  for (int k = 0; k < 7; ++k) EXPECT_NEAR(p(k), batch(k, 0), 1e-15);
  EXPECT_TRUE((p.array() > 0).all() && (p.array() < 1).all());
}

TEST(Classifier, CreateIsDeterministicPerSeed) {
  EXPECT_EQ(Classifier::Create(Small(), 4)->parameters(), Classifier::Create(Small(), 4)->parameters());
  EXPECT_NE(Classifier::Create(Small(), 4)->parameters(), Classifier::Create(Small(), 5)->parameters());
  EXPECT_FALSE(Classifier::FromParameters(Small(), Eigen::VectorXd::Zero(3)).ok());
}

TEST(Congruence, IsTheProbabilityThatBothNormalisedClassificationsAgree) {
  Eigen::VectorXd a(3), b(3);
  a << 0.9, 0.1, 0.0;
  b << 0.9, 0.1, 0.0;
  EXPECT_NEAR(InstantCongruence(a, b), 0.82, 1e-12);
  b << 0.0, 0.0, 1.0;
  EXPECT_EQ(InstantCongruence(a, b), 0.0);
  b << 2.0, 0.0, 0.0;  // sigmoid outputs need not sum to 1: normalised first
  a << 1.0, 1.0, 0.0;
  EXPECT_NEAR(InstantCongruence(a, b), 0.5, 1e-12);
  EXPECT_EQ(InstantCongruence(Eigen::VectorXd::Zero(3), b), 0.0);
}

TEST(Congruence, MovingAverageCoversTheLastYValuesAndRestarts) {
  MovingAverage f(3);
  EXPECT_DOUBLE_EQ(f.Push(1), 1);
  EXPECT_DOUBLE_EQ(f.Push(0), 0.5);
  EXPECT_DOUBLE_EQ(f.Push(0.5), 0.5);
  EXPECT_DOUBLE_EQ(f.Push(1), 0.5);  // (0 + 0.5 + 1) / 3
  EXPECT_DOUBLE_EQ(f.Push(1), 2.5 / 3);
  f.Reset();
  EXPECT_EQ(f.count(), 0);
  EXPECT_DOUBLE_EQ(f.Push(0.25), 0.25);
}

TEST(ConfusionMatrix, RowsNormaliseAndTheMinimumSkipsEmptyRows) {
  ConfusionMatrix cm;
  cm.counts = Eigen::MatrixXi::Zero(3, 3);
  cm.counts(0, 0) = 9;
  cm.counts(0, 1) = 1;
  cm.counts(1, 1) = 5;
  EXPECT_DOUBLE_EQ(cm.MinDiagonal(), 0.9);
  EXPECT_DOUBLE_EQ(cm.Accuracy(), 14.0 / 15.0);
  EXPECT_NE(cm.ToTable({"eye", "head"}).find("eye"), std::string::npos);
  EXPECT_NE(cm.ToMarkdown().find("**0.900**"), std::string::npos);
}

}  // namespace
}  // namespace dyad::observer
