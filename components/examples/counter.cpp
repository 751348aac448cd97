#include "counter.hpp"

#include <algorithm>
#include <cinttypes>
#include <cstring>

namespace dyad::examples {

void CounterSource::Describe(ComponentSpec& spec) {
  spec.Summary("Publishes 0, 1, 2, ... (optionally with seeded noise) on each step.");
  spec.Param("start", int64_t{0}).Doc("first value");
  spec.Param("noise", 0.0).Min(0).Doc("adds a seeded uniform integer in [-noise, noise]");
  spec.Param("limit", int64_t{0}).Min(0).Doc("stop the run after this many samples (0: never)");
  spec.Output<msg::Counter>("out").Doc("the count");
}

Status CounterSource::Configure(Context& ctx) {
  ctx_ = &ctx;
  next_ = ctx.params().Int("start");
  noise_ = ctx.params().Double("noise");
  limit_ = ctx.params().Int("limit");
  rng_.seed(ctx.seed());
  out_ = &ctx.output<msg::Counter>("out");
  return Status::OK();
}

Status CounterSource::Step(const StepInfo&) {
  msg::Counter c;
  int64_t v = next_++;
  if (noise_ > 0) {
    const auto n = static_cast<int64_t>(noise_);
    v += std::uniform_int_distribution<int64_t>(-n, n)(rng_);
  }
  c.value(v);
  if (Status s = out_->Publish(c); !s.ok()) return s;
  if (limit_ > 0 && static_cast<int64_t>(out_->published()) >= limit_) ctx_->RequestStop("published " + std::to_string(limit_) + " samples");
  return Status::OK();
}

void CounterSink::Describe(ComponentSpec& spec) {
  spec.Summary("Receives counters; writes them to a file; can end the run after N.");
  spec.Param("file", "").Path().Doc("one line per sample: value source sequence stamp_ns (empty: no file)");
  spec.Param("expect", int64_t{0}).Min(0).Doc("stop the run after receiving this many samples (0: never)");
  spec.Input<msg::Counter>("in").Doc("counters to record");
}

Status CounterSink::Configure(Context& ctx) {
  ctx_ = &ctx;
  path_ = ctx.params().String("file");
  expect_ = ctx.params().Int("expect");
  in_ = &ctx.input<msg::Counter>("in");
  return Status::OK();
}

Status CounterSink::Activate() {
  if (path_.empty()) return Status::OK();
  file_ = std::fopen(path_.c_str(), "w");
  if (file_ == nullptr) return Status::IOError(path_ + ": cannot open for writing: " + std::strerror(errno));
  return Status::OK();
}

Status CounterSink::Step(const StepInfo&) {
  // The input's health, said when it changes (tests read it from the log).
  if (in_->writers_alive() != writers_alive_ && in_->writers_alive() >= 0) {
    if (writers_alive_ >= 0 || in_->writers_alive() > 0)  // not "0 -> 0" at the first step
      ctx_->log().Info("writers of '" + in_->topic() + "' alive: " + std::to_string(std::max(writers_alive_, 0)) + " -> " +
                       std::to_string(in_->writers_alive()));
    writers_alive_ = in_->writers_alive();
  }
  for (const auto& c : in_->received()) {
    ++received_;
    if (file_)
      std::fprintf(file_, "%" PRId64 " %s %" PRIu64 " %" PRId64 "\n", c.value(), c.header().source().c_str(),
                   c.header().sequence_number(), c.header().stamp_ns());
  }
  if (expect_ > 0 && received_ >= expect_) ctx_->RequestStop("received " + std::to_string(received_) + " samples");
  return Status::OK();
}

Status CounterSink::Deactivate() {
  if (file_ && std::fclose(file_) != 0) return Status::IOError(path_ + ": write failed");
  file_ = nullptr;
  return Status::OK();
}

}  // namespace dyad::examples

DYAD_PLUGIN(registry) {
  registry.Add<dyad::examples::CounterSource>("counter_source");
  registry.Add<dyad::examples::CounterSink>("counter_sink");
}
