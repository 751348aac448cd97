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

}  // namespace
