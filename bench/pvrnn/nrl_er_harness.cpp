// nrl_er_harness: runs the original library's (NRL, github.com/oist-cnru/NRL) online error
// regression on a trained model for the switching workload and writes one CSV row per step.
// Built by bench/pvrnn/nrl_reference.sh against an NRL checkout (not by dyad's CMake: NRL is not
// part of this repository). Contract:
//
//   nrl_er_harness PROPS OUT.csv [--data DIR] [--window W] [--iterations N] [--lr A]
//       [--beta1 B1] [--beta2 B2] [--w W0,W1,...] [--start P] [--lead-in L] [--human H]
//       [--release R] [--pushed Q] [--gain G] [--closed-loop] [--jitter SD] [--seed S]
//
// PROPS is NRL's properties file (modelpath/datapath relative to the working directory); DIR is
// the data set folder with primitive_<p>_0.csv (x,y rows). Defaults are dyad's `vcbot` preset:
// W 5, 15 iterations, Adam lr 0.3, beta1 0.1, beta2 0.95, meta-prior 1e-5 per layer, start on
// primitive 1 (head), push primitive 2 (beak), lead-in 72, human 100, release 100, gain 0.9.
//
// The loop is NRL's own (src/standalone/main.cpp, demonstrateExperiment): per step i,
// e_generate -> intention r_i; executed e_i; push e_i into the window buffer; once the buffer
// holds W positions, e_postdict on the last W. Executed positions follow the switching test of
// components/pvrnn (switching_test.cpp): e_i = e_{i-1} + clip(target_i - e_{i-1}, +-5) per axis,
// e_{-1} = the start primitive's first data point (fixed) or r_0 (closed loop), with
//   target = robot stand-in during the lead-in and the release, and
//   target = G * pushed[t % T] + (1 - G) * stand-in while the human pushes (t = 0..H-1),
// where the stand-in is the start primitive's data set trajectory (default: a FIXED executed
// trajectory, the same for every engine, so traces compare step by step) or NRL's own intention
// r_i (--closed-loop, the switching test's closed loop). --jitter adds N(0, SD) to every
// executed coordinate (seeded), for ensembles.
//
// Output columns: step (lead-in steps negative), executed_x, executed_y, intention_x,
// intention_y (r_i, generated before e_i), loss, reconstruction, regulation (e_postdict's
// output of its best iteration; empty while the window is not yet full: NRL does not regress
// then), then the window's A as NRL keeps it after that postdiction (its e_au_copy/e_al_copy,
// the copy taken at the best iteration), per layer l, window slot k (0 = oldest), unit j:
// a<l>_<k>_mu<j> ..., a<l>_<k>_ls<j> .... Errors: a message naming the argument or file, exit 2.
#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "lib/LibNRL.h"
#include "nrl_harness.hpp"

namespace {

const char kHarness[] = "nrl_er_harness";

struct LayersOf {
  using type = std::vector<oist::ILayer*> oist::NetworkPvrnn::*;
  friend type Get(LayersOf);
};
struct AuCopyOf {
  using type = vectorXf1DContainer oist::LayerPvrnn::*;
  friend type Get(AuCopyOf);
};
struct AlCopyOf {
  using type = vectorXf1DContainer oist::LayerPvrnn::*;
  friend type Get(AlCopyOf);
};
template struct Expose<LayersOf, &oist::NetworkPvrnn::layers>;
template struct Expose<AuCopyOf, &oist::LayerPvrnn::e_au_copy>;
template struct Expose<AlCopyOf, &oist::LayerPvrnn::e_al_copy>;

struct Options {
  std::string props, out, data = "Macaw";
  int window = 5, iterations = 15, start = 1, pushed = 2, lead_in = 72, human = 100, release = 100;
  float lr = 0.3f, beta1 = 0.1f, beta2 = 0.95f;
  double gain = 0.9, jitter = 0;
  unsigned seed = 1;
  bool closed_loop = false;
  std::vector<float> w;
};

double Number(const std::string& opt, const char* text) {
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || !std::isfinite(v)) Fail(opt + ": not a number: '" + text + "'");
  return v;
}

