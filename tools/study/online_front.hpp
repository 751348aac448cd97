// tools/study/online_front.hpp: the participants' side of `dyad study serve` (docs/study.md, "A
// study online"): the handler of every subject's page that connects to the one endpoint.
//
// Each participant's page is told, between trials, what OnlineSession says (consent, waiting with
// a Ready button, done with the completion code, refused); it answers {"op":"consent","agree":b}
// and {"op":"ready"}. Ready starts the next attempt on a thread of the participant's: RunAttempt
// as the lab runs it, the graph's subject web component on a loopback port it picks itself (port
// 0) and writes into the participant's folder (DATA/P/.trial-N.port, the folder 0700), waiting
// for the page (wait_for_subject_s) and paused while it is gone (pause_without_subject). During
// the trial every text frame of the page is relayed to that web component and back (a WsClient
// per page connection, tried every 200 ms until the graph has written its port and listens):
// the relay and the overview's stats connect only to the port the graph wrote. At each phase
// change (a trial starts, a trial ends) the page's socket is closed with 1012: the page
// reconnects at once, so each phase starts on a fresh socket. Every ping_interval each page gets
// {"op":"ping","id":n}; its pong is swallowed (not relayed) and gives the round trip.
//
// Contract:
//   - One page per participant: a second one while the first is open gets {"op":"refused",
//     "message":"This link is already open in another window."} and is closed with 1008. A first
//     page silent for 2 ping intervals + 1 s (no pong: a connection dead without a close, which
//     TCP may take minutes to notice) is closed instead (1001), and the new one takes its place.
//   - At most max_sessions live sessions (a page connected, a trial running, or the page gone
//     less than reconnect_s between trials): a participant whose session is not live then gets
//     {"op":"refused","message":"Please come back later: ..."}, closed with 1008; nothing starts.
//     A participant done or refused (declined, withdrawn, ended) is not counted: their page is
//     told that (the completion code, the refusal) and closed; StopSession between trials frees
//     the session's place at once.
//   - A running trial's graph is on a DDS domain no other running trial has
//     (FrontOptions::domains, trial_domains.hpp), given back when its `dyad run` has exited.
//   - A live session holds the participant's SessionLock (a lab `study run` of them is refused,
//     and a participant the lab holds is refused here); it is released reconnect_s after the
//     page left between trials.
//   - A participant whose trial failed 3 times in a row (its graph exited with an error or never
//     started) is not offered another attempt until the front restarts: their page is told
//     {"op":"refused","message":"Something went wrong on our side, ..."} (a broken graph or
//     machine would otherwise fail at every Ready).
//   - Mid-trial, a page gone more than reconnect_s stops the trial, which ends incomplete: "the
//     participant's connection was lost for more than N s" (AttemptRequest::incomplete_reason).
//   - StopSession (the experimenter's overview, overview_channel.hpp): {"event":"session_ended",
//     "reason":...} logged, a running trial stopped and ended incomplete ("stopped by the
//     experimenter: REASON"), no trial starts for the participant any more and their page is told
//     the session has ended (OnlineSession's refused), also after a restart (the log holds it),
//     until ResumeSession logs {"event":"session_resumed"}: the link then opens the session where
//     it was (the stopped trial repeated with its reason).
//   - Snapshot: every live session, and those ended during this serve, for the overview.
//   - StopAll (SIGINT/SIGTERM): no trial starts any more, every running one is stopped as `dyad
//     study run` stops it, and this returns once they have ended and every relay is closed.
//
// Threads: the ClientHandler calls come from the web server (see web_server.hpp): OnOpen, OnClose
// and (study serve's endpoint says its handler only queues) OnText on civetweb's workers, whose
// 100 KB stacks an ASan build overflowed reading a session log there. So each only queues the
// page's event (a map look-up, no file, no lock file, no send that waits) for the front's own
// thread (a normal stack), started with the front and stopped by StopAll, which handles every
// page's events in the order they came: one page's open, then its frames, then its close; a
// close that comes while its open is still queued ends both unhandled. A page whose frames queue
// up past 1 MiB (the front's thread far behind) is closed (1008) rather than held in memory.
// Except during a trial: a page's frame is relayed by the worker that read it (RelayAtOnce), unless
// an earlier frame of the page still waits for the front's thread (then it queues behind it).
// Tick comes from the server's loop; each trial runs on a thread of its own, each relay's
// connection too. Everything shared is under one mutex, never held while a socket is written or
// a trial runs.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "dyad/thread_annotations.hpp"
#include "study_file.hpp"
#include "study_session.hpp"
#include "trial_domains.hpp"
#include "web_server.hpp"

