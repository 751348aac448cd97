// nrl_train_harness: runs the original library's (NRL, github.com/oist-cnru/NRL) training from its
// initial state (a fresh model from the properties file: NRL's own initial weights) and writes the
// loss terms of every epoch. Built by bench/pvrnn/nrl_reference.sh against an NRL checkout (not by
// dyad's CMake: NRL is not part of this repository). Contract:
//
//   nrl_train_harness PROPS OUT.csv [--epochs N] [--save-initial DIR]
//
// PROPS is NRL's properties file (datapath relative to the working directory; its modelpath is
// never written: this harness does not call NRL's save but for --save-initial). The epoch loop is
// NRL's own (src/lib/LibNRL.cpp, t_background): every primitive's t_forward, then every
// t_backward, then t_optAdam(epoch, alpha, beta1, beta2) with the properties' alpha, beta1, beta2;
// primitives in order (properties shuffle=false; shuffle=true is refused: it would need NRL's
// private generator). Default N = 200. --save-initial writes the initial model in NRL's format
// (NetworkPvrnn::save) to DIR before training, e.g. for `dyad import-nrl`.
//
// Output columns: epoch (1..N), loss, reconstruction, regulation: t_backward's terms of that
// epoch's pass (before its Adam step), as training.txt's loss, RE_Q and Regulation (9 significant
// digits). Errors: a message naming the argument or file, exit 2.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "lib/LibNRL.h"
#include "nrl_harness.hpp"

namespace {

const char kHarness[] = "nrl_train_harness";

struct TargetsOf {
  using type = vectorXf4DContainer oist::LibNRL::*;
  friend type Get(TargetsOf);
};
struct SeqLenOf {
  using type = int oist::LibNRL::*;
  friend type Get(SeqLenOf);
};
struct FloatOf {
  using type = float oist::LibNRL::*;
};
struct AlphaOf : FloatOf {
  friend type Get(AlphaOf);
};
struct Beta1Of : FloatOf {
  friend type Get(Beta1Of);
};
struct Beta2Of : FloatOf {
  friend type Get(Beta2Of);
};
struct ShuffleOf {
  using type = bool oist::LibNRL::*;
  friend type Get(ShuffleOf);
};
template struct Expose<TargetsOf, &oist::LibNRL::YSoftmax>;
template struct Expose<SeqLenOf, &oist::LibNRL::seqLen>;
template struct Expose<AlphaOf, &oist::LibNRL::t_alpha>;
template struct Expose<Beta1Of, &oist::LibNRL::t_beta1>;
template struct Expose<Beta2Of, &oist::LibNRL::t_beta2>;
template struct Expose<ShuffleOf, &oist::LibNRL::t_shuffle>;

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> positional;
  int epochs = 200;
  std::string save_initial;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("--", 0) != 0) {
      positional.push_back(a);
      continue;
    }
    if (i + 1 >= argc) Fail(a + ": needs a value");
    const std::string v = argv[++i];
    if (a == "--epochs") {
      char* end = nullptr;
      const long n = std::strtol(v.c_str(), &end, 10);
      if (*end != '\0' || n < 1 || n > 1000000) Fail("--epochs: must be an integer in 1..1000000, got '" + v + "'");
      epochs = static_cast<int>(n);
    } else if (a == "--save-initial") {
      save_initial = v;
    } else {
      Fail(a + ": unknown option");
    }
  }
  if (positional.size() != 2) Fail("usage: nrl_train_harness PROPS OUT.csv [--epochs N] [--save-initial DIR]");

  oist::LibNRL* nrl = oist::LibNRL::getInstance();
  nrl->newModel(positional[0]);  // NRL's constructors draw the initial weights (rand())
  oist::INetwork* model = nrl->*Get(ModelOf());
  if (model == nullptr) Fail(positional[0] + ": NRL could not create the model (see its messages above)");
  if (dynamic_cast<oist::NetworkPvrnn*>(model) == nullptr) Fail(positional[0] + ": network is not 'pvrnn'");
  if (nrl->*Get(ShuffleOf())) Fail(positional[0] + ": shuffle=true is not supported (NRL's generator is private)");
  if (!save_initial.empty()) model->save(save_initial);
  vectorXf4DContainer& targets = nrl->*Get(TargetsOf());
  const int seq_len = nrl->*Get(SeqLenOf());
  const float alpha = nrl->*Get(AlphaOf()), beta1 = nrl->*Get(Beta1Of()), beta2 = nrl->*Get(Beta2Of());

  std::ofstream out(positional[1]);
  if (!out) Fail(positional[1] + ": cannot write");
  out.precision(9);
  out << "epoch,loss,reconstruction,regulation\n";
  const int primitives = static_cast<int>(targets.size());
  for (int epoch = 1; epoch <= epochs; ++epoch) {  // LibNRL::t_background's loop body
    vectorXf3DContainer all_x;
    for (int p = 0; p < primitives; ++p) {
      vectorXf2DContainer x;
      model->t_forward(seq_len, p, x);
      all_x.push_back(x);
    }
    float loss = 0, reconstruction = 0, regulation = 0;
    for (int p = 0; p < primitives; ++p) {
      vectorXf3DContainer y = targets[p];
      vectorXf2DContainer x = all_x[p];
      model->t_backward(p, x, y, reconstruction, regulation, loss);
    }
    model->t_optAdam(epoch, alpha, beta1, beta2);
    out << epoch << "," << loss << "," << reconstruction << "," << regulation << "\n";
    if (!std::isfinite(loss)) Fail("the loss is not finite at epoch " + std::to_string(epoch));
  }
  if (!out.flush()) Fail(positional[1] + ": write failed");
  return 0;
}
