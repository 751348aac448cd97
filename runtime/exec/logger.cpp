#include "exec/logger.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>

namespace dyad {

bool StderrLogger::DebugEnabled() {
  static const bool enabled = [] {
    const char* v = std::getenv("DYAD_LOG");
    return v != nullptr && std::strcmp(v, "debug") == 0;
  }();
  return enabled;
}

void StderrLogger::Write(Level level, std::string_view message) {
  if (level == Level::kDebug && !DebugEnabled()) return;
  static std::mutex mutex;
  const char* tag = level == Level::kDebug ? "debug" : level == Level::kInfo ? "info" : level == Level::kWarn ? "warn" : "error";
  std::lock_guard<std::mutex> lock(mutex);
  std::fprintf(stderr, "[%s] %s: %.*s\n", tag, prefix_.c_str(), static_cast<int>(message.size()), message.data());
}

}  // namespace dyad
