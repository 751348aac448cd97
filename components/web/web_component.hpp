/// The `web` component: one embedded web server per process (civetweb) with
///   - `/subject`: the subject's page (steer the robot with the mouse, the experimenter's task:
///     a target primitive, a message, a countdown, "practice"; see web_human.hpp; after
///     each release of a hold of at least `self_report_min_hold_s`, when `self_report` is bound,
///     it asks "What were you drawing?" and the answer leaves on `self_report` with the hold's
///     start and end on the runtime clock; with self_reports: after_trial it asks nothing during
///     the trial: when `ask` is set, or `ask_after_s` into the run, steering ends, the page asks
///     about each hold in turn (its stroke, the pointer's path while held, as the picture), and
///     once all are answered or `self_report_timeout_s` passed the component ends the run with
///     RequestStop),
///   - `/experimenter`: the experimenter's page (with `learner` bound, also "learn from this
///     session": the learner's demonstrations, a run's loss, the swap; docs/components.md#learner),
///   - `/`: an index page, and the Foxglove WebSocket bridge over the graph's topics for
///     Foxglove ("Foxglove WebSocket" connection to ws://ADDRESS:PORT).
/// Pages are embedded in the plugin. The server binds 127.0.0.1 unless `address` says otherwise
/// (then it speaks TLS with `tls_certificate`). Every page and WebSocket needs a token, one per
/// role: the subject's opens the subject's page and steers; the viewer's watches (subject's page,
/// experimenter's page without notes, Foxglove read-only); the experimenter's opens everything,
/// writes notes, changes live parameters (dyad/param_requests, answers from dyad/params) and
/// publishes on `writable` topics. Its Step (its own rate, the
/// pages' display rate, <= 60 Hz) sends the robot's newest position to the subject's pages and
/// reports dropped samples to Foxglove clients; samples reach the bridge through serialized
/// subscriptions and pointer samples leave on `pointer` as they come: nothing here ever waits
/// for a browser.
///
/// Why a component and not a runtime service: the runtime stays free of HTTP, a graph places the
/// server in the process the subject's browser should reach, and it is swapped or left out by
/// YAML like every other part.
#pragma once

#include <array>
#include <atomic>
#include <memory>
#include <mutex>

#include <nlohmann/json.hpp>

#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>

#include "src/experimenter_channel.hpp"
#include "src/foxglove_bridge.hpp"
#include "src/param_answers.hpp"
#include "src/run_events.hpp"
#include "src/stats_table.hpp"
#include "src/subject_channel.hpp"
#include "src/web_server.hpp"

namespace dyad::web {

class WebComponent final : public Component {
 public:
  static void Describe(ComponentSpec& spec);
  Status Configure(Context& ctx) override;
  Status Activate() override;  // starts the server
  Status Step(const StepInfo& info) override;
  Status Deactivate() override;  // stops it (every client closed)