namespace dyad::study {

struct FrontOptions {
  std::string dyad;                // the dyad executable
  int max_sessions = 16;           // >= 1
  double wait_for_subject_s = 15;  // a trial's graph waits this long for the page (it reconnects at once)
  std::chrono::milliseconds ping_interval{2000};
  // Each running trial's graph on a domain of its own from these (trial_domains.hpp); empty (the
  // default): every trial on the graph's own domain.
  DomainRange domains{};
};

class OnlineFront final : public web::ClientHandler {
 public:
  using Clock = std::chrono::steady_clock;
  // One session as the experimenter's overview shows it.
  struct SessionView {
    std::string participant;
    std::string phase;  // consent, waiting, trial, paused (a trial, the page gone), away (between trials), done, refused, ended
    double gone_s = 0;  // paused or away: the page gone this long
    int trial = 0, of = 0, attempt = 0;  // the running trial, else the next one (0: none)
    std::string shown;                   // its condition as the experimenter may see it (Study::Shown)
    std::string file;                    // the running attempt's recording ("" between trials)
    int port = 0;                        // the running trial's web component (0: none)
    int domain = -1;                     // the running trial's DDS domain (-1: none, or the graph's own)
    std::optional<bool> engaged;         // the relayed page's last pointer sample this trial (none yet: nullopt)
    double rtt_ms = -1;                  // the page's last ping round trip (-1: none yet)
    std::string ended;                   // the experimenter's reason, when ended
  };
  OnlineFront(const Study& s, FrontOptions o);
  ~OnlineFront() override;  // StopAll()

  // The server whose pages this handles (null: none any more; no frame is sent after that).
  void SetServer(web::WebServer* server) { server_.store(server); }
  // From the server's loop, every 100 ms or so: lost pages, released sessions, pings.
  void Tick(Clock::time_point now);
  // Also stops the front's thread: the page events still queued are dropped (a page opened is
  // closed, 1001) and those that come later too.
  void StopAll();
  int running() const;  // trials running now
  int live(Clock::time_point now) const;
  std::vector<SessionView> Snapshot(Clock::time_point now) const;
  // See the contract; NotFound for an unknown participant, InvalidArgument without a reason.
  Status StopSession(const std::string& participant, const std::string& reason);
  Status ResumeSession(const std::string& participant);

  // Each only queues the page's event for the front's thread (see Threads above); but a frame of a
  // page whose trial runs, with none of the page's events waiting, is relayed at once (RelayAtOnce).
  void OnOpen(web::ClientId client, web::Role role) override;
  Status OnText(web::ClientId client, std::string_view text) override;
  Status OnBinary(web::ClientId, std::span<const uint8_t>) override { return Status::OK(); }
  void OnClose(web::ClientId client) override;

