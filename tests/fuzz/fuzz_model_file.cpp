// Fuzz target: the PV-RNN model file reader (checked_file container + model payload).
// First byte: odd = give the file a correct CRC (fuzz_support.hpp); the rest is the file.
#include <cstdio>

#include "dyad/pvrnn/model_file.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes = dyad::fuzz::CheckedFileBytes(data, size);
  const std::string path = dyad::fuzz::WriteTemp(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), "model.dpvrnn");
  auto model = dyad::pvrnn::LoadModel(path);
  if (!model.ok()) dyad::fuzz::Require(model.status().message().find(path) != std::string::npos, model.status().ToString());
  std::remove(path.c_str());
  return 0;
}
