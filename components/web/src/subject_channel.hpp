/// SubjectChannel — the WebSocket behind the subject's page (`/subject/ws`): pointer input from
/// the page, robot state to it.
///
/// Page -> server (JSON text): {"op":"pointer","x":..,"y":..,"engaged":bool,"t":ms} on every
/// pointer or key event and, while engaged, after 50 ms without one (a keepalive);
/// {"op":"steer"} to take the steering role; {"op":"self_report","choice":k} the subject's answer
/// to "What were you drawing?" (k: a primitive's index, -1 "something else"; from the steering
/// page only, a viewer's is refused), with "segment":i when it answers a question after the trial
/// (below). Server -> page: {"op":"hello",...} (role, steering, workspace, engage key,
/// primitives, whether they are a watermark, whether and after how long a hold to ask),
/// {"op":"role","steering":bool}, {"op":"task","target":k,"message":"..","countdown_s":s,
/// "practice":bool} (the experimenter's task: sent to every page at each change and to a page
/// that opens, its countdown as what is left of it then), {"op":"state","x","y"} (newest
/// only: a slow page never builds a backlog), {"op":"ack","t":ms} after a pointer sample was
/// published, at most one per kAckIntervalMs to a page (the page measures the round trip; an ack
/// per sample, 60 a second, was a third of a participant's frames): a sample is acknowledged when
/// the page's last ack is kAckIntervalMs old or older, else never (no ack comes later for it, so
/// the first sample after a pause always has its own), {"op":"question","segment":i,
/// "of":n,"stroke":[[x,y],...],"robot":[[x,y],...]} after the trial (the hold's stroke: the
/// pointer's path while held, what the person drew; the robot's path meanwhile, maybe empty;
/// segment -1: every question answered, "thank you"). A pointer sample may carry "wall" (the
/// event's time, ms since the epoch): the channel then keeps the event-to-publication delay.
///
/// After the trial (self_reports: after_trial, AskAfterTrial): steering ends for good (the hold
/// ends at once, every later pointer sample is published released) and the pages are asked about
/// each of the trial's holds in turn, its stroke as the picture; the steering page's answer to the
/// question shown goes to the ReportSink with its index, then the next question is shown, to a
/// page that opens later too. An answer to another question (stale) is ignored and that page is
/// shown the current one again.
///
/// Several pages may watch; one steers: the first to connect with the subject's or the
/// experimenter's token, until it leaves (the oldest such page left then steers, a subject's
/// before an experimenter's) or another such page asks to steer. A subject's page that connects
/// while an experimenter's steers takes the steering (the experimenter opened /subject first). A
/// viewer's page only watches: a pointer sample or a steering request from it closes it. Only the
/// steering page's pointer reaches the graph; when it disconnects, a disengaged sample is
/// published at once.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include <dyad/thread_annotations.hpp>
#include <nlohmann/json_fwd.hpp>

#include "web_server.hpp"

namespace dyad::web {

class SubjectChannel final : public ClientHandler {
 public:
  // A page's round trip is sampled as often as the control step: at most one ack per this.
  static constexpr double kAckIntervalMs = 100;

  struct Options {
    std::string engage_key = "Space";  // KeyboardEvent.code; the mouse button always engages
    double half_width = 50;            // the workspace is [-half_width, half_width]^2
    std::vector<std::vector<std::array<double, 2>>> primitives;  // for the watermark and the question
    std::vector<std::string> names;  // the data set's names of the primitives (empty: none)
    bool watermark = true;          // draw the primitives faintly behind the workspace
    bool ask = false;               // ask "What were you drawing?" after each release
    double ask_after_hold_s = 1.0;  // ... of a hold at least this long (a tap is no event)
    // The wall clock in ms since the epoch, read as a message is handled: the acks' interval and
    // the pointer delays. Empty: the system's (a test gives its own).
    std::function<double()> wall_ms;
  };
  // Publishes one pointer sample on the graph (called on civetweb threads, serialised here).
  using PointerSink = std::function<void(double x, double y, bool engaged)>;

  // Publishes the steering page's answer (called like PointerSink); its Status goes back to the
  // page. segment: -1 after an event (after_event), else the index of the hold asked about.
  using ReportSink = std::function<Status(int choice, int segment)>;

