#include "observer_component.hpp"

#include <limits>

namespace dyad::observer {

void PositionWindow::Push(double x, double y) {
  ring_(0, next_) = x;
  ring_(1, next_) = y;
  next_ = (next_ + 1) % ring_.cols();
  count_ = std::min(count_ + 1, ring_.cols());
}

const Eigen::MatrixXd& PositionWindow::Ordered() {
  const Eigen::Index n = ring_.cols();
  for (Eigen::Index i = 0; i < n; ++i) ordered_.col(i) = ring_.col((next_ + i) % n);
  return ordered_;
}

void Observer::Describe(ComponentSpec& spec) {
  spec.Summary("Classifies the human's and the robot's recent motion into primitives; publishes their congruence.");
  spec.RequiredParam("model", ParamType::kString).Path().Doc("observer file written by `dyad train-observer`");
  spec.Param("window", int64_t{5}).Range(1, 1000).Unit("steps").Doc("steps per classified window; must match the observer file");
  spec.Param("lowpass_steps", int64_t{10}).Range(1, 100000).Unit("steps")
      .Doc("Y: P(C_t) is the moving average of the instantaneous congruence over the last Y steps");
  spec.Input<msg::HumanInput>("human").Doc("the human's position and engaged flag");
  spec.Input<msg::Intention>("robot").Optional().Doc("the robot's intended position (unbound: robot stays empty)");
  spec.Output<msg::IntentionLabel>("labels").Doc("class probabilities of both and the congruence P(C_t), one per step");
}

Status Observer::Configure(Context& ctx) {
  const std::string& path = ctx.params().String("model");
  auto file = LoadObserver(path);
  if (!file.ok()) return Status::InvalidArgument("model: " + file.status().message());
  observer_ = std::move(file.value());
  const ClassifierSpec& spec = observer_.classifier.spec();
  const int64_t window = ctx.params().Int("window");
  if (window != spec.window)
    return Status::InvalidArgument("window = " + std::to_string(window) + ": " + path + " was trained with window " +
                                   std::to_string(spec.window));
  if (spec.dofs() != 2)
    return Status::InvalidArgument("model: " + path + " classifies " + std::to_string(spec.dofs()) + " DOFs, the observer needs 2 (x, y)");
  human_window_ = PositionWindow(2, spec.positions_needed());
  robot_window_ = PositionWindow(2, spec.positions_needed());
  filter_ = MovingAverage(static_cast<int>(ctx.params().Int("lowpass_steps")));
  human_p_.resize(spec.classes);
  robot_p_.resize(spec.classes);
  label_.human().reserve(static_cast<size_t>(spec.classes));
  label_.robot().reserve(static_cast<size_t>(spec.classes));
  // Warm the workspace so steps allocate nothing.
  observer_.classifier.Classify(Eigen::MatrixXd::Zero(2, spec.positions_needed()), &ws_, &robot_p_);
  human_ = &ctx.input<msg::HumanInput>("human");
  robot_ = &ctx.input<msg::Intention>("robot");
  labels_ = &ctx.output<msg::IntentionLabel>("labels");
  return Status::OK();
}

Status Observer::Step(const StepInfo&) {
  for (const auto& h : human_->received()) {
    if (h.engaged()) {
      if (!human_engaged_) human_window_.Clear();  // a new engagement starts a new window
      human_window_.Push(h.x(), h.y());
    }
    human_engaged_ = h.engaged();
  }
  for (const auto& r : robot_->received()) robot_window_.Push(r.x(), r.y());

  const bool have_robot = robot_window_.full();
  const bool have_human = human_engaged_ && human_window_.full();
  auto& robot = label_.robot();
  auto& human = label_.human();
  robot.clear();
  human.clear();
  if (have_robot) {
    observer_.classifier.Classify(robot_window_.Ordered(), &ws_, &robot_p_);
    robot.assign(robot_p_.data(), robot_p_.data() + robot_p_.size());
  }
  if (have_human) {
    observer_.classifier.Classify(human_window_.Ordered(), &ws_, &human_p_);
    human.assign(human_p_.data(), human_p_.data() + human_p_.size());
  }
  if (have_human && have_robot) {
    label_.congruence(filter_.Push(InstantCongruence(human_p_, robot_p_)));
  } else {
    filter_.Reset();
    label_.congruence(std::numeric_limits<double>::quiet_NaN());
  }
  return labels_->Publish(label_);
}

}  // namespace dyad::observer

DYAD_PLUGIN(registry) { registry.Add<dyad::observer::Observer>("observer"); }
