// Fuzz target: the NRL/VCBot plain-text readers: key=value files (properties_*.d, dataset.d) and
// the number lines of weight files and data rows (nrl_text). Every line of the input goes through
// ParseNumberList and ParseInteger too.
#include <cstdio>
#include <string>
#include <vector>

#include "dyad/pvrnn/nrl_import.hpp"
#include "fuzz_support.hpp"
#include "nrl_text.hpp"

namespace nrl = dyad::pvrnn::internal;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = dyad::fuzz::WriteTemp(data, size, "properties.d");
  auto kv = dyad::pvrnn::ReadKeyValueFile(path);
  if (!kv.ok()) dyad::fuzz::Require(kv.status().message().find(path) != std::string::npos, kv.status().ToString());
  std::remove(path.c_str());
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  std::vector<double> numbers;
  std::string bad;
  for (std::string_view line : dyad::fuzz::Split(text, "\n")) {
    if (nrl::ParseNumberList(line, &numbers, &bad)) {
      for (double x : numbers) dyad::fuzz::Require(x == x && x - x == 0, "non-finite number accepted");
    }
    int64_t value = 0;
    if (nrl::ParseInteger(line, -1000, 1000, &value)) dyad::fuzz::Require(value >= -1000 && value <= 1000, "integer out of range accepted");
  }
  return 0;
}
