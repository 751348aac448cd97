// bench_burst: publishes `burst` Counter samples per step (recorder benchmark).
//
// @component bench_burst   outputs: out (Counter)   rate_hz: any
//   params: burst (int, 100): samples per step
#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>

namespace {

class Burst final : public dyad::Component {
 public:
  static void Describe(dyad::ComponentSpec& spec) {
    spec.Summary("Publishes `burst` Counter samples per step (benchmark).");
    spec.Param("burst", int64_t{100}).Min(1).Doc("samples per step");
    spec.Output<dyad::msg::Counter>("out");
  }
  dyad::Status Configure(dyad::Context& ctx) override {
    burst_ = ctx.params().Int("burst");
    out_ = &ctx.output<dyad::msg::Counter>("out");
    return dyad::Status::OK();
  }
  dyad::Status Step(const dyad::StepInfo&) override {
    for (int64_t i = 0; i < burst_; ++i) {
      sample_.value(next_++);
      if (auto s = out_->Publish(sample_); !s.ok()) return s;
    }
    return dyad::Status::OK();
  }

 private:
  int64_t burst_ = 100, next_ = 0;
  dyad::msg::Counter sample_;
  dyad::Output<dyad::msg::Counter>* out_ = nullptr;
};

}  // namespace

DYAD_PLUGIN(registry) { registry.Add<Burst>("bench_burst"); }
