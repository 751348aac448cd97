// ping and pong: two dyad components bouncing a PingPong sample, for bench_pingpong.
//
// @component pong   inputs: in (PingPong)   outputs: out (PingPong)   trigger: in
//   Republishes every sample it receives.
// @component ping   inputs: back (PingPong) outputs: out (PingPong)   trigger: back
//   Sends a sample on Activate and the next one as soon as the previous came back; records each
//   round trip (steady clock) and ends the run after `rounds`, writing them to `file` (ns, one per line).
//   With `evict_kb`, it writes a buffer that large before each round trip (untimed), so that the
//   round trip starts with caches and TLB cold, as after a preemption.
#include <chrono>
#include <cstdio>
#include <vector>

#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>

namespace {

int64_t SteadyNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

class Pong final : public dyad::Component {
 public:
  static void Describe(dyad::ComponentSpec& spec) {
    spec.Summary("Republishes every PingPong it receives (benchmark).");
    spec.Input<dyad::msg::PingPong>("in");
    spec.Output<dyad::msg::PingPong>("out");
  }
  dyad::Status Configure(dyad::Context& ctx) override {
    in_ = &ctx.input<dyad::msg::PingPong>("in");
    out_ = &ctx.output<dyad::msg::PingPong>("out");
    return dyad::Status::OK();
  }
  // received() is const and Publish fills the header: the sample is copied once, into an object
  // kept from step to step (its strings and sequences keep their storage: no allocation).
  dyad::Status Step(const dyad::StepInfo&) override {
    for (const auto& s : in_->received()) {
      reply_ = s;
      if (auto st = out_->Publish(reply_); !st.ok()) return st;
    }
    return dyad::Status::OK();
  }

 private:
  dyad::msg::PingPong reply_;
  dyad::Input<dyad::msg::PingPong>* in_ = nullptr;
  dyad::Output<dyad::msg::PingPong>* out_ = nullptr;
};

class Ping final : public dyad::Component {
 public:
  static void Describe(dyad::ComponentSpec& spec) {
    spec.Summary("Measures round trips through a pong (benchmark).");
    spec.Param("rounds", int64_t{10000}).Min(1).Doc("round trips to measure");
    spec.Param("payload", int64_t{0}).Min(0).Doc("payload bytes per sample");
    spec.Param("file", "").Path().Doc("where to write the round-trip times (ns), one per line");
    spec.Param("evict_kb", int64_t{0}).Min(0).Doc("KiB of memory written before each round trip (cold caches)");
    spec.Input<dyad::msg::PingPong>("back");
    spec.Output<dyad::msg::PingPong>("out");
  }
  dyad::Status Configure(dyad::Context& ctx) override {
    ctx_ = &ctx;
    rounds_ = ctx.params().Int("rounds");
    file_ = ctx.params().String("file");
    sample_.payload().resize(static_cast<size_t>(ctx.params().Int("payload")));
    junk_.resize(static_cast<size_t>(ctx.params().Int("evict_kb")) * 1024);
    back_ = &ctx.input<dyad::msg::PingPong>("back");
    out_ = &ctx.output<dyad::msg::PingPong>("out");
    rtt_.reserve(static_cast<size_t>(rounds_));
    return dyad::Status::OK();
  }
  dyad::Status Activate() override { return Send(); }
  dyad::Status Step(const dyad::StepInfo&) override {
    const int64_t now = SteadyNs();
    for (const auto& s : back_->received()) {
      if (s.id() != sample_.id()) continue;  // stale
      rtt_.push_back(now - s.t0_ns());
    }
    if (static_cast<int64_t>(rtt_.size()) >= rounds_) {
      ctx_->RequestStop("measured " + std::to_string(rounds_) + " round trips");
      return dyad::Status::OK();
    }
    return Send();
  }
  dyad::Status Deactivate() override {
    if (file_.empty()) return dyad::Status::OK();
    std::FILE* f = std::fopen(file_.c_str(), "w");
    if (f == nullptr) return dyad::Status::IOError(file_ + ": cannot write");
    for (int64_t v : rtt_) std::fprintf(f, "%lld\n", static_cast<long long>(v));
    std::fclose(f);
    return dyad::Status::OK();
  }

 private:
  dyad::Status Send() {
    for (size_t i = 0; i < junk_.size(); i += 64) junk_[i] = static_cast<char>(junk_[i] + 1);
    sample_.id(sample_.id() + 1);
    sample_.t0_ns(SteadyNs());
    return out_->Publish(sample_);
  }
  dyad::Context* ctx_ = nullptr;
  int64_t rounds_ = 0;
  std::string file_;
  dyad::msg::PingPong sample_;
  std::vector<int64_t> rtt_;
  std::vector<char> junk_;  // evict_kb
  dyad::Input<dyad::msg::PingPong>* back_ = nullptr;
  dyad::Output<dyad::msg::PingPong>* out_ = nullptr;
};

}  // namespace

DYAD_PLUGIN(registry) {
  registry.Add<Ping>("bench_ping");
  registry.Add<Pong>("bench_pong");
}
