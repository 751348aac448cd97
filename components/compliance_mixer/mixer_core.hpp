/// MixerCore: the compliance mixer's math, free of DDS and clocks (times are passed in), so that
/// it is tested on its own (test/mixer_core_test.cpp) and the component stays a thin shell.
///
/// Each Update() turns the latest human and robot samples into one command position:
///   target = g*human + (1-g)*robot   while the human is engaged (g = `gain`, the study: 0.9)
///          = robot                   otherwise
///   mode kBlend: command = target
///   mode kPi:    command = state + kp*e + ki*I,  e = target - state,  I = sum of e*dt
///                (a PI loop closed around the driver's measured position; kp = 1, ki = 0
///                gives the plain blend back; anti-windup: I is clamped per axis to
///                +-integral_limit and not accumulated on an update whose command saturated)
///   then the change from the previous command is saturated (vector norm, so the direction of
///   motion is kept) to `max_step` per command and to `max_speed` times the runtime clock's time
///   since the previous command (the study: 5 units per 100 ms step, 50 units/s): a burst of
///   updates (a writer flooding the trigger input) moves the command no faster than max_speed,
///   and two updates at one instant do not move it. The first command is saturated to max_step
///   against the measured state.
///
/// The command contract (docs/components.md, "The command contract"): every position Update()
/// returns is one the arm may go to. A hold (hold = true) asks the driver to stay where it is and
/// carries the position to hold: the previous motion command, or, before any, the arm's last
/// measured position; never the target. Before anything is known of the arm (no state yet, no
/// motion sent) a hold carries (0, 0), the workspace origin, which is only a placeholder: a
/// driver never moves on a hold.
///
/// With `wait_for_state` (the component sets it when its `state` input is bound) the measured
/// state decides whether the mixer may move at all. The arm is "known" while its state is fresh
/// (no older than `state_timeout_ns`), finite and not `stopped` (a driver that reports stopped
/// cannot move the arm, and its position may not be real). While it is not known:
///   - before the first motion command: Update() returns holds (waiting_for_state = true), which
///     make a driver triggered by commands step and report where the arm is; the first motion
///     command then moves at most max_step from the measured position;
///   - after it (the arm was lost: its driver stopped, its state went stale): holds at the
///     previous motion command (arm_lost = true), so that the goal does not run on without the
///     arm; when the arm is known again, the first motion command starts from its measured
///     position, limited as a first command (max_step, max_speed), with the PI integral reset.
///   Each outage (lost, then known again) is counted with its duration and the holds sent
///   during it (arm_outages()); Result::outage_started and outage_ended_ns mark its edges.
/// Without it, and without a state, the first command is the target itself: unlimited.
/// Stale inputs: if the robot or human sample (or, in kPi, the state) is older than
/// `stale_timeout_ns` (the state: `state_timeout_ns`) or missing, Update() repeats the previous
/// command with hold = true (or returns no command at all before the first one). An input whose
/// position it would use holds the same way when that position is NaN or infinite
/// (non_finite = true): one such sample would otherwise become the previous command and poison
/// every later one.
///
///   MixerCore mixer(options);            // options.Validate() must be OK
///   MixerCore::Inputs in;
///   in.robot = {{10, 0}, now};  in.human = {{0, 0}, now};  in.engaged = true;
///   MixerCore::Result r = mixer.Update(in, now);   // r.has_command, r.position, r.hold
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <dyad/status.hpp>

namespace dyad::mixer {

struct Vec2 {
  double x = 0, y = 0;
};

enum class Mode { kBlend, kPi };

struct MixerOptions {
  double gain = 0.9;                     // weight of the human while engaged, [0, 1]
  double max_step = 5.0;                 // max change of the command per update, workspace units (norm); 0 = none
  double max_speed = 50.0;               // max change per second of runtime-clock time between commands; 0 = none
  Mode mode = Mode::kBlend;
  double kp = 1.0;                       // kPi: proportional gain, >= 0
  double ki = 0.0;                       // kPi: integral gain, 1/s, >= 0
  double integral_limit = 10.0;          // kPi: |I| per axis, workspace units * s, >= 0
  int64_t stale_timeout_ns = 500'000'000;  // an input older than this is stale, > 0
  int64_t state_timeout_ns = 500'000'000;  // the measured state older than this is stale, > 0
  bool wait_for_state = false;           // move only while the arm's position is known (above)

