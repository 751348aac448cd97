#include "observer_commands.hpp"

#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "dyad/observer/evaluation.hpp"
#include "dyad/observer/observer_file.hpp"
#include "dyad/observer/training.hpp"
#include "dyad/pvrnn/dataset.hpp"
#include "dyad/pvrnn/model_file.hpp"
#include "exit_code.hpp"

namespace dyad::cli {
namespace {

using namespace dyad::observer;
using tools::ExitCode;
using enum tools::ExitCode;

ExitCode Fail(ExitCode code, const std::string& msg) {
  std::fprintf(stderr, "error: %s\n", msg.c_str());
  return code;
}

std::string Join(const std::vector<uint64_t>& v) {
  std::string s;
  for (size_t i = 0; i < v.size(); ++i) s += (i ? "," : "") + std::to_string(v[i]);
  return s;
}

struct TrainObserverArgs {
  std::string model, output, input = "positions";
  std::vector<uint64_t> seeds = {1, 2, 3, 4, 5};
  std::vector<uint64_t> validation_seeds = {101, 102, 103};
  int epochs = 150, batch = 64, steps = 200, drop = 20, window = 5;
  double lr = 0.001;
  uint64_t seed = 1;
  double min_diagonal = 0;
};

ExitCode TrainObserver(const TrainObserverArgs& a) {
  using Clock = std::chrono::steady_clock;
  auto model = pvrnn::LoadModel(a.model);
  if (!model.ok()) return Fail(kBadInput, model.status().message());
  ClassifierSpec spec = ClassifierSpecFor(model.value());
  if (!ParseInputRepresentation(a.input, &spec.input))
    return Fail(kBadInput, "--input " + a.input + ": must be positions or displacements");
  spec.window = a.window;
  if (Status s = spec.Validate(); !s.ok()) return Fail(kBadInput, "--" + s.message());
  if (a.drop >= a.steps)
    return Fail(kBadInput, "--drop " + std::to_string(a.drop) + ": must be < --steps " + std::to_string(a.steps) +
                               " (the generated steps that remain are the training data)");
  for (uint64_t v : a.validation_seeds)
    for (uint64_t t : a.seeds)
      if (v == t) return Fail(kBadInput, "--validation-seeds: seed " + std::to_string(v) + " is also a training seed");

  PriorDataOptions data;
  data.seeds = a.seeds;
  data.steps = a.steps;
  data.drop = a.drop;
  auto train = GeneratePriorTrajectories(model.value(), data);
  if (!train.ok()) return Fail(kBadInput, train.status().message());
  data.seeds = a.validation_seeds;
  auto validation = GeneratePriorTrajectories(model.value(), data);
  if (!validation.ok()) return Fail(kBadInput, "--validation-seeds: " + validation.status().message());

  TrainOptions options;
  options.epochs = a.epochs;
  options.batch = a.batch;
  options.seed = a.seed;
  options.adam.lr = a.lr;
  options.log_every = std::max(1, a.epochs / 10);
  std::printf("training observer on %s: %d primitives x %zu seeds (%s) x %d steps (first %d dropped), %s, window %d\n",
              a.model.c_str(), model->sequences(), a.seeds.size(), Join(a.seeds).c_str(), a.steps, a.drop,
              ToString(spec.input), spec.window);
  const auto t0 = Clock::now();
  auto trained = TrainClassifier(spec, train.value(), options, [&](const EpochReport& r) {
    std::printf("epoch %d/%d  loss %.4f  train accuracy %.4f  %.1fs\n", r.epoch, a.epochs, r.loss, r.accuracy,
                std::chrono::duration<double>(Clock::now() - t0).count());
    std::fflush(stdout);
  });
  if (!trained.ok()) return Fail(kBadInput, trained.status().message());
  auto cm = EvaluateTrajectories(trained.value(), validation.value());
  if (!cm.ok()) return Fail(kFailure, cm.status().message());

  ObserverFile file;
  file.classifier = std::move(trained.value());
  auto& p = file.provenance;
  p.source = "dyad train-observer " + a.model;
  p.model = a.model;
  p.train_seeds = a.seeds;
  p.validation_seeds = a.validation_seeds;
  p.steps = a.steps;
  p.drop = a.drop;
  p.epochs = a.epochs;
  p.seed = a.seed;
  p.validation_min_diagonal = cm->MinDiagonal();
  p.validation_accuracy = cm->Accuracy();
  std::printf("confusion matrix on validation data (prior, seeds %s; rows: true primitive, row-normalised):\n%s",
              Join(a.validation_seeds).c_str(), cm->ToTable().c_str());
  std::printf("diagonal min %.4f, accuracy %.4f over %lld windows\n", cm->MinDiagonal(), cm->Accuracy(),
              static_cast<long long>(cm->total()));
  const auto dir = std::filesystem::path(a.output).parent_path();
  std::error_code ec;
  if (!dir.empty()) std::filesystem::create_directories(dir, ec);
  if (ec) return Fail(kFailure, dir.string() + ": cannot create folder: " + ec.message());
  if (Status s = SaveObserver(file, a.output); !s.ok()) return Fail(kFailure, s.message());
  std::printf("observer written to %s\n", a.output.c_str());
  if (cm->MinDiagonal() < a.min_diagonal) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "diagonal min %.4f is below --min-diagonal %.4f", cm->MinDiagonal(), a.min_diagonal);
    return Fail(kFailure, buf);
  }
  return kOk;
}

