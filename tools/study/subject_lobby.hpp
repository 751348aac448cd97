// tools/study/subject_lobby.hpp: the subject's page for a whole session (docs/study.md, "The
// subject's link"): `dyad study run --page` serves the graph's own subject's page (the web
// component's, components/web/pages/subject.html) on the address and port each trial's web
// component will bind, with the participant's subject token, whenever no trial runs. So one link
// opens at once, before the first trial, and stays valid across the session: between trials the
// page is here and says "waiting for the experimenter"; when a trial starts the lobby closes,
// the trial's graph takes the port, and the page reconnects to it by itself (it retries every
// second). The trial's web component waits for it (`wait_for_subject_s`) before the clock runs.
//
// Why the port handover and not a proxy: the page, its WebSocket protocol and the trial's graph
// stay what they are (the same page a graph run by hand serves), the runner forwards no traffic,
// and a later front (#45's `dyad study serve`) needs only what a participant keeps for the whole
// session, a stable address and token, which this gives.
//
// WebSocket `/subject/ws` here (the page's own socket): server -> page {"op":"waiting",
// "message":"..."} on connecting and at each change of the message; the page's frames (pointer
// samples) are ignored: nothing here steers or records.
//
// Contract:
//   - SubjectToken reads the `subject` line of a web component's token_file (its format:
//     "ROLE TOKEN" lines for experimenter, subject and viewer; 0600), and makes that file with new
//     tokens when it is missing, as the component would.
//   - Open binds the address and port (the first Open of port 0 picks a free one; later Opens
//     the same), Close frees them (every page is disconnected: it retries). pages() counts the
//     pages connected now with the subject's token.
#pragma once

#include <atomic>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "dyad/status.hpp"
#include "dyad/thread_annotations.hpp"
#include "web_server.hpp"

namespace dyad::study {

StatusOr<std::string> SubjectToken(const std::string& token_file);

class SubjectLobby final : public web::ClientHandler {
 public:
  SubjectLobby(std::string address, int port, std::string subject_token)
      : address_(std::move(address)), port_(port), token_(std::move(subject_token)) {}
  ~SubjectLobby() override { Close(); }

  Status Open();
  void Close();
  bool open() const { return server_ != nullptr; }
  int port() const { return port_; }
  int pages() const { return pages_.load(); }
  // The subject's link (each host of the address).
  std::vector<std::string> Links() const;
  // What every page shows while it waits (now, and to each page that connects).
  void SetMessage(const std::string& text);

  void OnOpen(web::ClientId client, web::Role role) override;
  Status OnText(web::ClientId, std::string_view) override { return Status::OK(); }
  Status OnBinary(web::ClientId, std::span<const uint8_t>) override { return Status::OK(); }
  void OnClose(web::ClientId client) override;

 private:
  std::string WaitingJson() const REQUIRES(mutex_);
  const std::string address_;
  std::atomic<int> port_;  // bound by the first Open (read by the study page's threads)
  const std::string token_;
  std::unique_ptr<web::WebServer> server_;  // null while closed (a trial runs)
  std::atomic<web::WebServer*> live_{nullptr};
  mutable Mutex mutex_;
  std::string message_ GUARDED_BY(mutex_);
  std::set<web::ClientId> subjects_ GUARDED_BY(mutex_);
  std::atomic<int> pages_{0};
};

}  // namespace dyad::study