  // OK, or InvalidArgument naming the field, its value and the broken constraint.
  Status Validate() const;
};

class MixerCore {
 public:
  // A timestamped position; `receive_ns` < 0 means never received.
  struct Sample {
    Vec2 position;
    int64_t receive_ns = -1;
  };
  struct Inputs {
    Sample robot;          // the robot's intention
    Sample human;          // the human's hand position
    bool engaged = false;  // the human's newest engaged flag
    Sample state;          // measured position; receive_ns < 0 when unbound or not yet received
    bool stopped = false;  // the newest state says stopped (its driver cannot move the arm)
  };
  // The arm's outages so far (wait_for_state): lost after the first motion command, then known again.
  struct Outages {
    uint64_t count = 0;    // outages begun (the one under way included)
    int64_t lost_ns = 0;   // their total duration, the one under way up to the latest update
    uint64_t holds = 0;    // hold commands returned while the arm was lost
    bool ongoing = false;  // the arm is lost at the latest update
  };
  enum class Stale { kNone, kRobot, kHuman, kState };
  struct Result {
    bool has_command = false;  // false only before the first command while inputs are stale
    Vec2 position;
    bool hold = false;         // inputs stale: `position` repeats the previous command
    bool saturated = false;    // the step limit shortened the change
    Stale stale = Stale::kNone;  // which input made it hold (the first found)
    bool non_finite = false;     // it held because that input's position is NaN or infinite
    bool waiting_for_state = false;  // wait_for_state: a hold before the first command (stale = kState)
    bool arm_lost = false;       // wait_for_state: the arm is not known after the first command (it holds)
    bool stopped = false;        // ... because its driver reports stopped (else: its state is stale)
    bool outage_started = false;  // this update began an outage
    int64_t outage_ended_ns = -1;  // this update ended an outage lasting this long; -1: none ended
  };

  // REQUIRES: options.Validate().ok().
  explicit MixerCore(const MixerOptions& options);

  // One control update at runtime-clock time `now_ns` (never decreasing).
  Result Update(const Inputs& in, int64_t now_ns);

  const MixerOptions& options() const { return options_; }
  // Live changes between updates (the component's live params). REQUIRES: gain in [0, 1],
  // max_step >= 0 (their declarations say so; the runtime validated them).
  void SetGainAndMaxStep(double gain, double max_step) {
    options_.gain = gain;
    options_.max_step = max_step;
  }
  Vec2 integral() const { return integral_; }
  const Outages& arm_outages() const { return outages_; }

 private:
  bool Fresh(const Sample& s, int64_t now_ns) const {
    return s.receive_ns >= 0 && now_ns - s.receive_ns <= options_.stale_timeout_ns;
  }
  bool FreshState(const Sample& s, int64_t now_ns) const {
    return s.receive_ns >= 0 && now_ns - s.receive_ns <= options_.state_timeout_ns;
  }
  // Counts an outage's start, end and holds from one update's result (wait_for_state).
  void TrackOutage(Result* r, bool lost, int64_t now_ns);
  // The motion command of an update whose inputs are fresh and finite, into *r.
  void Motion(const Inputs& in, int64_t now_ns, double dt, Result* r);

  MixerOptions options_;
  bool has_last_ = false;
  Vec2 last_;                 // previous command
  Vec2 integral_;             // kPi: sum of e*dt
  int64_t last_update_ns_ = -1;
  int64_t last_command_ns_ = -1;  // when the previous command (a hold too) was made
  bool has_arm_ = false;      // a measured position was known once
  Vec2 arm_;                  // the latest known measured position (fresh, finite, not stopped)
  bool resync_ = false;       // the arm was lost: the next motion command starts from its state
  int64_t lost_since_ns_ = -1;  // the outage under way began at this update
  int64_t lost_done_ns_ = 0;    // the finished outages' total duration
  Outages outages_;

  // The longest change allowed at `now_ns` from the previous command (or, for the first, from
  // the measured state): max_step, and max_speed x the time since the previous command; infinity: none.
  double StepLimit(int64_t now_ns) const;
};

// Shortens `delta` to norm `max_norm` (unchanged when shorter or max_norm <= 0). Sets *clipped.
Vec2 SaturateNorm(Vec2 delta, double max_norm, bool* clipped);

const char* ToString(MixerCore::Stale stale);

}  // namespace dyad::mixer
