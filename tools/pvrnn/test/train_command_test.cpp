// `dyad train` on a data set in NRL's own layout (no dataset.d, several samples per primitive),
// run as a real process: it trains on every sample and says how many per primitive.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "dyad/pvrnn/model_file.hpp"
#include "dyad/pvrnn/nrl_trainer.hpp"
#include "dyad/pvrnn/train_config.hpp"

namespace fs = std::filesystem;

namespace {

std::string Read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(TrainCommand, TrainsOnEverySampleOfAnNrlFolder) {
  const fs::path dir = fs::temp_directory_path() / ("dyad_train_test_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "data");
  const int nsamples[] = {1, 3, 2};  // NRL's sample data set's nsamples
  for (int p = 0; p < 3; ++p)
    for (int s = 0; s < nsamples[p]; ++s) {
      std::ofstream out(dir / "data" / ("primitive_" + std::to_string(p) + "_" + std::to_string(s) + ".csv"));
      for (int t = 0; t < 6; ++t) out << 10 * p + s + t << "," << -3 * t << "\n";
    }
  { std::ofstream(dir / "data" / "primitive_1_4.csv") << "1,2\n"; }  // after a gap: not used
  std::ofstream(dir / "train.yaml") << "dataset: data\n"
                                       "layers:\n  - {d: 6, z: 2, tau: 2, w: 0.01}\n"
                                       "encoding: {dofs: [[-50, 50], [-50, 50]], dsoft: 10, sigma: 0.2}\n"
                                       "epochs: 3\nseed: 1\nthreads: 1\nlog_every: 1\noutput: m.dpvrnn\n";
  const std::string cmd = std::string(DYAD_EXE) + " train " + (dir / "train.yaml").string() + " > " + (dir / "out").string() +
                          " 2> " + (dir / "err").string();
  const int status = std::system(cmd.c_str());
  const std::string out = Read(dir / "out"), err = Read(dir / "err");
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << out << err;
  EXPECT_NE(out.find("(6 sequences x 6 steps)"), std::string::npos) << out;
  EXPECT_NE(out.find("sequences per primitive (samples of primitives 0..2): 1, 3, 2\n"), std::string::npos) << out;
  EXPECT_NE(err.find("warning: " + (dir / "data" / "primitive_1_4.csv").string() +
                     ": not used (primitive_1_3.csv is missing: samples are read from 0 up to the first missing one)"),
            std::string::npos)
      << err;
  auto m = dyad::pvrnn::LoadModel((dir / "m.dpvrnn").string());
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->sequences(), 6);
  // The training log's numbers are exact (#41): its last loss is the model's, bit for bit.
  std::istringstream log(Read(dir / "m.dpvrnn.csv"));
  std::string line, last, loss;
  while (std::getline(log, line))
    if (!line.empty()) last = line;
  std::istringstream row(last);
  for (int k = 0; k < 5; ++k) std::getline(row, loss, ',');  // epoch,reconstruction_q,reconstruction_p,regulation,loss
  EXPECT_EQ(std::strtod(loss.c_str(), nullptr), m->provenance.final_loss) << last;
  if (!HasFailure()) fs::remove_all(dir);
}

// prior: nrl runs NRL's training (NrlTrainer from NRL's initial state): the log's losses are the
// in-process NrlTrainer's, bit for bit; a primitive with several samples is refused by name.
TEST(TrainCommand, PriorNrlTrainsAsNrlTrainerDoes) {
  const fs::path dir = fs::temp_directory_path() / ("dyad_train_nrl_test_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "data");
  for (int p = 0; p < 3; ++p) {
    std::ofstream out(dir / "data" / ("primitive_" + std::to_string(p) + "_0.csv"));
    for (int t = 0; t < 6; ++t) out << 10 * p + t << "," << -3 * t << "\n";
  }
  std::ofstream(dir / "train.yaml") << "dataset: data\n"
                                       "layers:\n  - {d: 6, z: 2, tau: 2, w: 0.01}\n  - {d: 4, z: 1, tau: 5, w: 0.01}\n"
                                       "encoding: {dofs: [[-50, 50], [-50, 50]], dsoft: 10, sigma: 0.2}\n"
                                       "epochs: 3\nprior: nrl\nnoise: false\nlog_every: 1\noutput: m.dpvrnn\n";
  const std::string cmd = std::string(DYAD_EXE) + " train " + (dir / "train.yaml").string() + " > " + (dir / "out").string() +
                          " 2> " + (dir / "err").string();
  int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << Read(dir / "out") << Read(dir / "err");
  EXPECT_NE(Read(dir / "out").find("NRL's way (prior: nrl)"), std::string::npos) << Read(dir / "out");

  auto c = dyad::pvrnn::LoadTrainConfig((dir / "train.yaml").string());
  ASSERT_TRUE(c.ok()) << c.status().message();
  auto data = dyad::pvrnn::LoadNrlDataset(c->dataset);
  ASSERT_TRUE(data.ok()) << data.status().message();
  dyad::pvrnn::NrlTrainerOptions o;
  o.adam = c->adam;  // NRL's epsilon 1e-20 (not set in the file)
  auto trainer = dyad::pvrnn::NrlTrainer::Create(dyad::pvrnn::NrlTrainer::InitialModel(c->spec, data->steps(), data->size()),
                                                 data.value(), o);
  ASSERT_TRUE(trainer.ok()) << trainer.status().message();
  std::istringstream log(Read(dir / "m.dpvrnn.csv"));
  std::string line;
  std::getline(log, line);  // header
  for (int e = 1; e <= 3; ++e) {
    ASSERT_TRUE(std::getline(log, line)) << "epoch " << e;
    const double want = trainer.value()->Epoch().loss;
    std::istringstream row(line);
    std::string loss;
    for (int k = 0; k < 5; ++k) std::getline(row, loss, ',');  // epoch,reconstruction_q,reconstruction_p,regulation,loss
    EXPECT_EQ(std::strtod(loss.c_str(), nullptr), want) << line;
  }
  auto m = dyad::pvrnn::LoadModel((dir / "m.dpvrnn").string());
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->provenance.epochs, 3);

  { std::ofstream(dir / "data" / "primitive_1_1.csv") << Read(dir / "data" / "primitive_1_0.csv"); }
  status = std::system(cmd.c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2);
  EXPECT_NE(Read(dir / "err").find("primitive 1 has sample 1: the NRL mode trains one sample per primitive"), std::string::npos)
      << Read(dir / "err");
  if (!HasFailure()) fs::remove_all(dir);
}

}  // namespace