int Count(const std::string& opt, const char* text, int min) {
  const double v = Number(opt, text);
  if (v != std::floor(v) || v < min) Fail(opt + ": must be an integer >= " + std::to_string(min) + ", got " + text);
  return static_cast<int>(v);
}

Options Parse(int argc, char** argv) {
  Options o;
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("--", 0) != 0) {
      positional.push_back(a);
      continue;
    }
    if (a == "--closed-loop") {
      o.closed_loop = true;
      continue;
    }
    if (i + 1 >= argc) Fail(a + ": needs a value");
    const char* v = argv[++i];
    if (a == "--data") o.data = v;
    else if (a == "--window") o.window = Count(a, v, 1);
    else if (a == "--iterations") o.iterations = Count(a, v, 1);
    else if (a == "--start") o.start = Count(a, v, 0);
    else if (a == "--pushed") o.pushed = Count(a, v, 0);
    else if (a == "--lead-in") o.lead_in = Count(a, v, 0);
    else if (a == "--human") o.human = Count(a, v, 0);
    else if (a == "--release") o.release = Count(a, v, 0);
    else if (a == "--seed") o.seed = static_cast<unsigned>(Count(a, v, 0));
    else if (a == "--lr") o.lr = static_cast<float>(Number(a, v));
    else if (a == "--beta1") o.beta1 = static_cast<float>(Number(a, v));
    else if (a == "--beta2") o.beta2 = static_cast<float>(Number(a, v));
    else if (a == "--gain") o.gain = Number(a, v);
    else if (a == "--jitter") o.jitter = Number(a, v);
    else if (a == "--w") {
      std::stringstream ss(v);
      for (std::string item; std::getline(ss, item, ',');) o.w.push_back(static_cast<float>(Number(a, item.c_str())));
    } else Fail(a + ": unknown option");
  }
  if (positional.size() != 2) Fail("usage: nrl_er_harness PROPS OUT.csv [options] (see the header of nrl_er_harness.cpp)");
  o.props = positional[0];
  o.out = positional[1];
  if (o.lr <= 0 || o.beta1 < 0 || o.beta1 >= 1 || o.beta2 < 0 || o.beta2 >= 1)
    Fail("--lr must be > 0 and --beta1, --beta2 in [0, 1)");
  if (o.jitter < 0) Fail("--jitter: must be >= 0");
  return o;
}

std::vector<Eigen::Vector2d> ReadPrimitive(const std::string& dir, int p) {
  const std::string path = dir + "/primitive_" + std::to_string(p) + "_0.csv";
  std::ifstream in(path);
  if (!in) Fail(path + ": cannot open");
  std::vector<Eigen::Vector2d> rows;
  int line_no = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_no;
    if (line.empty()) continue;
    double x = 0, y = 0;
    if (std::sscanf(line.c_str(), "%lf,%lf", &x, &y) != 2) Fail(path + ":" + std::to_string(line_no) + ": expected x,y");
    rows.emplace_back(x, y);
  }
  if (rows.empty()) Fail(path + ": no rows");
  return rows;
}

void WriteHeader(std::ostream& out, const std::vector<int>& z, int window) {
  out << "step,executed_x,executed_y,intention_x,intention_y,loss,reconstruction,regulation";
  for (size_t l = 0; l < z.size(); ++l)
    for (int k = 0; k < window; ++k) {
      for (int j = 0; j < z[l]; ++j) out << ",a" << l << "_" << k << "_mu" << j;
      for (int j = 0; j < z[l]; ++j) out << ",a" << l << "_" << k << "_ls" << j;
    }
  out << "\n";
}

