// The trainer's split of the sequences into chunks run on a thread pool: the same mathematics
// as one block of all sequences (gradients against one sequence at a time, in double), and the
// same bits whatever the number of threads.
#include <gtest/gtest.h>

#include "dyad/pvrnn/analytic_dataset.hpp"
#include "dyad/pvrnn/posterior_pass.hpp"
#include "dyad/pvrnn/softmax_encoding.hpp"
#include "dyad/pvrnn/trainer.hpp"

namespace dyad::pvrnn {
namespace {

using Md = MatrixT<double>;

Model StudyModel(const Dataset& d, uint64_t seed) {
  return Model::Initialize(ModelSpec::MacawBot(), d.steps(), d.size(), seed);
}

// Columns t*S + s of `all` for the sequences first..first+n-1, in the chunk's order t*n + s.
Md Columns(const Md& all, int S, int T, int first, int n) {
  Md out(all.rows(), T * n);
  for (int t = 0; t < T; ++t) out.middleCols(t * n, n) = all.middleCols(t * S + first, n);
  return out;
}

double RelativeDifference(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return (a - b).norm() / std::max(a.norm(), b.norm());
}

// One pass over the 7 sequences as one block (batched), against 7 passes of one sequence:
// the weight gradients sum, A's gradients and the loss terms agree to rounding.
TEST(ChunkedTraining, BatchedGradientsEqualOneSequenceAtATime) {
  const Dataset d = MakeAnalyticDataset();
  const Model m = StudyModel(d, 3);
  const NetworkLayout layout(m.spec);
  const int S = d.size(), T = d.steps(), tz = layout.total_z(), td = layout.total_d();
  Eigen::MatrixXd positions(d.dofs(), T * S);
  for (int t = 0; t < T; ++t)
    for (int s = 0; s < S; ++s) positions.col(t * S + s) = d.sequences[s].col(t);
  const Md targets = EncodePositions(m.spec.output, positions);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n01;
  Md eps(tz, T * S);
  for (int i = 0; i < eps.size(); ++i) eps.data()[i] = n01(rng);
  const std::vector<double> meta_prior = {0.3, 0.5};

  PosteriorPass<double> all(layout, T, S);
  const LossTerms whole = all.Forward(m.weights, m.adaptive, eps, targets, NetworkState<double>::Zero(td, S), meta_prior);
  Weights<double> gw(layout);
  AdaptiveVariables<double> ga(tz, T, S);
  all.Backward(&gw, &ga);

  Weights<double> sum_gw(layout);
  Md ga_mu(tz, T * S), ga_ls(tz, T * S);
  double reconstruction = 0, regulation = 0;
  PosteriorPass<double> one(layout, T, 1);
  for (int s = 0; s < S; ++s) {
    AdaptiveVariables<double> a(tz, T, 1), g(tz, T, 1);
    a.mu() = Columns(m.adaptive.mu(), S, T, s, 1);
    a.log_sigma() = Columns(m.adaptive.log_sigma(), S, T, s, 1);
    const Md e = Columns(eps, S, T, s, 1), y = Columns(targets, S, T, s, 1);
    const LossTerms& l = one.Forward(m.weights, a, e, y, NetworkState<double>::Zero(td, 1), meta_prior);
    reconstruction += l.reconstruction;
    regulation += l.regulation;
    Weights<double> g_w(layout);
    one.Backward(&g_w, &g);
    sum_gw.flat() += g_w.flat();
    for (int t = 0; t < T; ++t) {
      ga_mu.col(t * S + s) = g.mu().col(t);
      ga_ls.col(t * S + s) = g.log_sigma().col(t);
    }
  }
  EXPECT_LT(RelativeDifference(gw.flat(), sum_gw.flat()), 1e-10);
  EXPECT_LT(RelativeDifference(ga.mu().reshaped(), ga_mu.reshaped()), 1e-10);
  EXPECT_LT(RelativeDifference(ga.log_sigma().reshaped(), ga_ls.reshaped()), 1e-10);
  EXPECT_NEAR(whole.reconstruction, reconstruction, 1e-10 * reconstruction);
  EXPECT_NEAR(whole.regulation, regulation, 1e-10 * regulation);
}

// Trainings with 1, 2 and 7 chunks follow the same path (rounding differs only): after one
// epoch in double the weights agree to 1e-10.
TEST(ChunkedTraining, ChunkCountChangesRoundingOnly) {
  const Dataset d = MakeAnalyticDataset();
  std::vector<Eigen::VectorXd> weights;
  std::vector<double> losses;
  for (int chunks : {1, 2, 7}) {
    TrainerOptions o;
    o.chunks = chunks;
    o.threads = 1;
    auto t = Trainer<double>::Create(StudyModel(d, 4), d, o).value();
    EXPECT_EQ(t->chunks(), chunks);
    losses.push_back(t->Epoch().loss);
    t->Epoch();
    weights.push_back(t->Snapshot(false).weights.flat());
  }
  for (size_t i = 1; i < weights.size(); ++i) {
    EXPECT_NEAR(losses[i], losses[0], 1e-10 * losses[0]);
    EXPECT_LT(RelativeDifference(weights[i], weights[0]), 1e-10);
  }
}

// The result does not depend on the threads: identical loss and weights bit for bit after
// 30 epochs with 1 and 2 threads (float, noise on), for 2 and 7 chunks.
TEST(ChunkedTraining, OneAndTwoThreadsGiveIdenticalBits) {
  const Dataset d = MakeAnalyticDataset();
  for (int chunks : {2, 7}) {
    std::unique_ptr<Trainer<float>> t[2];
    for (int i = 0; i < 2; ++i) {
      TrainerOptions o;
      o.chunks = chunks;
      o.threads = i + 1;
      t[i] = Trainer<float>::Create(StudyModel(d, 6), d, o).value();
      EXPECT_EQ(t[i]->threads(), i + 1);
    }
    for (int e = 0; e < 30; ++e) {
      const double l1 = t[0]->Epoch().loss, l2 = t[1]->Epoch().loss;
      ASSERT_EQ(l1, l2) << "epoch " << e << ", " << chunks << " chunks";
    }
    const Model m1 = t[0]->Snapshot(true), m2 = t[1]->Snapshot(true);
    EXPECT_EQ(m1.weights.flat(), m2.weights.flat()) << chunks << " chunks";
    EXPECT_EQ(m1.adaptive.flat(), m2.adaptive.flat()) << chunks << " chunks";
    EXPECT_EQ(m1.training->weights_v, m2.training->weights_v) << chunks << " chunks";
  }
}

// The next epoch's eps are drawn during an epoch: a checkpoint still resumes exactly (10 + 10
// epochs on 2 threads equal 20 on 1).
TEST(ChunkedTraining, ResumingOnTwoThreadsContinuesExactly) {
  const Dataset d = MakeAnalyticDataset();
  TrainerOptions one, two;
  one.threads = 1;
  two.threads = 2;
  auto straight = Trainer<float>::Create(StudyModel(d, 8), d, one).value();
  auto first = Trainer<float>::Create(StudyModel(d, 8), d, two).value();
  for (int e = 0; e < 20; ++e) straight->Epoch();
  for (int e = 0; e < 10; ++e) first->Epoch();
  auto resumed = Trainer<float>::Create(first->Snapshot(true), d, two).value();
  for (int e = 0; e < 10; ++e) resumed->Epoch();
  EXPECT_EQ(resumed->Snapshot(false).weights.flat(), straight->Snapshot(false).weights.flat());
  EXPECT_EQ(resumed->Snapshot(false).adaptive.flat(), straight->Snapshot(false).adaptive.flat());
}

TEST(ChunkedTraining, ThreadsDefaultToTheCoresAtMostOnePerChunk) {
  const Dataset d = MakeAnalyticDataset();
  TrainerOptions o;
  o.chunks = 20;  // more than the 7 sequences: one chunk per sequence
  auto t = Trainer<float>::Create(StudyModel(d, 1), d, o).value();
  EXPECT_EQ(t->chunks(), 7);
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  EXPECT_EQ(t->threads(), std::min(cores, 7));
  o.chunks = 0;
  auto bad = Trainer<float>::Create(StudyModel(d, 1), d, o);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().message(), "chunks: must be >= 1, got 0");
}

}  // namespace
}  // namespace dyad::pvrnn
