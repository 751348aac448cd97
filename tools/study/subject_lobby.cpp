#include "subject_lobby.hpp"

#include <sys/stat.h>

#include <fstream>

#include <nlohmann/json.hpp>

#include "dyad/private_file.hpp"
#include "pages.hpp"

namespace dyad::study {

StatusOr<std::string> SubjectToken(const std::string& token_file) {
  struct stat st {};
  if (lstat(token_file.c_str(), &st) != 0) {
    const std::string subject = web::RandomToken();
    const std::string text =
        "experimenter " + web::RandomToken() + "\nsubject " + subject + "\nviewer " + web::RandomToken() + "\n";
    if (Status s = WritePrivateFile(token_file, text, CreateMode::kNew); !s.ok()) return s;
    return subject;
  }
  std::ifstream in(token_file);
  for (std::string line; std::getline(in, line);)
    if (line.rfind("subject ", 0) == 0 && line.size() > 8) return line.substr(8);
  // The web component says what is wrong with the file when the trial starts; no link meanwhile.
  return Status::InvalidArgument(token_file + ": no 'subject TOKEN' line");
}

Status SubjectLobby::Open() {
  if (server_) return Status::OK();
  web::WebServer::Options o;
  o.address = address_;
  o.port = port_;
  o.tokens = {{web::Role::kSubject, token_}};
  o.pages["/subject"] = web::WebServer::Page{"text/html; charset=utf-8", web::kSubjectHtml, {web::Role::kSubject}, ""};
  o.endpoints.push_back(web::WebServer::Endpoint{"/subject/ws", {}, this, {web::Role::kSubject}, /*viewers=*/false});
  auto server = web::WebServer::Start(o);
  if (!server.ok())
    return server.status().WithContext("the subject's page between trials (" + address_ + ":" + std::to_string(port_) + ")");
  server_ = std::move(server.value());
  port_ = server_->port();
  live_.store(server_.get());
  return Status::OK();
}

void SubjectLobby::Close() {
  live_.store(nullptr);
  server_.reset();  // every page disconnected (OnClose for each), the port free
}

std::vector<std::string> SubjectLobby::Links() const {
  std::vector<std::string> out;
  for (const std::string& host : web::UrlHosts(address_))
    out.push_back("http://" + host + ":" + std::to_string(port_) + "/subject?token=" + token_);
  return out;
}

std::string SubjectLobby::WaitingJson() const { return nlohmann::json{{"op", "waiting"}, {"message", message_}}.dump(); }

void SubjectLobby::SetMessage(const std::string& text) {
  std::string json;
  std::set<web::ClientId> pages;
  {
    MutexLock lock(mutex_);
    message_ = text;
    json = WaitingJson();
    pages = subjects_;
  }
  if (web::WebServer* server = live_.load())
    for (web::ClientId c : pages) server->SendText(c, json);
}

void SubjectLobby::OnOpen(web::ClientId client, web::Role) {
  std::string json;
  {
    MutexLock lock(mutex_);
    subjects_.insert(client);
    pages_.store(static_cast<int>(subjects_.size()));
    json = WaitingJson();
  }
  if (web::WebServer* server = live_.load()) server->SendText(client, json);
}

void SubjectLobby::OnClose(web::ClientId client) {
  MutexLock lock(mutex_);
  subjects_.erase(client);
  pages_.store(static_cast<int>(subjects_.size()));
}

}  // namespace dyad::study
