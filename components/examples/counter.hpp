/// Example components that exercise the runtime: a counting source and a sink that writes what
/// it receives to a file. Used by the runtime's tests and as templates for new components.
///
/// @component counter_source
/// rate_hz or trigger: periodic
/// outputs: out (Counter)
/// params:
///   start (int, 0): first value
///   noise (double, 0): adds a seeded uniform integer in [-noise, noise] to each value
///   limit (int, 0): stop the run after publishing this many samples (0: never)
/// @endcomponent
///
/// @component counter_sink
/// inputs: in (Counter)
/// params:
///   file (string, ""): write one line per received sample: value, source, sequence, stamp_ns
///   expect (int, 0): stop the run after receiving this many samples (0: never)
/// @endcomponent
#pragma once

#include <cstdio>
#include <random>

#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>

namespace dyad::examples {

class CounterSource final : public Component {
 public:
  static void Describe(ComponentSpec& spec);
  Status Configure(Context& ctx) override;
  Status Step(const StepInfo& info) override;

 private:
  Context* ctx_ = nullptr;
  Output<msg::Counter>* out_ = nullptr;  // owned by the runtime
  int64_t next_ = 0, limit_ = 0;
  double noise_ = 0;
  std::mt19937_64 rng_;
};

class CounterSink final : public Component {
 public:
  static void Describe(ComponentSpec& spec);
  Status Configure(Context& ctx) override;
  Status Activate() override;
  Status Step(const StepInfo& info) override;
  Status Deactivate() override;

 private:
  Context* ctx_ = nullptr;
  Input<msg::Counter>* in_ = nullptr;  // owned by the runtime
  std::string path_;
  int writers_alive_ = -1;  // as last said
  std::FILE* file_ = nullptr;
  int64_t expect_ = 0, received_ = 0;
};

}  // namespace dyad::examples