 private:
  struct Participant;
  struct Event {
    enum class Kind { kOpen, kText, kClose } kind;
    web::ClientId client = 0;
    Participant* participant = nullptr;  // kOpen: whose link the page opened
    std::string text;                    // kText
    int64_t received_ns = 0;             // kText: when a worker had it (wall clock, ns since the epoch)
    bool ordered = false;                // kText: counted in in_flight_ (a pong is not: never relayed)
  };
  // The front's thread: the queued events, one at a time, until StopAll.
  void Events();
  // On the front's thread: a page opened, a frame, a page closed.
  void Open(Participant& p, web::ClientId client);
  void Text(web::ClientId client, std::string_view text, int64_t received_ns);
  void Closed(web::ClientId client);
  // Why `client` may not be p's page now ("" when it is, from now on). `final`: p's session is
  // done or refused (its page is only told so): max_sessions does not apply.
  std::string Take(Participant& p, web::ClientId client, Clock::time_point now, bool final) REQUIRES(mutex_);
  int LiveLocked(Clock::time_point now) const REQUIRES(mutex_);
  // The running trial's port, as its graph wrote it into p's port_file (0: no trial, or not yet).
  int TrialPort(Participant& p) const;
  void Relay(Participant& p, web::ClientId client);
  // Closes p's page `client` with 1012 (it reconnects at once): no longer p's page from now on.
  void NextPhase(Participant& p, web::ClientId client, const std::string& reason);
  // The page's frame for p's phase (OnlineSession::PageFrame); done or refused, the page is then
  // closed (1000, 1008: it keeps its view and does not come back) and its session is not live.
  void SendPhase(Participant& p, web::ClientId client);
  bool Pong(Participant& p, std::string_view text);
  // A relayed frame: a pointer sample's "engaged" for the overview; returns its page's stamp
  // "wall" (ms since the epoch), or a negative number when it has none.
  double Pointer(Participant& p, std::string_view text);
  // On the worker that read the frame: relays it to the page's trial when one runs and none of the
  // page's frames wait for the front's thread (they go first: a page's frames keep their order),
  // so a page's frames do not queue behind every other page's on one thread. False: the frame is
  // for the front's thread (a pong, no trial, an earlier event waiting, a write that failed).
  bool RelayAtOnce(web::ClientId client, std::string_view text, int64_t received_ns);
  // The pointer delays through the front (page -> a worker has the frame -> relayed), logged on
  // StopAll (bench/capacity reads them): where the graph's "page -> socket" goes.
  void NotePointerDelay(double wall_ms, int64_t received_ns);
  void Answer(Participant& p, web::ClientId client, std::string_view text);
  // Starts p's next trial; a trial that cannot start (its token file unreadable, its graph failed
  // kFailuresInARow times, no domain free) returns what its page is told ("" when started or nothing to say).
  std::string StartTrial(Participant& p);
  void RunTrial(Participant& p, AttemptRequest r);
  Participant* Of(web::ClientId client);
  void Send(web::ClientId client, std::string text);
  void Close(web::ClientId client, int code, const std::string& reason);

  const Study& study_;
  const FrontOptions options_;
  std::atomic<web::WebServer*> server_{nullptr};
  std::atomic<bool> closing_{false};
  std::atomic<int> relays_{0};                                        // Relay threads under way (StopAll waits for them)
  std::map<std::string, std::unique_ptr<Participant>> participants_;  // fixed at construction
  mutable Mutex mutex_;
  std::map<web::ClientId, Participant*> clients_ GUARDED_BY(mutex_);
  TrialDomains domains_ GUARDED_BY(mutex_);  // the running trials' domains
  // The page events for the front's thread (never held while one is handled).
  Mutex events_mutex_;
  std::condition_variable events_cv_;
  std::deque<Event> events_ GUARDED_BY(events_mutex_);
  std::map<web::ClientId, size_t> queued_bytes_ GUARDED_BY(events_mutex_);  // a page's frames queued
  std::set<web::ClientId> opening_ GUARDED_BY(events_mutex_);  // opens queued (a close meanwhile erases one: neither is handled)
  bool events_stopped_ GUARDED_BY(events_mutex_) = false;
  // A page's frames queued or being handled that a relayed frame must not overtake (not its pongs).
  std::map<web::ClientId, int> in_flight_ GUARDED_BY(events_mutex_);
  Mutex delays_mutex_;
  std::vector<double> to_worker_ms_ GUARDED_BY(delays_mutex_), to_relayed_ms_ GUARDED_BY(delays_mutex_);
  std::thread events_thread_;  // last: started once the rest is made
};

}  // namespace dyad::study
