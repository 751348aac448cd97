/// The study's intention observer: classifies the last steps of the human's and of the robot's
/// motion with the trained classifier (dyad/observer/classifier.hpp) and publishes both class
/// probability vectors and the intention congruence P(C_t).
///
/// @component observer
/// trigger: robot (or rate_hz 10)
/// inputs:
///   human (HumanInput): the human's position and engaged flag
///   robot (Intention, optional): the robot's intended position; left unbound, only the human
///          is classified (robot stays empty, congruence NaN), e.g. to label a human-only run
/// outputs:
///   labels (IntentionLabel), one per step:
///     robot: sigmoid outputs (one per primitive) for the last `window` robot positions; empty
///            until `window` positions have arrived
///     human: the same for the human's last `window` positions while engaged; empty while not
///            engaged and for the first window-1 steps of each engagement (the window restarts
///            when the human engages: positions from before do not mix in)
///     congruence: P(C_t), the moving average over the last `lowpass_steps` values of
///            c_t = sum_k h^_k r^_k (h^, r^: outputs normalised to sum 1) since both sides were
///            last classified; NaN whenever `human` is empty (the filter restarts then)
/// params:
///   model (string, required): observer file (`dyad train-observer`)
///   window (int, 5, steps): must equal the window the classifier was trained with
///   lowpass_steps (int, 10, steps): Y of the moving average (study: 10)
/// @endcomponent
#pragma once

#include <Eigen/Core>

#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>

#include "dyad/observer/evaluation.hpp"
#include "dyad/observer/observer_file.hpp"

namespace dyad::observer {

// The last `size` positions, oldest first on read; no allocation after construction.
class PositionWindow {
 public:
  PositionWindow(int dofs, int size) : ring_(dofs, size), ordered_(dofs, size) {}
  void Clear() { count_ = next_ = 0; }
  void Push(double x, double y);
  bool full() const { return count_ == ring_.cols(); }
  // The window, oldest first. REQUIRES full().
  const Eigen::MatrixXd& Ordered();

 private:
  Eigen::MatrixXd ring_, ordered_;
  Eigen::Index count_ = 0, next_ = 0;
};

class Observer final : public Component {
 public:
  static void Describe(ComponentSpec& spec);
  Status Configure(Context& ctx) override;
  Status Step(const StepInfo& info) override;

 private:
  ObserverFile observer_;
  Classifier::Workspace ws_;
  PositionWindow human_window_{2, 5}, robot_window_{2, 5};
  MovingAverage filter_{10};
  bool human_engaged_ = false;
  Eigen::VectorXd human_p_, robot_p_;
  Input<msg::HumanInput>* human_ = nullptr;   // owned by the runtime
  Input<msg::Intention>* robot_ = nullptr;    // owned by the runtime
  Output<msg::IntentionLabel>* labels_ = nullptr;  // owned by the runtime
  msg::IntentionLabel label_;
};

}  // namespace dyad::observer