  SubjectChannel(Options options, PointerSink sink, ReportSink report = {})
      : options_(std::move(options)), sink_(std::move(sink)), report_(std::move(report)) {}
  void SetServer(WebServer* server);
  // Sends the robot's position to every page (newest only).
  void BroadcastState(double x, double y);
  // The experimenter's task for the person (web component's task_* params, practice).
  struct Task {
    int target = -1;          // a primitive to draw; -1: none
    std::string message;      // empty: none
    double countdown_s = 0;   // a countdown of this length started at `countdown_start` (0: none)
    std::chrono::steady_clock::time_point countdown_start{};
    bool practice = false;
    double time_s = 0;  // the trial's length from `time_start`: the page shows the time left (0: none)
    std::chrono::steady_clock::time_point time_start{};
  };
  // Sends it to every page, and to every page that opens later.
  void SetTask(const Task& task);
  size_t pages() const;
  // Whether a page steers now (the web component's wait_for_subject_s waits for one).
  bool steered() const;
  // After the trial (see the file comment). EndSteering: no page steers any more (a hold under
  // way ends now, through the PointerSink). AskAfterTrial: ends the steering if not yet, then
  // asks about each hold in turn (none: thanks at once). Each acts once per channel.
  using Trace = std::vector<std::array<double, 2>>;
  struct Question {
    Trace stroke;  // the pointer's path while held: what the person drew (the picture)
    Trace robot;   // the robot's path meanwhile, drawn faintly beside it (may be empty)
  };
  void EndSteering();
  void AskAfterTrial(std::vector<Question> questions);
  // Where a pointer sample's time went, in ms, for each sample that carried the page's "wall"
  // stamp (meaningful when page and server share a clock; the first 100,000). The hops add up to
  // the total; the hops are empty when no server delivered the samples.
  struct PointerDelays {
    std::vector<double> total;                 // the page's event -> published on the graph
    std::vector<double> page_to_socket;        // -> civetweb's worker has the frame (page, socket)
    std::vector<double> socket_to_handler;     // -> the one handler thread starts on it (its queue)
    std::vector<double> handler_to_published;  // -> published (JSON parse, the DDS write)
  };
  PointerDelays pointer_delays() const;

  void OnOpen(ClientId client, Role role) override;
  Status OnText(ClientId client, std::string_view text) override;
  Status OnBinary(ClientId client, std::span<const uint8_t> bytes) override;
  void OnClose(ClientId client) override;

 private:
  // OnText's ops, the JSON object checked to be one with an "op" string.
  Status OnPointer(ClientId client, const nlohmann::json& j, double handler_ms);
  Status OnSteer(ClientId client);
  Status OnSelfReport(ClientId client, const nlohmann::json& j);
  void SendRole(ClientId client, bool steering);
  std::string TaskJson() const REQUIRES(mutex_);
  std::string QuestionJson() const REQUIRES(mutex_);
  void EndSteeringLocked() REQUIRES(mutex_);
  void SendToAll(uint32_t channel, const std::string& frame);
  double WallMs() const;  // options_.wall_ms, or the system's
  const Options options_;
  const PointerSink sink_;
  const ReportSink report_;
  std::atomic<WebServer*> server_{nullptr};
  // Guards the members below and serialises sink_ calls.
  mutable Mutex mutex_;
  std::vector<ClientId> pages_ GUARDED_BY(mutex_);  // in connection order
  std::map<ClientId, Role> roles_ GUARDED_BY(mutex_);
  ClientId steering_ GUARDED_BY(mutex_) = 0;  // 0: none
  double last_x_ GUARDED_BY(mutex_) = 0;
  double last_y_ GUARDED_BY(mutex_) = 0;
  ClientId acked_ GUARDED_BY(mutex_) = 0;  // the page acknowledged last, and when (wall ms)
  double acked_ms_ GUARDED_BY(mutex_) = 0;
  Task task_ GUARDED_BY(mutex_);
  bool trial_over_ GUARDED_BY(mutex_) = false;  // EndSteering came: no more steering
  bool asking_ GUARDED_BY(mutex_) = false;      // AskAfterTrial came: questions_ are asked
  std::vector<Question> questions_ GUARDED_BY(mutex_);
  size_t asked_ GUARDED_BY(mutex_) = 0;  // the question shown; questions_.size(): all answered
  PointerDelays delays_ GUARDED_BY(mutex_);
};

}  // namespace dyad::web
