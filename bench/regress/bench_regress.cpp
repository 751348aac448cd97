// bench_regress: the robot's deliberation step (online error regression, issue 4) on the
// MacawBot model, one thread. The workload is the switching experiment of the tests: the robot
// draws the head alone for 72 steps, the human pushes it along the beak for 100 steps (executed
// = previous + clip(0.9 beak + 0.1 robot - previous, +-5)), then lets go for 100 steps.
//
// Table 1: ms per experiment step (ErrorRegression::Step: encode, optimise, slide, generate),
//   median and p99 over `--runs` repetitions of the 200 human + release steps, for W 5 and 15
//   with 15 iterations, Adam (the presets' settings: W 5 = vcbot, W 15 = reference) and Ceres
//   LBFGS, in float and double; and the mean window loss along each one's own (closed-loop) run.
//   Last row: the NRL mode (preset nrl, noise off; issue 44), W 5.
// Table 2: equal wall time on the same problems. Along one closed-loop Adam run, each step's
//   window is solved again from the same start A by Adam and by Ceres, each capped at 1, 2 and 4
//   times Adam's median step time (15 iterations, float) with no iteration cap, and with 15
//   iterations each and no cap; reported: the mean best window loss, iterations per solve and
//   how often Ceres ends at or below Adam. W 5 uses the vcbot preset, W 15 the reference preset
//   (lr 0.1, training w).
//
//   bench_regress [--runs N] [--model FILE.dpvrnn]   (default: import ../shared/data/vcbot)
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <limits>
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
  std::vector<int> iterations, evaluations;
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
      tr.evaluations.push_back(r.evaluations);
    }
  }
  return tr;
}

// A copy of one window problem that remembers the lowest loss evaluated.
class Replayed final : public WindowFunction<float> {
 public:
  explicit Replayed(const WindowObjective<float>& src) : obj_(src.weights(), src.window()) {
    obj_.SetWindow(src.targets(), src.start(), src.eps(), src.meta_prior());
  }
  double Evaluate(const AdaptiveVariables<float>& a, AdaptiveVariables<float>* grad) override {
    const double l = obj_.Evaluate(a, grad).loss;
    best = std::min(best, l);
    return l;
  }
  double best = std::numeric_limits<double>::infinity();

