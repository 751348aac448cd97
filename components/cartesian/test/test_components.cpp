// Test-only components for the driver and mixer process tests (loaded with `dyad run --plugins`):
//   test_state_log   writes each CartesianState: stamp_ns x y vx vy stopped (%.17g)
//   test_command_log writes each CartesianCommand: stamp_ns x y hold
//   test_human       HumanInput at a fixed position, engaged during [engaged_from, engaged_to)
//                    steps, silent from step `silent_from` (-1: never)
//   test_intention   Intention moving along x by `speed` units per step from `start`
//   test_command     CartesianCommand moving along x by `speed` units per step, silent from
//                    step `silent_from` (-1: never); the steps before `hold_until` send holds
//                    at `hold_at` instead (a far position: a driver must not go there)
//   test_arm         a driver (trigger: command): at each motion command its position becomes
//                    the command's x, y; holds change nothing; during its steps
//                    [stopped_from, stopped_to) it reports stopped and does not move (a lost arm)
#include <cinttypes>
#include <cstdio>
#include <cstring>

#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>

namespace {

using namespace dyad;

class FileLog {
 public:
  Status Open(const std::string& path) {
    file_ = std::fopen(path.c_str(), "w");
    if (file_ == nullptr) return Status::IOError(path, std::strerror(errno));
    return Status::OK();
  }
  std::FILE* get() { return file_; }
  void Close() {
    if (file_) std::fclose(file_);
    file_ = nullptr;
  }

 private:
  std::FILE* file_ = nullptr;
};

class StateLog final : public Component {
 public:
  static void Describe(ComponentSpec& spec) {
    spec.Summary("test: writes CartesianState samples to a file");
    spec.Param("file", "").Doc("output file");
    spec.Input<msg::CartesianState>("state");
  }
  Status Configure(Context& ctx) override {
    in_ = &ctx.input<msg::CartesianState>("state");
    return file_.Open(ctx.params().String("file"));
  }
  Status Step(const StepInfo&) override {
    for (const auto& s : in_->received())
      std::fprintf(file_.get(), "%" PRId64 " %.17g %.17g %.17g %.17g %d\n", s.header().stamp_ns(), s.x(), s.y(), s.vx(),
                   s.vy(), s.stopped() ? 1 : 0);
    return Status::OK();
  }
  void Shutdown() override { file_.Close(); }

 private:
  Input<msg::CartesianState>* in_ = nullptr;
  FileLog file_;
};

class CommandLog final : public Component {
 public:
  static void Describe(ComponentSpec& spec) {
    spec.Summary("test: writes CartesianCommand samples to a file");
    spec.Param("file", "").Doc("output file");
    spec.Input<msg::CartesianCommand>("command");
  }
  Status Configure(Context& ctx) override {
    in_ = &ctx.input<msg::CartesianCommand>("command");
    return file_.Open(ctx.params().String("file"));
  }
  Status Step(const StepInfo&) override {
    for (const auto& c : in_->received())
      std::fprintf(file_.get(), "%" PRId64 " %.17g %.17g %d\n", c.header().stamp_ns(), c.x(), c.y(), c.hold() ? 1 : 0);
    return Status::OK();
  }
  void Shutdown() override { file_.Close(); }

 private:
  Input<msg::CartesianCommand>* in_ = nullptr;
  FileLog file_;
};

class Human final : public Component {
 public:
  static void Describe(ComponentSpec& spec) {
    spec.Summary("test: a human at a fixed position");
    spec.Param("position", std::vector<double>{0, 0});
    spec.Param("engaged_from", int64_t{0});
    spec.Param("engaged_to", int64_t{0});
    spec.Param("silent_from", int64_t{-1});
    spec.Output<msg::HumanInput>("out");
  }
  Status Configure(Context& ctx) override {
    const auto& p = ctx.params();
    x_ = p.DoubleList("position").at(0);
    y_ = p.DoubleList("position").at(1);
    from_ = p.Int("engaged_from");
    to_ = p.Int("engaged_to");
    silent_ = p.Int("silent_from");
    out_ = &ctx.output<msg::HumanInput>("out");
    return Status::OK();
  }
  Status Step(const StepInfo& info) override {
    const auto k = static_cast<int64_t>(info.index);
    if (silent_ >= 0 && k >= silent_) return Status::OK();
    msg::HumanInput h;
    h.x(x_);
    h.y(y_);
    h.engaged(k >= from_ && k < to_);
    return out_->Publish(h);
  }