 private:
  void LogPointerDelays();
  Status ConfigureBridge(Context& ctx, const Params& p);
  Status ConfigureSubject(Context& ctx, const Params& p);
  Status ConfigureExperimenter(Context& ctx);
  void ConfigurePages();
  StatusOr<std::string> PublishParamRequest(const ParamRequest& request);  // ExperimenterChannel's param sink
  Status PublishSelfReport(int choice, int segment);                       // SubjectChannel's report sink
  void MarkHold(double x, double y, bool starts, bool ends, int64_t now);  // after_trial: the holds asked about
  void StepAfterTrial(int64_t now, bool robot_moved);
  void StartQuestions(int64_t now);
  nlohmann::json QuestionsJson();  // for the experimenter's page: null, or asked/answered/of
  Status ConfigureTask(Context& ctx, const Params& p);
  void StepTask();
  Context* ctx_ = nullptr;
  WebServer::Options options_;
  std::string port_file_;
  Status ChooseTokens(const Params& p);
  Status ChooseTls(const Params& p);
  void LogUrls() const;
  void WaitForSubject(double seconds);    // params.wait_for_subject_s
  void StepPause(int64_t now);            // params.pause_without_subject
  void Mark(const std::string& text);     // a note by "web" on `notes` (the pause marks)
  std::string token_file_;                // params.token_file
  std::map<Role, std::string> shown_;     // what the printed URLs show for each token (see ChooseTokens)
  std::string token_file_text_;           // what Activate writes to a token_file that did not exist; empty: none
  std::vector<std::string> writable_;     // params.writable
  Input<msg::CartesianState>* robot_ = nullptr;   // owned by the runtime
  Output<msg::HumanInput>* pointer_ = nullptr;    // owned by the runtime
  Input<msg::Intention>* intention_ = nullptr;    // owned by the runtime
  Input<msg::IntentionLabel>* labels_ = nullptr;  // owned by the runtime
  Input<msg::LearnerStatus>* learner_ = nullptr;  // owned by the runtime
  Input<msg::RecordingStatus>* recording_ = nullptr;  // owned by the runtime
  Output<msg::Annotation>* notes_ = nullptr;      // owned by the runtime
  std::unique_ptr<ExperimenterChannel> experimenter_;
  std::shared_ptr<StatsTable> stats_;  // filled by the dyad/stats subscription
  std::shared_ptr<RunEvents> events_;  // filled by the dyad/processes and dyad/health subscriptions
  std::shared_ptr<ParamAnswers> answers_;  // filled by the dyad/params subscription
  SerializedWriter* param_requests_ = nullptr;  // dyad/param_requests; owned by the runtime
  msg::ParamChange param_request_;              // the last request (its header's sequence number)
  int64_t last_stats_ns_ = 0;
  msg::Annotation note_;
  std::unique_ptr<FoxgloveBridge> bridge_;
  std::unique_ptr<SubjectChannel> subject_;
  std::unique_ptr<WebServer> server_;
  // The pointer's sink (civetweb threads) and StepPause (the step thread) both publish on
  // `pointer`: this serialises them and guards the members below.
  std::mutex pointer_mutex_;
  msg::HumanInput pointer_sample_;
  bool pause_without_subject_ = false;  // params.pause_without_subject
  bool paused_ = false;                 // no page steers: the pause marker was published
  bool pointed_since_pause_ = false;    // a page's sample was published since the pause began
  int pauses_ = 0;                      // step thread only, with paused_ns_ and pause_start_ns_
  int64_t paused_ns_ = 0, pause_start_ns_ = 0;
  std::mutex notes_mutex_;  // notes_'s Publish calls: the experimenter's notes (civetweb) and the pause marks (Step)
  Output<msg::SelfReport>* reports_ = nullptr;  // owned by the runtime; may be unbound
  Output<msg::SubjectTask>* task_out_ = nullptr;  // owned by the runtime; may be unbound
  int primitives_ = 0;                            // of params.dataset (0: none)
  std::vector<std::string> primitive_names_;     // of params.dataset (empty: it names none)
  SubjectChannel::Task task_;                     // as sent (Step's; the experimenter's page reads it there too)
  bool task_sent_ = false;
  bool countdown_asked_ = false;                  // set by task_countdown_s's commit (step thread)
  // The steering page's last hold (runtime clock), for its self-report; touched only by the
  // subject channel's sinks, which it serialises.
  std::atomic<bool> holding_{false};  // read by Step for the experimenter's page
  bool answerable_ = false;
  int64_t hold_start_ns_ = 0, hold_end_ns_ = 0, min_hold_ns_ = 0;
  // self_reports: after_trial. The holds of the trial, kept by the pointer sink (ends, strokes)
  // and Step (the robot's paths), until the questions start; then `asked_`, read by the report sink.
  struct Hold {
    int64_t start_ns = 0, end_ns = 0;  // end 0: under way
    SubjectChannel::Trace stroke;      // the steering page's pointer while held: what the person drew
    SubjectChannel::Trace robot;       // the robot's path meanwhile (empty without robot state)
  };
  bool after_trial_ = false;
  int64_t ask_after_ns_ = 0, question_timeout_ns_ = 0, first_step_ns_ = -1;
  std::mutex holds_mutex_;  // guards the members below
  std::vector<Hold> holds_, asked_;
  bool asking_ = false;
  int64_t question_start_ns_ = 0, question_shown_ns_ = 0;
  std::atomic<int> answered_{0}, lost_{0};  // questions answered; of those, answers not published
  int64_t all_answered_ns_ = -1;  // step thread only
  bool stop_requested_ = false;   // step thread only
};

}  // namespace dyad::web
