// Logging to stderr, one line per message, shared by the runtime and components.
#pragma once

#include <dyad/component.hpp>

#include <string>

namespace dyad {

class StderrLogger final : public Logger {
 public:
  explicit StderrLogger(std::string prefix) : prefix_(std::move(prefix)) {}
  void Write(Level level, std::string_view message) override;
  // DYAD_LOG=debug shows debug lines.
  static bool DebugEnabled();

 private:
  std::string prefix_;
};

}  // namespace dyad
