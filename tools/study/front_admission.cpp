#include "front_admission.hpp"

#include <filesystem>

#include "study_links.hpp"

namespace dyad::study {

FrontAdmission::FrontAdmission(const Study& s, std::vector<std::string>* problems) : study_(s) {
  MutexLock lock(mutex_);
  missing_ = s.participants;
  ReadMissing(problems);
  last_read_ = Clock::now();
}

void FrontAdmission::ReadMissing(std::vector<std::string>* problems) {
  if (study_.token_file_webs.size() != 1) return;
  std::vector<std::string> still;
  for (const std::string& p : missing_) {
    const std::string file = (std::filesystem::path(study_.data) / p / (study_.token_file_webs[0] + "-tokens")).string();
    std::error_code ec;
    if (!std::filesystem::exists(std::filesystem::symlink_status(file, ec))) {
      still.push_back(p);
      continue;
    }
    auto token = ReadSubjectToken(file);
    if (token.ok()) tokens_.emplace_back(*token, p);
    else if (problems) problems->push_back(token.status().message());
  }
  missing_ = std::move(still);
}

std::variant<web::Admission, web::Refusal> FrontAdmission::Admit(std::string_view token, std::string_view remote_address,
                                                                 Clock::time_point now) {
  MutexLock lock(mutex_);
  // A known token first: the limit never refuses one (behind a proxy or NAT every participant
  // shares the guesser's address).
  if (!experimenter_.empty() && web::TokenMatches(token, experimenter_)) return web::Admission{web::Role::kExperimenter, ""};
  std::string who;
  for (int pass = 0; pass < 2 && who.empty(); ++pass) {
    if (pass == 1) {  // links made since: their files read, at most once a second
      if (missing_.empty() || now - last_read_ < std::chrono::seconds(1)) break;
      last_read_ = now;
      ReadMissing(nullptr);
    }
    for (const auto& [known, participant] : tokens_)  // every one compared: constant time per token
      if (web::TokenMatches(token, known)) who = participant;
  }
  if (!who.empty()) return web::Admission{web::Role::kSubject, who};
  auto window = by_address_.find(remote_address);
  if (window != by_address_.end() && now - window->second.start >= std::chrono::minutes(1)) {
    by_address_.erase(window);
    window = by_address_.end();
  }
  if (window != by_address_.end() && window->second.unknown > kUnknownPerMinute)
    return web::Refusal{429, "too many unknown links: wait a minute"};
  if (window == by_address_.end()) window = by_address_.emplace(std::string(remote_address), Window{now, 0}).first;
  ++window->second.unknown;
  // The old windows go once in a while (an address that never comes back).
  if (by_address_.size() > 4096)
    std::erase_if(by_address_, [&](const auto& kv) { return now - kv.second.start >= std::chrono::minutes(1); });
  return web::Refusal{404, "not found"};
}

void FrontAdmission::SetExperimenterToken(std::string token) {
  MutexLock lock(mutex_);
  experimenter_ = std::move(token);
}

int FrontAdmission::with_links() const {
  MutexLock lock(mutex_);
  return static_cast<int>(tokens_.size());
}

}  // namespace dyad::study
