#include "pvrnn_commands.hpp"

#include <CLI/CLI.hpp>

#include <unistd.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include "dyad/interrupt.hpp"
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "dyad/pvrnn/analytic_dataset.hpp"
#include "dyad/pvrnn/error_regression.hpp"
#include "dyad/pvrnn/model_file.hpp"
#include "dyad/pvrnn/nrl_import.hpp"
#include "dyad/pvrnn/nrl_trainer.hpp"
#include "dyad/pvrnn/prior_generator.hpp"
#include "dyad/pvrnn/train_config.hpp"
#include "dyad/pvrnn/trainer.hpp"
#include "exit_code.hpp"
#include "text_output.hpp"

namespace dyad::cli {
namespace {

using namespace dyad::pvrnn;
using Clock = std::chrono::steady_clock;

using tools::ExitCode;
using enum tools::ExitCode;

ExitCode Fail(ExitCode code, const std::string& msg) {
  std::fprintf(stderr, "error: %s\n", msg.c_str());
  return code;
}

std::string Duration(double s) {
  char buf[32];
  if (s < 120) std::snprintf(buf, sizeof buf, "%.0fs", s);
  else if (s < 7200) std::snprintf(buf, sizeof buf, "%dm%02ds", static_cast<int>(s) / 60, static_cast<int>(s) % 60);
  else std::snprintf(buf, sizeof buf, "%dh%02dm", static_cast<int>(s) / 3600, (static_cast<int>(s) / 60) % 60);
  return buf;
}

// The model training starts from: the checkpoint (--resume), else a new one of the config's
// shape; with its provenance. kOk, or the exit code having said why.
ExitCode StartingModel(const TrainConfig& c, const std::string& config_path, const Dataset& data, bool resume, Model* init) {
  if (resume) {
    auto ck = LoadModel(c.checkpoint);
    if (!ck.ok()) return Fail(kBadInput, "--resume: " + ck.status().message());
    if (!ck->training) return Fail(kBadInput, c.checkpoint + ": has no training state (not a checkpoint)");
    if (!(ck->spec == c.spec)) return Fail(kBadInput, c.checkpoint + ": model shape differs from " + config_path);
    *init = std::move(ck.value());
  } else {
    *init = Model::Initialize(c.spec, data.steps(), data.size(), c.seed);
  }
  init->provenance.source = "dyad train " + config_path;
  init->provenance.dataset = c.dataset;
  init->provenance.seed = c.seed;
  init->provenance.scalar = c.scalar;
  return kOk;
}

// The folders of the outputs made, and the log CSV opened (appended to on --resume) with its
// header when new. kOk, or the exit code having said why.
ExitCode OpenTrainingLog(const TrainConfig& c, bool resume, std::ofstream* csv) {
  for (const std::string& f : {c.output, c.checkpoint, c.log_csv}) {
    const auto dir = std::filesystem::path(f).parent_path();
    std::error_code ec;
    if (!dir.empty()) std::filesystem::create_directories(dir, ec);
    if (ec) return Fail(kFailure, dir.string() + ": cannot create folder: " + ec.message());
  }
  csv->open(c.log_csv, resume && std::filesystem::exists(c.log_csv) ? std::ios::app : std::ios::trunc);
  if (!*csv) return Fail(kFailure, c.log_csv + ": cannot open for writing");
  if (!resume || csv->tellp() == 0) {
    *csv << "epoch,reconstruction_q,reconstruction_p,regulation,loss";
    for (int k = 0; k < c.spec.num_layers(); ++k) *csv << ",kl_layer" << k;
    *csv << ",elapsed_s\n";
  }
  return kOk;
}

template <typename Scalar>
ExitCode RunTraining(const TrainConfig& c, const std::string& config_path, const Dataset& data, bool resume) {
  Model init;
  if (ExitCode code = StartingModel(c, config_path, data, resume, &init); code != kOk) return code;
  TrainerOptions opts;
  opts.adam = c.adam;
  opts.seed = c.seed;
  opts.sample_noise = c.noise;
  opts.threads = static_cast<int>(c.threads);
  auto made = Trainer<Scalar>::Create(init, data, opts);
  if (!made.ok()) return Fail(kBadInput, made.status().message());
  Trainer<Scalar>& trainer = *made.value();
  const int64_t start_epoch = trainer.epoch();
  if (start_epoch >= c.epochs)
    return Fail(kBadInput, c.checkpoint + ": already at epoch " + std::to_string(start_epoch) + " of " + std::to_string(c.epochs));

  std::ofstream csv;
  if (ExitCode code = OpenTrainingLog(c, resume, &csv); code != kOk) return code;
  const bool tty = isatty(fileno(stdout));
  std::printf("training %s (%d sequences x %d steps) from epoch %lld to %lld, %s, seed %llu\n", c.dataset.c_str(),
              data.size(), data.steps(), static_cast<long long>(start_epoch), static_cast<long long>(c.epochs),
              c.scalar.c_str(), static_cast<unsigned long long>(c.seed));
  std::string per_primitive;
  for (int n : data.SequencesPerPrimitive()) per_primitive += (per_primitive.empty() ? "" : ", ") + std::to_string(n);
  std::printf("sequences per primitive (samples of primitives 0..%d): %s\n", data.primitives() - 1, per_primitive.c_str());
  auto snapshot = [&](bool with_state, const LossTerms& l) {
    Model m = trainer.Snapshot(with_state);
    m.provenance.epochs = trainer.epoch();
    m.provenance.final_loss = l.loss;
    m.provenance.final_reconstruction = l.reconstruction;
    m.provenance.final_regulation = l.regulation;
    return m;
  };
  InterruptWatcher interrupt;  // Ctrl-C: the loop saves a checkpoint and stops
  const auto t0 = Clock::now();
  LossTerms l;
  while (trainer.epoch() < c.epochs) {
    l = trainer.Epoch();
    const int64_t e = trainer.epoch();
    if (!std::isfinite(l.loss)) {
      std::printf("\n");
      return Fail(kFailure, "training diverged at epoch " + std::to_string(e) + " (loss " + std::to_string(l.loss) + ")");
    }
    const bool interrupted = interrupt.interrupted();
    if (e % c.log_every == 0 || e == c.epochs || interrupted) {
      const double elapsed = std::chrono::duration<double>(Clock::now() - t0).count();
      const double re_p = trainer.PriorReconstruction(true, c.seed + static_cast<uint64_t>(e));
      const double eta = elapsed / static_cast<double>(e - start_epoch) * static_cast<double>(c.epochs - e);
      std::printf("%sepoch %lld/%lld  RE_Q %.4g  RE_P %.4g  Regulation %.4g  loss %.4g  %.3f ms/epoch  ETA %s%s",
                  tty ? "\r\033[K" : "", static_cast<long long>(e), static_cast<long long>(c.epochs), l.reconstruction,
                  re_p, l.regulation, l.loss, 1e3 * elapsed / static_cast<double>(e - start_epoch),
                  Duration(eta).c_str(), tty ? "" : "\n");
      std::fflush(stdout);
      using tools::CsvNumber;  // exact: the log's numbers read back to the doubles computed
      csv << e << ',' << CsvNumber(l.reconstruction) << ',' << CsvNumber(re_p) << ',' << CsvNumber(l.regulation) << ','
          << CsvNumber(l.loss);
      for (double kl : l.kl_per_layer) csv << ',' << CsvNumber(kl);
      csv << ',' << CsvNumber(elapsed) << '\n';
      csv.flush();
    }
    const bool checkpoint_due = c.checkpoint_every > 0 && e % c.checkpoint_every == 0;
    if (checkpoint_due || interrupted) {
      if (Status s = SaveModel(snapshot(true, l), c.checkpoint); !s.ok()) return Fail(kFailure, s.message());
    }
    if (interrupted) {
      std::printf("\ninterrupted (%s) at epoch %lld: checkpoint saved to %s (continue with --resume)\n",
                  SignalName(interrupt.signal()), static_cast<long long>(e), c.checkpoint.c_str());
      return tools::ForSignal(interrupt.signal());  // stopped by a person: neither done nor failed
    }
  }
  if (tty) std::printf("\n");
  if (Status s = SaveModel(snapshot(true, l), c.checkpoint); !s.ok()) return Fail(kFailure, s.message());
  if (Status s = SaveModel(snapshot(false, l), c.output); !s.ok()) return Fail(kFailure, s.message());
  std::printf("done: %lld epochs in %s, loss %.4f; model written to %s\n",
              static_cast<long long>(c.epochs - start_epoch),
              Duration(std::chrono::duration<double>(Clock::now() - t0).count()).c_str(), l.loss, c.output.c_str());
  return kOk;
}

// `prior: nrl`: NRL's training (NrlTrainer) from NRL's initial state, in one run (no checkpoints,
// no --resume); the log's reconstruction_p is left empty (NRL's RE_P is not computed).
ExitCode RunNrlTraining(const TrainConfig& c, const std::string& config_path, const Dataset& data, bool resume) {
  if (resume)
    return Fail(kBadInput, "--resume: " + config_path + " has prior: nrl, which trains in one run from NRL's initial state");
  NrlTrainerOptions opts;
  opts.adam = c.adam;
  opts.noise = c.noise;
  opts.seed = c.seed;
  auto made = NrlTrainer::Create(NrlTrainer::InitialModel(c.spec, data.steps(), data.size()), data, opts);
  if (!made.ok()) return Fail(kBadInput, made.status().message());
  NrlTrainer& trainer = *made.value();
  std::ofstream csv;
  if (ExitCode code = OpenTrainingLog(c, false, &csv); code != kOk) return code;
  std::printf("training %s (%d sequences x %d steps) NRL's way (prior: nrl) for %lld epochs, noise %s, seed %llu\n",
              c.dataset.c_str(), data.size(), data.steps(), static_cast<long long>(c.epochs), c.noise ? "on" : "off",
              static_cast<unsigned long long>(c.seed));
  InterruptWatcher interrupt;  // Ctrl-C: the model so far is written and the run stops
  const auto t0 = Clock::now();
  LossTerms l;
  while (trainer.epoch() < c.epochs && !interrupt.interrupted()) {
    l = trainer.Epoch();
    const int64_t e = trainer.epoch();
    if (!std::isfinite(l.loss))
      return Fail(kFailure, "training diverged at epoch " + std::to_string(e) + " (loss " + std::to_string(l.loss) + ")");
    if (e % c.log_every != 0 && e != c.epochs) continue;
    const double elapsed = std::chrono::duration<double>(Clock::now() - t0).count();
    std::printf("epoch %lld/%lld  RE_Q %.4g  Regulation %.4g  loss %.4g  %.3f ms/epoch\n", static_cast<long long>(e),
                static_cast<long long>(c.epochs), l.reconstruction, l.regulation, l.loss, 1e3 * elapsed / static_cast<double>(e));
    std::fflush(stdout);
    using tools::CsvNumber;
    csv << e << ',' << CsvNumber(l.reconstruction) << ",," << CsvNumber(l.regulation) << ',' << CsvNumber(l.loss);
    for (double kl : l.kl_per_layer) csv << ',' << CsvNumber(kl);
    csv << ',' << CsvNumber(elapsed) << '\n';
    csv.flush();
  }
  Model m = trainer.Snapshot();
  m.provenance.source = "dyad train " + config_path + " (prior: nrl)";
  m.provenance.dataset = c.dataset;
  m.provenance.seed = c.seed;
  m.provenance.scalar = "float";
  m.provenance.final_loss = l.loss;
  m.provenance.final_reconstruction = l.reconstruction;
  m.provenance.final_regulation = l.regulation;
  if (Status s = SaveModel(m, c.output); !s.ok()) return Fail(kFailure, s.message());
  std::printf("%s: %lld epochs, loss %.4f; model written to %s\n", interrupt.interrupted() ? "interrupted" : "done",
              static_cast<long long>(trainer.epoch()), l.loss, c.output.c_str());
  return interrupt.interrupted() ? tools::ForSignal(interrupt.signal()) : kOk;
}

ExitCode Train(const std::string& config_path, bool resume, const std::vector<std::string>& sets) {
  auto c = LoadTrainConfig(config_path, sets);
  if (!c.ok()) return Fail(kBadInput, c.status().message());
  auto data = LoadNrlDataset(c->dataset);
  if (!data.ok()) return Fail(kBadInput, data.status().message());
  for (const std::string& w : data->warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  if (c->loops > 1) data = RepeatSequences(*data, static_cast<int>(c->loops));
  if (data->dofs() != c->spec.num_dofs())
    return Fail(kBadInput, config_path + ": encoding.dofs lists " + std::to_string(c->spec.num_dofs()) +
                               " DOFs, the data set " + c->dataset + " has " + std::to_string(data->dofs()));
  if (c->prior == "nrl") return RunNrlTraining(c.value(), config_path, data.value(), resume);
  return c->scalar == "double" ? RunTraining<double>(c.value(), config_path, data.value(), resume)
                               : RunTraining<float>(c.value(), config_path, data.value(), resume);
}

ExitCode ImportNrl(const NrlImportOptions& o, const std::string& out) {
  auto m = ImportNrlModel(o);
  if (!m.ok()) return Fail(kBadInput, m.status().message());
  if (Status s = SaveModel(m.value(), out); !s.ok()) return Fail(kFailure, s.message());
  std::printf("imported %s: %d layers, %d primitives x %d steps, epoch %lld -> %s\n", o.model_dir.c_str(),
              m->spec.num_layers(), m->sequences(), m->steps(), static_cast<long long>(m->provenance.epochs), out.c_str());
  return kOk;
}

ExitCode GenerateModel(const std::string& path, int primitive, int steps, const std::string& out, uint64_t seed, bool no_noise) {
  auto m = LoadModel(path);
  if (!m.ok()) return Fail(kBadInput, m.status().message());
  if (primitive < 0 || primitive >= m->sequences())
    return Fail(kBadInput, "--primitive " + std::to_string(primitive) + ": the model has primitives 0.." +
                               std::to_string(m->sequences() - 1));
  constexpr int kMaxSteps = 1'000'000;  // 28 h at 100 ms; bounds the memory of the trajectory
  if (steps <= 0 || steps > kMaxSteps)
    return Fail(kBadInput, "--steps " + std::to_string(steps) + ": must be in 1.." + std::to_string(kMaxSteps));
  GenerateOptions g;
  g.noise = !no_noise;
  g.seed = seed;
  const Eigen::MatrixXd xy = GeneratePrimitive(m.value(), primitive, steps, g);
  std::FILE* f = out.empty() ? stdout : std::fopen(out.c_str(), "w");
  if (f == nullptr) return Fail(kFailure, out + ": cannot open for writing");
  for (int t = 0; t < xy.cols(); ++t) {
    for (int i = 0; i < xy.rows(); ++i) std::fprintf(f, i ? ",%.17g" : "%.17g", xy(i, t));
    std::fprintf(f, "\n");
  }
  if (f != stdout && std::fclose(f) != 0) return Fail(kFailure, out + ": write failed");
  return kOk;
}

// A trajectory CSV: `x,y` rows without a header, or a header naming columns `x` and `y` (as
// `dyad bag export` writes for CartesianState; other columns ignored). Errors: `file:line: ...`.
StatusOr<std::vector<std::array<double, 2>>> ReadTrajectory(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Status::InvalidArgument(path + ": cannot open for reading");
  std::vector<std::array<double, 2>> out;
  std::string line;
  int line_no = 0, col_x = 0, col_y = 1;
  size_t min_cells = 2;
  auto split = [](const std::string& l) {
    std::vector<std::string> cells;
    std::stringstream ss(l);
    std::string c;
    while (std::getline(ss, c, ',')) cells.push_back(c);
    if (!l.empty() && l.back() == ',') cells.emplace_back();
    return cells;
  };
  auto number = [](std::string c, double* v) {
    while (!c.empty() && (c.back() == '\r' || c.back() == ' ')) c.pop_back();
    while (!c.empty() && c.front() == ' ') c.erase(c.begin());
    if (c.empty()) return false;
    char* end = nullptr;
    *v = std::strtod(c.c_str(), &end);
    return end == c.c_str() + c.size() && std::isfinite(*v);
  };
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line == "\r") continue;
    const std::vector<std::string> cells = split(line);
    double v = 0;
    if (out.empty() && line_no == 1 && !number(cells[0], &v)) {  // a header
      col_x = col_y = -1;
      for (size_t i = 0; i < cells.size(); ++i) {
        std::string c = cells[i];
        while (!c.empty() && (c.back() == '\r' || c.back() == ' ')) c.pop_back();
        if (c == "x") col_x = static_cast<int>(i);
        if (c == "y") col_y = static_cast<int>(i);
      }
      if (col_x < 0 || col_y < 0)
        return Status::InvalidArgument(path + ":1: header has no columns named x and y (got: " + line + ")");
      min_cells = static_cast<size_t>(std::max(col_x, col_y)) + 1;
      continue;
    }
    if (cells.size() < min_cells)
      return Status::InvalidArgument(path + ":" + std::to_string(line_no) + ": expected at least " +
                                     std::to_string(min_cells) + " comma-separated values, got " + std::to_string(cells.size()));
    std::array<double, 2> xy{};
    if (!number(cells[col_x], &xy[0]) || !number(cells[col_y], &xy[1]))
      return Status::InvalidArgument(path + ":" + std::to_string(line_no) + ": x and y must be finite numbers, got '" +
                                     cells[col_x] + "', '" + cells[col_y] + "'");
    out.push_back(xy);
  }
  if (out.empty()) return Status::InvalidArgument(path + ": no positions (expected x,y rows)");
  return out;
}

struct RegressArgs {
  std::string model, trajectory, out, preset = "vcbot", optimizer, a_init, noise;
  std::optional<int> window, iterations;
  std::optional<double> lr, beta1, beta2, epsilon;
  int start_primitive = 0;
  double budget_ms = 0;
  std::vector<double> meta_prior;
  uint64_t seed = 1;
};

ExitCode Regress(const RegressArgs& a) {
  auto o = ErrorRegressionOptions::Preset(a.preset);
  if (!o) return Fail(kBadInput, "--preset " + a.preset + ": must be vcbot, reference or nrl");
  if (a.window) o->window = *a.window;
  if (a.iterations) o->iterations = *a.iterations;
  if (!a.optimizer.empty()) {
    auto k = ParseOptimizerKind(a.optimizer);
    if (!k) return Fail(kBadInput, "--optimizer " + a.optimizer + ": must be adam or ceres");
    o->optimizer = *k;
  }
  if (!a.a_init.empty()) {
    auto k = ParseAInit(a.a_init);
    if (!k) return Fail(kBadInput, "--a-init " + a.a_init + ": must be zero, copy or prior");
    o->a_init = *k;
  }
  if (!a.noise.empty()) {
    auto k = ParseNoiseMode(a.noise);
    if (!k) return Fail(kBadInput, "--noise " + a.noise + ": must be off, fixed or resample");
    o->noise = *k;
  }
  if (a.lr) o->adam.lr = *a.lr;
  if (a.beta1) o->adam.beta1 = *a.beta1;
  if (a.beta2) o->adam.beta2 = *a.beta2;
  if (a.epsilon) o->adam.epsilon = *a.epsilon;
  if (!a.meta_prior.empty()) o->meta_prior = a.meta_prior;
  if (a.budget_ms < 0) return Fail(kBadInput, "--budget-ms: must be >= 0 (0: no cap)");
  auto model = LoadModel(a.model);
  if (!model.ok()) return Fail(kBadInput, model.status().message());
  if (model->spec.num_dofs() != 2)
    return Fail(kBadInput, a.model + ": has " + std::to_string(model->spec.num_dofs()) + " DOFs; regress reads x,y (2)");
  if (auto p = o->Problems(model->spec.num_layers()); !p.empty()) {
    // Name the option as spelled on the command line.
    std::string field = p.front().field;
    for (auto& ch : field) if (ch == '_') ch = '-';
    if (field.rfind("adam.", 0) == 0) field = field.substr(5);
    return Fail(kBadInput, "--" + field + ": " + p.front().message);
  }
  auto trajectory = ReadTrajectory(a.trajectory);
  if (!trajectory.ok()) return Fail(kBadInput, trajectory.status().message());
  auto er = ErrorRegression<float>::Create(model.value(), o.value());
  if (!er.ok()) return Fail(kBadInput, er.status().message());
  if (Status s = (*er)->Reset(a.start_primitive, a.seed); !s.ok())
    return Fail(kBadInput, "--" + std::string("start-primitive ") + std::to_string(a.start_primitive) + ": " + a.model +
                               " has primitives 0.." + std::to_string(model->sequences() - 1));
  std::FILE* f = a.out.empty() ? stdout : std::fopen(a.out.c_str(), "w");
  if (f == nullptr) return Fail(kFailure, a.out + ": cannot open for writing");
  std::fprintf(f, "step,executed_x,executed_y,intended_x,intended_y,nelbo,reconstruction,regulation,iterations,evaluations,time_ms\n");
  std::fprintf(f, "-1,,,%.9g,%.9g,,,,0,0,0\n", (*er)->intention()[0], (*er)->intention()[1]);
  for (const auto& xy : trajectory.value()) {
    const auto deadline = a.budget_ms > 0
                              ? SteadyClock::now() + std::chrono::duration_cast<SteadyClock::duration>(
                                                         std::chrono::duration<double, std::milli>(a.budget_ms))
                              : SteadyClock::time_point::max();
    const StepResult& r = (*er)->Step(xy.data(), deadline);
    if (!r.regressed) {  // nrl: free generation until the window is full, no loss yet
      std::fprintf(f, "%lld,%.9g,%.9g,%.9g,%.9g,,,,0,0,%.6f\n", static_cast<long long>(r.step), xy[0], xy[1], r.intention[0],
                   r.intention[1], 1e3 * r.optimisation_s);
      continue;
    }
    std::fprintf(f, "%lld,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%d,%d,%.6f\n", static_cast<long long>(r.step), xy[0], xy[1],
                 r.intention[0], r.intention[1], r.loss.loss, r.loss.reconstruction, r.loss.regulation, r.iterations,
                 r.evaluations, 1e3 * r.optimisation_s);
  }
  if (f != stdout && std::fclose(f) != 0) return Fail(kFailure, a.out + ": write failed");
  return kOk;
}

}  // namespace

