// tools/study/online_front.hpp: the participants' side of `dyad study serve` (docs/study.md, "A
// study online"): the handler of every subject's page that connects to the one endpoint.
//
// Each participant's page is told, between trials, what OnlineSession says (consent, waiting with
// a Ready button, done with the completion code, refused); it answers {"op":"consent","agree":b}
// and {"op":"ready"}. Ready starts the next attempt on a thread of the participant's: RunAttempt
// as the lab runs it, the graph's subject web component on a free loopback port of its own,
// waiting for the page (wait_for_subject_s) and paused while it is gone (pause_without_subject).
// During the trial every text frame of the page is relayed to that web component and back (a
// WsClient per page connection, connected every 200 ms until the graph listens). At each phase
// change (a trial starts, a trial ends) the page's socket is closed with 1012: the page
// reconnects at once, so each phase starts on a fresh socket. Every ping_interval each page gets
// {"op":"ping","id":n}; its pong is swallowed (not relayed) and gives the round trip.
//
// Contract:
//   - One page per participant: a second one while the first is open gets {"op":"refused",
//     "message":"This link is already open in another window."} and is closed with 1008.
//   - At most max_sessions live sessions (a page connected, a trial running, or the page gone
//     less than reconnect_s between trials): a participant whose session is not live then gets
//     {"op":"refused","message":"Please come back later: ..."}, closed with 1008; nothing starts.
//   - A live session holds the participant's SessionLock (a lab `study run` of them is refused,
//     and a participant the lab holds is refused here); it is released reconnect_s after the
//     page left between trials.
//   - Mid-trial, a page gone more than reconnect_s stops the trial, which ends incomplete: "the
//     participant's connection was lost for more than N s" (AttemptRequest::incomplete_reason).
//   - StopAll (SIGINT/SIGTERM): no trial starts any more, every running one is stopped as `dyad
//     study run` stops it, and this returns once they have ended and every relay is closed.
//
// Threads: the ClientHandler calls come from the web server (see web_server.hpp); Tick from the
// server's loop; each trial runs on a thread of its own. Everything shared is under one mutex,
// never held while a socket is written or a trial runs.
#pragma once

#include <atomic>
#include <chrono>
#include <map>
#include <memory>
#include <string>

#include "dyad/thread_annotations.hpp"
#include "study_file.hpp"
#include "study_session.hpp"
#include "web_server.hpp"

namespace dyad::study {

struct FrontOptions {
  std::string dyad;                // the dyad executable
  int max_sessions = 16;           // >= 1
  double wait_for_subject_s = 15;  // a trial's graph waits this long for the page (it reconnects at once)
  std::chrono::milliseconds ping_interval{2000};
};

class OnlineFront final : public web::ClientHandler {
 public:
  using Clock = std::chrono::steady_clock;
  OnlineFront(const Study& s, FrontOptions o);
  ~OnlineFront() override;  // StopAll()

  // The server whose pages this handles (null: none any more; no frame is sent after that).
  void SetServer(web::WebServer* server) { server_.store(server); }
  // From the server's loop, every 100 ms or so: lost pages, released sessions, pings.
  void Tick(Clock::time_point now);
  void StopAll();
  int running() const;  // trials running now
  int live(Clock::time_point now) const;

  void OnOpen(web::ClientId client, web::Role role) override;
  Status OnText(web::ClientId client, std::string_view text) override;
  Status OnBinary(web::ClientId, std::span<const uint8_t>) override { return Status::OK(); }
  void OnClose(web::ClientId client) override;

 private:
  struct Participant;
  // Why `client` may not be p's page now ("" when it is, from now on).
  std::string Take(Participant& p, web::ClientId client, Clock::time_point now) REQUIRES(mutex_);
  int LiveLocked(Clock::time_point now) const REQUIRES(mutex_);
  void Relay(Participant& p, web::ClientId client);
  bool Pong(Participant& p, std::string_view text);
  void Answer(Participant& p, web::ClientId client, std::string_view text);
  void StartTrial(Participant& p);
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
};

}  // namespace dyad::study