 private:
  WindowObjective<float> obj_;
};

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
  std::printf("%-6s %-6s %-7s %10s %10s %8s %9s %12s %11s\n", "window", "scalar", "optim", "median ms", "p99 ms", "it/step",
              "eval/step", "of 100 ms", "mean loss");
  double adam_float_median[2] = {0, 0};
  for (int wi = 0; wi < 2; ++wi) {
    const int window = wi == 0 ? 5 : 15;
    for (int si = 0; si < 2; ++si) {
      for (auto kind : {OptimizerKind::kAdam, OptimizerKind::kCeres}) {
        std::vector<double> ms;
        double its = 0, evals = 0, loss = 0;
        for (int r = 0; r < runs; ++r) {
          const Trace tr = si == 0 ? Run<float>(*model, beak, Options(window, kind), nullptr, 0)
                                   : Run<double>(*model, beak, Options(window, kind), nullptr, 0);
          ms.insert(ms.end(), tr.step_ms.begin(), tr.step_ms.end());
          for (int it : tr.iterations) its += it;
          for (int e : tr.evaluations) evals += e;
          loss += Mean(tr.loss) / runs;
        }
        const double med = Percentile(ms, 0.5);
        if (si == 0 && kind == OptimizerKind::kAdam) adam_float_median[wi] = med;
        std::printf("%-6d %-6s %-7s %10.4f %10.4f %8.1f %9.1f %11.2f%% %11.5f\n", window, si == 0 ? "float" : "double",
                    ToString(kind), med, Percentile(ms, 0.99), its / static_cast<double>(ms.size()),
                    evals / static_cast<double>(ms.size()), med / 100 * 100, loss);
      }
    }
  }
  {  // The NRL mode (preset nrl, noise off): NRL's own error regression step by step (issue 44).
    ErrorRegressionOptions o = ErrorRegressionOptions::Preset("nrl").value();
    o.noise = NoiseMode::kOff;
    std::vector<double> ms;
    double its = 0, loss = 0;
    for (int r = 0; r < runs; ++r) {
      const Trace tr = Run<float>(*model, beak, o, nullptr, 0);
      ms.insert(ms.end(), tr.step_ms.begin(), tr.step_ms.end());
      for (int it : tr.iterations) its += it;
      loss += Mean(tr.loss) / runs;
    }
    const double med = Percentile(ms, 0.5);
    std::printf("%-6d %-6s %-7s %10.4f %10.4f %8.1f %9.1f %11.2f%% %11.5f   (preset nrl: NRL's ER, its loss)\n", o.window,
                "float", "nrl", med, Percentile(ms, 0.99), its / static_cast<double>(ms.size()),
                its / static_cast<double>(ms.size()), med / 100 * 100, loss);
  }
  std::printf("\nEqual wall time, same problems: along one closed-loop Adam run (float), every step's window is solved\n"
              "again from the same start A by both optimisers, each capped at k x Adam's float median step time above\n"
              "(no iteration cap). Mean best window loss (N-ELBO) over the 200 human + release steps, iterations per\n"
              "solve, and the share of solves where Ceres ends at or below Adam.\n");
  std::printf("%-6s %6s %9s %12s %12s %9s %9s %10s\n", "window", "budget", "ms", "adam loss", "ceres loss", "adam it",
              "ceres it", "ceres<=adam");
  for (int wi = 0; wi < 2; ++wi) {
    const int window = wi == 0 ? 5 : 15;
    for (double k : {1.0, 2.0, 4.0, -1.0}) {  // -1: 15 iterations each, no time cap
      const double budget_s = k > 0 ? 1e-3 * k * adam_float_median[wi] : 0;
      auto er = ErrorRegression<float>::Create(*model, Options(window, OptimizerKind::kAdam)).value();
      (void)er->Reset(kHead, 1);
      AdamWindowOptimizer<float> adam(Options(window, OptimizerKind::kAdam).adam);
      CeresWindowOptimizer<float> ceres(CeresOptions{});
      std::array<double, 2> executed{er->intention()[0], er->intention()[1]};
      double loss[2] = {0, 0}, its[2] = {0, 0};
      int n = 0, ceres_le = 0;
      for (int i = 0; i < kLeadIn + kHuman + kRelease; ++i) {
        const int t = i - kLeadIn;
        double tx = er->intention()[0], ty = er->intention()[1];
        if (t >= 0 && t < kHuman) {
          tx = 0.9 * beak(0, t % beak.cols()) + 0.1 * tx;
          ty = 0.9 * beak(1, t % beak.cols()) + 0.1 * ty;
        }
        executed[0] += std::clamp(tx - executed[0], -5.0, 5.0);
        executed[1] += std::clamp(ty - executed[1], -5.0, 5.0);
        er->Step(executed.data());
        if (t < 0) continue;
        double best[2];
        for (int o = 0; o < 2; ++o) {
          Replayed f(er->last_objective());
          AdaptiveVariables<float> a = er->last_start_a();
          const auto deadline = budget_s > 0 ? SteadyClock::now() + std::chrono::duration_cast<SteadyClock::duration>(
                                                                       std::chrono::duration<double>(budget_s))
                                             : SteadyClock::time_point::max();
          WindowOptimizer<float>& opt = o == 0 ? static_cast<WindowOptimizer<float>&>(adam) : ceres;
          const SolveReport r = opt.Minimize(f, a, SolveBudget{k > 0 ? 100000 : 15, deadline});
          best[o] = f.best;
          loss[o] += f.best;
          its[o] += r.iterations;
        }
        ceres_le += best[1] <= best[0] * (1 + 1e-6);
        ++n;
      }
      char label[16];
      std::snprintf(label, sizeof label, k > 0 ? "%.0fx" : "15 it", k);
      std::printf("%-6d %6s %9.4f %12.5f %12.5f %9.1f %9.1f %9.0f%%\n", window, label, 1e3 * budget_s, loss[0] / n,
                  loss[1] / n, its[0] / n, its[1] / n, 100.0 * ceres_le / n);
    }
  }
  return 0;
}
