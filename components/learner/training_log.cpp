#include "training_log.hpp"

#include <cstdio>
#include <fstream>

namespace dyad::learner {

void TrainingLog::Update(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return;
  in.seekg(offset_);
  std::string chunk((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  offset_ += static_cast<int64_t>(chunk.size());
  partial_ += chunk;
  size_t start = 0;
  for (size_t nl; (nl = partial_.find('\n', start)) != std::string::npos; start = nl + 1) TakeLine(partial_.substr(start, nl - start));
  partial_.erase(0, start);
}

void TrainingLog::TakeLine(const std::string& line) {
  if (line.empty()) return;
  last_line = line;
  if (line.rfind("error: ", 0) == 0) last_error = line;
  long long e = 0, n = 0;
  if (std::sscanf(line.c_str(), "epoch %lld/%lld", &e, &n) == 2) {
    epoch = e, epochs = n;
    const size_t at = line.find("  loss ");
    if (at != std::string::npos) std::sscanf(line.c_str() + at, "  loss %lf", &loss);
    return;
  }
  const size_t at = line.rfind(" to ");
  if (line.rfind("training ", 0) == 0 && at != std::string::npos && std::sscanf(line.c_str() + at, " to %lld", &n) == 1) epochs = n;
}

}  // namespace dyad::learner