struct EvaluateArgs {
  std::string observer, dataset;
  int loops = 2;
  std::vector<double> noise = {0.0};
  uint64_t seed = 1;
};

// The confusion matrix of the data set's primitives traced as a synthetic human would (looped,
// with noise): how the observer will see a human who follows the data set.
ExitCode EvaluateObserver(const EvaluateArgs& a) {
  for (double noise : a.noise) {  // all checked before the first table is printed
    if (!(noise >= 0)) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "--noise %g: must be >= 0", noise);
      return Fail(kBadInput, buf);
    }
  }
  auto obs = LoadObserver(a.observer);
  if (!obs.ok()) return Fail(kBadInput, obs.status().message());
  auto data = pvrnn::LoadNrlDataset(a.dataset);
  if (!data.ok()) return Fail(kBadInput, data.status().message());
  for (double noise : a.noise) {
    auto cm = EvaluateTrajectories(obs->classifier, DatasetTraces(data.value(), a.loops, noise, a.seed));
    if (!cm.ok()) return Fail(kBadInput, a.dataset + ": " + cm.status().message());
    std::printf("%s traced %d times, noise std %g (seed %llu); rows: true primitive, row-normalised:\n%s",
                a.dataset.c_str(), a.loops, noise, static_cast<unsigned long long>(a.seed), cm->ToTable().c_str());
    std::printf("diagonal min %.4f, accuracy %.4f over %lld windows\n\n", cm->MinDiagonal(), cm->Accuracy(),
                static_cast<long long>(cm->total()));
  }
  return kOk;
}

}  // namespace

void AddObserverCommands(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand(
      "train-observer", "Train the intention classifier on trajectories generated from a PV-RNN model's prior");
  auto a = std::make_shared<TrainObserverArgs>();
  cmd->add_option("model", a->model, "PV-RNN model (.dpvrnn)")->required();
  cmd->add_option("-o,--output", a->output, "Observer file to write (.dobs)")->required();
  cmd->add_option("--seeds", a->seeds, "Prior-noise seeds of the training data (default 1,2,3,4,5)")->delimiter(',');
  cmd->add_option("--validation-seeds", a->validation_seeds, "Prior-noise seeds of the held-out validation data (default 101,102,103)")
      ->delimiter(',');
  cmd->add_option("--epochs", a->epochs, "Training epochs (default 150)")->check(CLI::Range(1, 1000000));
  cmd->add_option("--batch", a->batch, "Mini-batch size (default 64)")->check(CLI::Range(1, 1000000));
  cmd->add_option("--lr", a->lr, "Adam step size (default 0.001)")->check(CLI::PositiveNumber);
  cmd->add_option("--seed", a->seed, "Seed of the initial weights and sample order (default 1)");
  cmd->add_option("--steps", a->steps, "Steps generated per primitive and seed (default 200)")->check(CLI::Range(2, 1000000));
  cmd->add_option("--drop", a->drop, "First steps dropped from each generation (default 20)")->check(CLI::Range(0, 1000000));
  cmd->add_option("--input", a->input, "Input representation: positions | displacements (default positions)");
  cmd->add_option("--window", a->window, "Steps per classified window (default 5)")->check(CLI::Range(1, 1000));
  cmd->add_option("--min-diagonal", a->min_diagonal,
                  "Exit 1 (after writing the file) when the validation diagonal's minimum is below this");
  cmd->callback([&exit_code, a] { exit_code = tools::Code(TrainObserver(*a)); });

  auto* ev = app.add_subcommand("evaluate-observer",
                                "Confusion matrix of an observer on a data set's primitives traced like a human (looped, noisy)");
  auto e = std::make_shared<EvaluateArgs>();
  ev->add_option("observer", e->observer, "Observer file (.dobs)")->required();
  ev->add_option("--dataset", e->dataset, "NRL data set folder (primitive i is class i)")->required();
  ev->add_option("--loops", e->loops, "Times each primitive is traced in a row (default 2)")->check(CLI::Range(1, 1000));
  ev->add_option("--noise", e->noise, "Noise std per axis, workspace units; a list gives one table each (default 0)")
      ->delimiter(',');
  ev->add_option("--seed", e->seed, "Noise seed (default 1)");
  ev->callback([&exit_code, e] { exit_code = tools::Code(EvaluateObserver(*e)); });
}

}  // namespace dyad::cli