void WriteA(std::ostream& out, const std::vector<oist::ILayer*>& layers) {
  for (oist::ILayer* il : layers) {
    auto* layer = static_cast<oist::LayerPvrnn*>(il);
    const auto& au = layer->*Get(AuCopyOf());
    const auto& al = layer->*Get(AlCopyOf());
    for (size_t k = 0; k < au.size(); ++k) {
      for (int j = 0; j < au[k].size(); ++j) out << "," << au[k][j];
      for (int j = 0; j < al[k].size(); ++j) out << "," << al[k][j];
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = Parse(argc, argv);
  const std::vector<Eigen::Vector2d> own = ReadPrimitive(o.data, o.start), push = ReadPrimitive(o.data, o.pushed);

  oist::LibNRL* nrl = oist::LibNRL::getInstance();
  nrl->newModel(o.props);
  nrl->load();
  if (nrl->getNDof() != 2) Fail(o.props + ": NRL did not load a 2-DOF model (see its messages above)");
  auto* net = dynamic_cast<oist::NetworkPvrnn*>(nrl->*Get(ModelOf()));
  if (net == nullptr) Fail(o.props + ": network is not 'pvrnn'");
  const std::vector<oist::ILayer*>& layers = net->*Get(LayersOf());
  std::vector<float> w = o.w.empty() ? std::vector<float>(layers.size(), 1e-5f) : o.w;
  if (w.size() != layers.size())
    Fail("--w: needs one value per layer (" + std::to_string(layers.size()) + "), got " + std::to_string(w.size()));

  const int steps = o.lead_in + o.human + o.release;
  nrl->e_enable(o.start, o.window, w.data(), steps, o.iterations, o.lr, o.beta1, o.beta2, false, false);
  std::vector<int> z;
  for (oist::ILayer* il : layers) z.push_back(static_cast<int>((static_cast<oist::LayerPvrnn*>(il)->*Get(AuCopyOf()))[0].size()));

  std::ofstream out(o.out);
  if (!out) Fail(o.out + ": cannot write");
  out.precision(9);
  WriteHeader(out, z, o.window);

  std::mt19937 rng(o.seed);
  std::normal_distribution<double> jitter(0.0, o.jitter > 0 ? o.jitter : 1.0);
  std::vector<float> buffer;  // the executed positions, oldest first; NRL gets the last W
  float intention[2] = {0, 0};
  Eigen::Vector2d executed = own[0];
  for (int i = 0; i < steps; ++i) {
    const int t = i - o.lead_in;
    nrl->e_generate(intention);
    const Eigen::Vector2d robot(intention[0], intention[1]);
    if (i == 0 && o.closed_loop) executed = robot;
    const Eigen::Vector2d stand_in = o.closed_loop ? robot : own[i % own.size()];
    const Eigen::Vector2d target =
        t >= 0 && t < o.human ? Eigen::Vector2d(o.gain * push[t % push.size()] + (1 - o.gain) * stand_in) : stand_in;
    executed += (target - executed).cwiseMax(-5.0).cwiseMin(5.0);
    Eigen::Vector2d sent = executed;
    if (o.jitter > 0) sent += Eigen::Vector2d(jitter(rng), jitter(rng));
    buffer.push_back(static_cast<float>(sent.x()));
    buffer.push_back(static_cast<float>(sent.y()));
    out << t << "," << static_cast<float>(sent.x()) << "," << static_cast<float>(sent.y()) << "," << intention[0] << ","
        << intention[1];
    if (static_cast<int>(buffer.size()) >= 2 * o.window) {
      float elbo[3] = {0, 0, 0};
      nrl->e_postdict(buffer.data() + buffer.size() - 2 * o.window, elbo, false);
      out << "," << elbo[0] << "," << elbo[1] << "," << elbo[2];
      WriteA(out, layers);
    } else {
      out << ",,,";
      for (size_t l = 0; l < z.size(); ++l)
        for (int k = 0; k < 2 * o.window * z[l]; ++k) out << ",";
    }
    out << "\n";
  }
  if (!out.flush()) Fail(o.out + ": write failed");
  return 0;
}