 private:
  double x_ = 0, y_ = 0;
  int64_t from_ = 0, to_ = 0, silent_ = -1;
  Output<msg::HumanInput>* out_ = nullptr;
};

class Intention final : public Component {
 public:
  static void Describe(ComponentSpec& spec) {
    spec.Summary("test: an intention moving along x");
    spec.Param("start", std::vector<double>{0, 0});
    spec.Param("speed", 1.0).Doc("units per step along x");
    spec.Output<msg::Intention>("out");
  }
  Status Configure(Context& ctx) override {
    const auto& p = ctx.params();
    x_ = p.DoubleList("start").at(0);
    y_ = p.DoubleList("start").at(1);
    speed_ = p.Double("speed");
    out_ = &ctx.output<msg::Intention>("out");
    return Status::OK();
  }
  Status Step(const StepInfo& info) override {
    msg::Intention i;
    i.x(x_ + speed_ * static_cast<double>(info.index));
    i.y(y_);
    return out_->Publish(i);
  }

 private:
  double x_ = 0, y_ = 0, speed_ = 1;
  Output<msg::Intention>* out_ = nullptr;
};

class Command final : public Component {
 public:
  static void Describe(ComponentSpec& spec) {
    spec.Summary("test: a command moving along x, then silence");
    spec.Param("speed", 1.0).Doc("units per step along x");
    spec.Param("silent_from", int64_t{-1});
    spec.Param("hold_until", int64_t{0});
    spec.Param("hold_at", std::vector<double>{0, 0});
    spec.Output<msg::CartesianCommand>("out");
  }
  Status Configure(Context& ctx) override {
    speed_ = ctx.params().Double("speed");
    silent_ = ctx.params().Int("silent_from");
    hold_until_ = ctx.params().Int("hold_until");
    const auto& at = ctx.params().DoubleList("hold_at");
    if (at.size() != 2) return Status::InvalidArgument("hold_at: [x, y]");
    hold_x_ = at[0], hold_y_ = at[1];
    out_ = &ctx.output<msg::CartesianCommand>("out");
    return Status::OK();
  }
  Status Step(const StepInfo& info) override {
    const auto k = static_cast<int64_t>(info.index);
    if (silent_ >= 0 && k >= silent_) return Status::OK();
    msg::CartesianCommand c;
    const bool hold = k < hold_until_;
    c.x(hold ? hold_x_ : speed_ * static_cast<double>(k));
    c.y(hold ? hold_y_ : 0);
    c.hold(hold);
    return out_->Publish(c);
  }

 private:
  double speed_ = 1, hold_x_ = 0, hold_y_ = 0;
  int64_t silent_ = -1, hold_until_ = 0;
  Output<msg::CartesianCommand>* out_ = nullptr;
};

class Arm final : public Component {
 public:
  static void Describe(ComponentSpec& spec) {
    spec.Summary("test: an arm that goes where motion commands say, and is lost for a while");
    spec.Param("stopped_from", int64_t{-1});
    spec.Param("stopped_to", int64_t{-1});
    spec.Input<msg::CartesianCommand>("command");
    spec.Output<msg::CartesianState>("state");
  }
  Status Configure(Context& ctx) override {
    from_ = ctx.params().Int("stopped_from");
    to_ = ctx.params().Int("stopped_to");
    command_ = &ctx.input<msg::CartesianCommand>("command");
    state_ = &ctx.output<msg::CartesianState>("state");
    return Status::OK();
  }
  Status Step(const StepInfo& info) override {
    const auto k = static_cast<int64_t>(info.index);
    const bool stopped = k >= from_ && k < to_;
    if (const msg::CartesianCommand* c = command_->latest(); c != nullptr && !c->hold() && !stopped) {
      out_.x(c->x());
      out_.y(c->y());
    }
    out_.stopped(stopped);
    return state_->Publish(out_);
  }

 private:
  int64_t from_ = -1, to_ = -1;
  Input<msg::CartesianCommand>* command_ = nullptr;
  Output<msg::CartesianState>* state_ = nullptr;
  msg::CartesianState out_;
};

}  // namespace

DYAD_PLUGIN(registry) {
  registry.Add<StateLog>("test_state_log");
  registry.Add<CommandLog>("test_command_log");
  registry.Add<Human>("test_human");
  registry.Add<Intention>("test_intention");
  registry.Add<Command>("test_command");
  registry.Add<Arm>("test_arm");
}
