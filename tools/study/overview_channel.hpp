// tools/study/overview_channel.hpp: the experimenter's overview of `dyad study serve` (docs/study.md,
// "The experimenter's overview"): one page with every live session, a note to a session's log,
// and stopping a session with its reason.
//
// The page is `/overview?token=E` (overview.html), E the serve's experimenter token: the
// "experimenter TOKEN" line of DATA/serve-tokens (ServeExperimenterToken: made 0600 on the first
// start, read after; a link, a file readable by others or a bad token is refused, naming the
// file). `dyad study serve` prints the link. Participants' tokens do not open it, nor E a
// participant's page.
//
// WebSocket `/overview/ws?token=E` (the experimenter's role only), JSON text both ways:
//   server -> page: {"op":"state","study","blind","participants":n,"max_sessions","reconnect_s",
//     "sessions":[{"participant","phase","gone_s","trial","of","attempt","shown","file","domain",
//     "recording_bytes","engaged","rtt_ms","step_p99_ms","step_component","misses","ended"}]}
//     once a second and after each request: every live session and each one ended (OnlineFront::
//     Snapshot; phase: consent, waiting, trial, paused (a trial whose page is gone: gone_s),
//     away (between trials, gone_s), done, refused, ended (ended: the experimenter's reason));
//     trial of `of`: the running trial, else the next one; shown: its condition as the
//     experimenter may see it (the label when the study is blind); domain: the running trial's DDS
//     domain (null: none, or every trial on the graph's own); recording_bytes: the running
//     attempt's file now; engaged: the relayed page's last pointer sample (false while the page
//     is gone); rtt_ms: the page's ping round trip; step_p99_ms and misses: the running trial's
//     graph's own stats (the largest step p99 of its components, which one, and their deadline
//     misses summed), from its web component's {"op":"stats"} once a second on /experimenter/ws
//     (a WsClient per running trial, with the experimenter token of the participant's
//     DATA/P/<web>-tokens; "ended" is set while a stopped session's trial ends too).
//     null: not known (yet).
//     {"op":"done","request","participant"} when a request was carried out; {"op":"error",
//     "message"} when it was refused (the page stays).
//   page -> server:
//     {"op":"note","participant":P,"text":".."}: AddNote, P's session log (with the trial under way)
//     {"op":"stop","participant":P,"reason":".."}: OnlineFront::StopSession (the running trial
//       stopped and ended incomplete with the reason; no more trials; P's page told the session
//       has ended; {"event":"session_ended"} logged)
//     {"op":"resume","participant":P}: OnlineFront::ResumeSession (P's link opens the session
//       again where it was; the stopped trial is repeated with its reason)
//   A frame of another shape is answered with an error.
//
// Threads: the handler's calls come from the web server; Start() runs the once-a-second state and
// the stats clients on a thread of its own, until Stop(), only while an overview page is open.
#pragma once

#include <atomic>
#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <thread>

#include "dyad/status.hpp"
#include "dyad/thread_annotations.hpp"
#include "online_front.hpp"
#include "study_file.hpp"
#include "web_server.hpp"

namespace dyad::web {
class WsClient;
}

namespace dyad::study {

// DATA/serve-tokens' experimenter token, the file made (0600, its folder 0700) when missing;
// instances on one folder share it (one made at the same instant by another is read).
StatusOr<std::string> ServeExperimenterToken(const Study& s);

// A trial graph's step statistics from its web component's {"op":"stats","rows":[...]} frame
// (experimenter_channel.hpp); nullopt for any other frame.
struct StepStats {
  double p99_ms = 0;      // the largest of its components'
  std::string component;  // whose
  long misses = 0;        // deadline misses, all components
};
std::optional<StepStats> ParseStats(std::string_view frame);

class OverviewChannel final : public web::ClientHandler {
 public:
  using Clock = std::chrono::steady_clock;
  OverviewChannel(const Study& s, OnlineFront* front, int max_sessions);
  ~OverviewChannel() override;  // Stop()

  void SetServer(web::WebServer* server) { server_.store(server); }
  void Start();
  void Stop();
  // The state frame now (JSON text).
  std::string State(Clock::time_point now);

  void OnOpen(web::ClientId client, web::Role role) override;
  Status OnText(web::ClientId client, std::string_view text) override;
  Status OnBinary(web::ClientId, std::span<const uint8_t>) override { return Status::OK(); }
  void OnClose(web::ClientId client) override;

 private:
  struct Upstream;
  Status Request(std::string_view text, std::string* request, std::string* participant);
  void UpdateStats(const std::vector<OnlineFront::SessionView>& sessions);
  std::string StateOf(const std::vector<OnlineFront::SessionView>& sessions);
  void Loop();
  void Broadcast(const std::string& text);
  void Send(web::ClientId client, const std::string& text);

  const Study& study_;
  OnlineFront* const front_;
  const int max_sessions_;
  std::atomic<web::WebServer*> server_{nullptr};
  std::atomic<bool> stopping_{false};
  std::thread thread_;
  Mutex mutex_;
  std::set<web::ClientId> pages_ GUARDED_BY(mutex_);
  std::map<std::string, std::shared_ptr<Upstream>> stats_ GUARDED_BY(mutex_);  // by participant, their running trial's
};

}  // namespace dyad::study
