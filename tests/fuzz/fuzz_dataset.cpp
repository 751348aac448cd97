// Fuzz target: the NRL data set reader (dataset.d plus primitive_<i>_0.csv files). One input
// packs the files: dataset.d, then each CSV, separated by lines "----".
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "dyad/pvrnn/dataset.hpp"
#include "fuzz_support.hpp"

namespace fs = std::filesystem;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const char* tmp = std::getenv("TMPDIR");
  const fs::path dir = fs::path(tmp && *tmp ? tmp : "/tmp") / ("dyad_fuzz_dataset_" + std::to_string(getpid()));
  std::error_code ec;
  fs::remove_all(dir, ec);
  fs::create_directories(dir);
  const auto parts = dyad::fuzz::Split(input, "\n----\n");
  for (size_t i = 0; i < parts.size() && i < 9; ++i) {
    const fs::path file = i == 0 ? dir / "dataset.d" : dir / ("primitive_" + std::to_string(i - 1) + "_0.csv");
    std::ofstream(file, std::ios::binary).write(parts[i].data(), static_cast<std::streamsize>(parts[i].size()));
  }
  auto dataset = dyad::pvrnn::LoadNrlDataset(dir.string());
  if (!dataset.ok()) dyad::fuzz::Require(dataset.status().message().find(dir.string()) != std::string::npos, dataset.status().ToString());
  fs::remove_all(dir, ec);
  return 0;
}