void AddPvrnnCommands(CLI::App& app, int& exit_code) {
  {
    auto* cmd = app.add_subcommand("train", "Train a PV-RNN model from a YAML config (Ctrl-C saves a checkpoint)");
    auto config = std::make_shared<std::string>();
    auto resume = std::make_shared<bool>(false);
    auto sets = std::make_shared<std::vector<std::string>>();
    cmd->add_option("config", *config, "Training config (YAML)")->required();
    cmd->add_flag("--resume", *resume, "Continue from the config's checkpoint file");
    cmd->add_option("--set", *sets, "Override a config value, e.g. --set adam.lr=0.002 (repeatable)");
    cmd->callback([&exit_code, config, resume, sets] { exit_code = tools::Code(Train(*config, *resume, *sets)); });
  }
  {
    auto* cmd = app.add_subcommand("import-nrl", "Convert an NRL/VCBot model folder into a dyad model file");
    auto o = std::make_shared<NrlImportOptions>();
    auto out = std::make_shared<std::string>();
    cmd->add_option("model_dir", o->model_dir, "NRL model folder (L0_w_p.d, ...)")->required();
    cmd->add_option("--properties", o->properties_file, "properties_*.d of the model")->required();
    cmd->add_option("--dataset", o->dataset_dir, "Data set folder the model was trained on")->required();
    cmd->add_option("-o,--output", *out, "Output model file (.dpvrnn)")->required();
    cmd->callback([&exit_code, o, out] { exit_code = tools::Code(ImportNrl(*o, *out)); });
  }
  {
    auto* gen = app.add_subcommand("generate", "Generate trajectories or data sets");
    gen->require_subcommand(1);
    auto* model = gen->add_subcommand("model", "Write a primitive generated from the prior (CSV x,y per step)");
    struct Args {
      std::string path, out;
      int primitive = 0, steps = 72;
      uint64_t seed = 1;
      bool no_noise = false;
    };
    auto a = std::make_shared<Args>();
    model->add_option("model", a->path, "Model file (.dpvrnn)")->required();
    model->add_option("--primitive", a->primitive, "Primitive (sequence) index")->required();
    model->add_option("--steps", a->steps, "Steps to generate")->required();
    model->add_option("-o,--output", a->out, "CSV file (default: stdout)");
    auto* seed = model->add_option("--seed", a->seed, "Noise seed (default 1)");
    auto* nn = model->add_flag("--no-noise", a->no_noise, "Means only (reproducible)");
    seed->excludes(nn);
    model->callback([&exit_code, a] {
      exit_code = tools::Code(GenerateModel(a->path, a->primitive, a->steps, a->out, a->seed, a->no_noise));
    });
    auto* ds = gen->add_subcommand("dataset", "Write the built-in analytic data set (7 closed shapes, 72 steps, 2 DOF)");
    auto dir = std::make_shared<std::string>();
    ds->add_option("--out", *dir, "Output folder (NRL layout)")->required();
    ds->callback([&exit_code, dir] {
      Status s = WriteNrlDataset(MakeAnalyticDataset(), *dir);
      exit_code = tools::Code(s.ok() ? kOk : Fail(kFailure, s.message()));
      if (s.ok()) std::printf("wrote 7 primitives x 72 steps to %s\n", dir->c_str());
    });
  }
  {
    auto* cmd = app.add_subcommand("regress", "Offline error regression over a trajectory CSV (x,y per step); per-step CSV out");
    auto a = std::make_shared<RegressArgs>();
    cmd->add_option("model", a->model, "Model file (.dpvrnn)")->required();
    cmd->add_option("trajectory", a->trajectory, "Executed positions: x,y rows, or a CSV with columns named x and y (dyad bag export)")->required();
    cmd->add_option("-o,--output", a->out, "Per-step CSV (default: stdout)");
    cmd->add_option("--preset", a->preset,
                    "vcbot (W 5, 15 it, Adam 0.3/0.1/0.95, w 1e-5), reference (W 15, 15 it, Adam 0.1, training w) or nrl "
                    "(NRL's own error regression with the vcbot numbers, Adam epsilon 1e-20; docs/pvrnn.md)");
    cmd->add_option("--window", a->window, "Window W (default: the preset's)");
    cmd->add_option("--iterations", a->iterations, "Optimiser iterations per step (default: the preset's)");
    cmd->add_option("--optimizer", a->optimizer, "adam or ceres");
    cmd->add_option("--lr", a->lr, "Adam step size");
    cmd->add_option("--beta1", a->beta1, "Adam beta1");
    cmd->add_option("--beta2", a->beta2, "Adam beta2");
    cmd->add_option("--epsilon", a->epsilon, "Adam epsilon (default: the preset's; nrl 1e-20)");
    cmd->add_option("--meta-prior", a->meta_prior, "Online meta-prior per layer, e.g. --meta-prior 1e-5 1e-5")->expected(1, 100);
    cmd->add_option("--a-init", a->a_init, "A of the newest window step: zero, copy or prior (default prior)");
    cmd->add_option("--noise", a->noise, "off, fixed or resample (default: the preset's: off; nrl: resample, NRL's N(0,1))");
    cmd->add_option("--start-primitive", a->start_primitive, "Primitive the robot starts on (default 0)");
    cmd->add_option("--seed", a->seed, "Noise seed (default 1)");
    cmd->add_option("--budget-ms", a->budget_ms, "Wall-time cap per step in ms (default: none)");
    cmd->callback([&exit_code, a] { exit_code = tools::Code(Regress(*a)); });
  }
}

}  // namespace dyad::cli
