// bench_pvrnn_train: ms per training epoch and achieved GFLOP/s (2 x multiply-adds of the
// posterior pass + BPTT) for the study's model (d=40,10; z=4,1; tau=2,10) on the Macaw set
// (or the built-in analytic set when ../shared/data is absent), beside the GFLOP/s of a large
// Eigen GEMM (one thread) in the same scalar, measured in the same run. Per scalar three rows:
// 1 chunk on 1 thread, 2 chunks (the default) on 1 thread and on --threads (default 2), with
// the speed-up over the first row.
//
//   bench_pvrnn_train [--epochs N] [--threads N] [--full] [--curve N]
//     --full: run 50,000 epochs in float (default options) and report wall time and final loss
//     --curve N: train N epochs (seed 1) and print the loss every 1000 epochs to 17 digits, in
//                float and double (to compare the loss curve before and after an engine change)
#include <Eigen/Core>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>

#include "dyad/pvrnn/analytic_dataset.hpp"
#include "dyad/pvrnn/trainer.hpp"

using namespace dyad::pvrnn;
using Clock = std::chrono::steady_clock;

namespace {

template <typename Scalar>
double GemmGflops() {
  const int n = 512;
  MatrixT<Scalar> a = MatrixT<Scalar>::Random(n, n), b = MatrixT<Scalar>::Random(n, n), c(n, n);
  c.noalias() = a * b;  // warm up
  int reps = 0;
  const auto t0 = Clock::now();
  double secs = 0;
  do {
    c.noalias() = a * b;
    ++reps;
    secs = std::chrono::duration<double>(Clock::now() - t0).count();
  } while (secs < 0.5);
  if (c(0, 0) == Scalar(12345)) std::printf(" ");  // keep the product alive
  return 2.0 * n * n * n * reps / secs / 1e9;
}

template <typename Scalar>
double MsPerEpoch(const Model& init, const Dataset& data, const TrainerOptions& o, int epochs, double* gflops) {
  auto trainer = Trainer<Scalar>::Create(init, data, o).value();
  for (int e = 0; e < 20; ++e) trainer->Epoch();  // warm up
  const auto t0 = Clock::now();
  for (int e = 0; e < epochs; ++e) trainer->Epoch();
  const double secs = std::chrono::duration<double>(Clock::now() - t0).count();
  *gflops = 2.0 * trainer->MultiplyAddsPerEpoch() / (secs / epochs) / 1e9;
  return 1e3 * secs / epochs;
}

// One row per configuration; the last column is the speed-up over the first row of the scalar.
template <typename Scalar>
void Rows(const char* name, const Model& init, const Dataset& data, int epochs, int threads) {
  const double gemm = GemmGflops<Scalar>();
  double first = 0;
  for (auto [chunks, n_threads] : {std::pair{1, 1}, std::pair{2, 1}, std::pair{2, threads}}) {
    TrainerOptions o;
    o.chunks = chunks;
    o.threads = n_threads;
    double gflops = 0;
    const double ms = MsPerEpoch<Scalar>(init, data, o, epochs, &gflops);
    if (first == 0) first = ms;
    std::printf("%-7s %6d %7d %10.3f %10.2f %12.2f %9.1f%% %12.1f s %8.2fx\n", name, chunks, n_threads, ms, gflops,
                gemm, 100 * gflops / gemm, ms * 50000 / 1e3, first / ms);
  }
}

template <typename Scalar>
void Curve(const char* name, const Model& init, const Dataset& data, int epochs) {
  auto trainer = Trainer<Scalar>::Create(init, data, TrainerOptions{}).value();
  for (int e = 1; e <= epochs; ++e) {
    const LossTerms& l = trainer->Epoch();
    if (e % 1000 == 0 || e == 1) std::printf("curve %s %d %.17g\n", name, e, l.loss);
  }
}

}  // namespace

int main(int argc, char** argv) {
  int epochs = 2000, curve = 0, threads = 2;
  bool full = false;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--epochs") && i + 1 < argc) epochs = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--full")) full = true;
    else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc) threads = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--curve") && i + 1 < argc) curve = std::atoi(argv[++i]);
  }
  Eigen::setNbThreads(1);
  const std::string macaw = std::string(DYAD_SHARED_DATA_DIR) + "/vcbot/dataset/Macaw";
  Dataset data;
  if (std::filesystem::exists(macaw)) {
    data = LoadNrlDataset(macaw).value();
  } else {
    data = MakeAnalyticDataset();
  }
  const Model init = Model::Initialize(ModelSpec::MacawBot(), data.steps(), data.size(), 1);
  if (curve > 0) {
    Curve<float>("float", init, data, curve);
    Curve<double>("double", init, data, curve);
    return 0;
  }
  std::printf("PV-RNN training, model d=40,10 z=4,1 tau=2,10 on '%s' (%d sequences x %d steps), %d epochs\n",
              data.name.c_str(), data.size(), data.steps(), epochs);
  std::printf("%-7s %6s %7s %10s %10s %12s %10s %14s %9s\n", "scalar", "chunks", "threads", "ms/epoch", "GFLOP/s",
              "GEMM GFLOP/s", "of GEMM", "50k epochs", "speed-up");
  Rows<float>("float", init, data, epochs, threads);
  Rows<double>("double", init, data, epochs, threads);
  if (full) {
    auto trainer = Trainer<float>::Create(init, data, TrainerOptions{}).value();
    const auto t0 = Clock::now();
    LossTerms l;
    for (int e = 1; e <= 50000; ++e) {
      l = trainer->Epoch();
      if (e % 5000 == 0)
        std::printf("epoch %6d  loss %.4f  RE_Q %.4f  Regulation %.4f  RE_P %.3f  %.1f s\n", e, l.loss,
                    l.reconstruction, l.regulation, trainer->PriorReconstruction(true, e), 
                    std::chrono::duration<double>(Clock::now() - t0).count());
    }
    std::printf("50,000 epochs (float): %.1f s wall, final loss %.4f\n",
                std::chrono::duration<double>(Clock::now() - t0).count(), l.loss);
  }
  return 0;
}
