// bench_regress: the robot's deliberation step (online error regression, issue 4) on the
// MacawBot model, one thread. The workload is the switching experiment of the tests: the robot
// draws the head alone for 72 steps, the human pushes it along the beak for 100 steps (executed
// = previous + clip(0.9 beak + 0.1 robot - previous, +-5)), then lets go for 100 steps.
//
// Table 1: ms per experiment step (ErrorRegression::Step: encode, optimise, slide, generate),
//   median and p99 over `--runs` repetitions of the 272 steps, for W 5 and 15 with 15 iterations,
//   Adam (the presets' settings: W 5 = vcbot, W 15 = reference's lr 0.1) and Ceres LBFGS, in
//   float and double.
// Table 2: equal wall time. The executed positions of one Adam run are replayed open-loop to
//   every optimiser (same data for all), each step capped at the same budget (Adam's median
//   time for 15 iterations, in float) with no iteration cap; reported: the mean window loss
//   (N-ELBO of the best iterate) over the human and release steps, and iterations per step.
//
//   bench_regress [--runs N] [--model FILE.dpvrnn]   (default: import ../shared/data/vcbot)
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "dyad/pvrnn/dataset.hpp"
#include "dyad/pvrnn/error_regression.hpp"
#include "dyad/pvrnn/model_file.hpp"
#include "dyad/pvrnn/nrl_import.hpp"

using namespace dyad::pvrnn;

namespace {

constexpr int kHead = 1, kBeak = 2, kLeadIn = 72, kHuman = 100, kRelease = 100;

struct Trace {
  std::vector<std::array<double, 2>> executed;
  std::vector<double> step_ms, loss;
  std::vector<int> iterations;
};

double Percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(p * (v.size() - 1) + 0.5))];
}

// Closed loop (the robot's intention feeds the executed position), or open loop on `replay`.
template <typename Scalar>
Trace Run(const Model& model, const Eigen::MatrixXd& beak, const ErrorRegressionOptions& o,
          const std::vector<std::array<double, 2>>* replay, double budget_s) {
  auto er = ErrorRegression<Scalar>::Create(model, o).value();
  (void)er->Reset(kHead, 1);
  Trace tr;
  std::array<double, 2> executed{er->intention()[0], er->intention()[1]};
  const int steps = kLeadIn + kHuman + kRelease;
  for (int i = 0; i < steps; ++i) {
    const int t = i - kLeadIn;
    if (replay != nullptr) {
      executed = (*replay)[i];
    } else {
      const double rx = er->intention()[0], ry = er->intention()[1];
      double tx = rx, ty = ry;
      if (t >= 0 && t < kHuman) {
        tx = 0.9 * beak(0, t % beak.cols()) + 0.1 * rx;
        ty = 0.9 * beak(1, t % beak.cols()) + 0.1 * ry;
      }
      executed[0] += std::clamp(tx - executed[0], -5.0, 5.0);
      executed[1] += std::clamp(ty - executed[1], -5.0, 5.0);
    }
    tr.executed.push_back(executed);
    const auto t0 = SteadyClock::now();
    const auto deadline = budget_s > 0 ? t0 + std::chrono::duration_cast<SteadyClock::duration>(
                                                  std::chrono::duration<double>(budget_s))
                                       : SteadyClock::time_point::max();
    const StepResult& r = er->Step(executed.data(), deadline);
    const double ms = 1e3 * std::chrono::duration<double>(SteadyClock::now() - t0).count();
    if (t >= 0) {
      tr.step_ms.push_back(ms);
      tr.loss.push_back(r.loss.loss);
      tr.iterations.push_back(r.iterations);
    }
  }
  return tr;
}

ErrorRegressionOptions Options(int window, OptimizerKind kind) {
  ErrorRegressionOptions o = window == 5 ? ErrorRegressionOptions::Vcbot() : ErrorRegressionOptions::Reference();
  o.window = window;
  o.optimizer = kind;
  return o;
}

double Mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 20;
  std::string model_path;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--runs") && i + 1 < argc) runs = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--model") && i + 1 < argc) model_path = argv[++i];
    else {
      std::fprintf(stderr, "usage: bench_regress [--runs N] [--model FILE.dpvrnn]\n");
      return 2;
    }
  }
  const std::string vcbot = std::string(DYAD_SHARED_DATA_DIR) + "/vcbot";
  auto data = LoadNrlDataset(vcbot + "/dataset/Macaw");
  if (!data.ok()) {
    std::fprintf(stderr, "needs the Macaw data set: %s\n", data.status().message().c_str());
    return 2;
  }
  auto model = model_path.empty()
                   ? ImportNrlModel({vcbot + "/model/MacawBot", vcbot + "/config/properties_MacawBot.d", vcbot + "/dataset/Macaw"})
                   : LoadModel(model_path);
  if (!model.ok()) {
    std::fprintf(stderr, "%s\n", model.status().message().c_str());
    return 2;
  }
  const Eigen::MatrixXd& beak = data->sequences[kBeak];
  std::printf("MacawBot, switching workload (%d human + %d release steps after a %d-step lead-in), %d runs, one thread\n\n",
              kHuman, kRelease, kLeadIn, runs);
  std::printf("%-6s %-6s %-7s %10s %10s %10s %12s\n", "window", "scalar", "optim", "median ms", "p99 ms", "it/step",
              "of 100 ms");
  double adam_float_median[2] = {0, 0};
  for (int wi = 0; wi < 2; ++wi) {
    const int window = wi == 0 ? 5 : 15;
    for (int si = 0; si < 2; ++si) {
      for (auto kind : {OptimizerKind::kAdam, OptimizerKind::kCeres}) {
        std::vector<double> ms;
        double its = 0;
        for (int r = 0; r < runs; ++r) {
          const Trace tr = si == 0 ? Run<float>(*model, beak, Options(window, kind), nullptr, 0)
                                   : Run<double>(*model, beak, Options(window, kind), nullptr, 0);
          ms.insert(ms.end(), tr.step_ms.begin(), tr.step_ms.end());
          for (int it : tr.iterations) its += it;
        }
        const double med = Percentile(ms, 0.5);
        if (si == 0 && kind == OptimizerKind::kAdam) adam_float_median[wi] = med;
        std::printf("%-6d %-6s %-7s %10.4f %10.4f %10.1f %11.2f%%\n", window, si == 0 ? "float" : "double",
                    ToString(kind), med, Percentile(ms, 0.99), its / static_cast<double>(ms.size()), med / 100 * 100);
      }
    }
  }
  std::printf("\nEqual wall time per step (= Adam's float median above), no iteration cap, executed positions of one\n"
              "closed-loop Adam run replayed to all; mean window loss (N-ELBO of the best iterate) over 200 steps:\n");
  std::printf("%-6s %-6s %-7s %10s %12s %10s\n", "window", "scalar", "optim", "budget ms", "mean loss", "it/step");
  for (int wi = 0; wi < 2; ++wi) {
    const int window = wi == 0 ? 5 : 15;
    const Trace ref = Run<float>(*model, beak, Options(window, OptimizerKind::kAdam), nullptr, 0);
    std::vector<std::array<double, 2>> replay = ref.executed;
    for (int si = 0; si < 2; ++si) {
      for (auto kind : {OptimizerKind::kAdam, OptimizerKind::kCeres}) {
        ErrorRegressionOptions o = Options(window, kind);
        o.iterations = 100000;
        std::vector<double> loss;
        double its = 0;
        for (int r = 0; r < std::max(1, runs / 4); ++r) {
          const Trace tr = si == 0 ? Run<float>(*model, beak, o, &replay, 1e-3 * adam_float_median[wi])
                                   : Run<double>(*model, beak, o, &replay, 1e-3 * adam_float_median[wi]);
          loss.push_back(Mean(tr.loss));
          for (int it : tr.iterations) its += it / static_cast<double>(tr.iterations.size());
        }
        std::printf("%-6d %-6s %-7s %10.4f %12.5f %10.1f\n", window, si == 0 ? "float" : "double", ToString(kind),
                    adam_float_median[wi], Mean(loss), its / static_cast<double>(loss.size()));
      }
    }
    // The same with the iteration cap of the presets (15), for reference.
    for (auto kind : {OptimizerKind::kAdam, OptimizerKind::kCeres}) {
      const Trace tr = Run<float>(*model, beak, Options(window, kind), &replay, 0);
      std::printf("%-6d %-6s %-7s %10s %12.5f %10.1f   (15 iterations, no time cap)\n", window, "float", ToString(kind), "-",
                  Mean(tr.loss), Mean(std::vector<double>(tr.iterations.begin(), tr.iterations.end())));
    }
  }
  return 0;
}
