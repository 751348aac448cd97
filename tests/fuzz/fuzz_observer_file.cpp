// Fuzz target: the observer (intention classifier) file reader.
// First byte: odd = give the file a correct CRC (fuzz_support.hpp); the rest is the file.
#include <cstdio>

#include "dyad/observer/observer_file.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes = dyad::fuzz::CheckedFileBytes(data, size);
  const std::string path = dyad::fuzz::WriteTemp(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), "observer.dobs");
  auto observer = dyad::observer::LoadObserver(path);
  if (!observer.ok()) dyad::fuzz::Require(observer.status().message().find(path) != std::string::npos, observer.status().ToString());
  std::remove(path.c_str());
  return 0;
}
