#include "front_admission.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>

#include <algorithm>
#include <filesystem>

#include "study_links.hpp"

namespace dyad::study {

std::string FrontAdmission::AddressKey(std::string_view address) {
  in6_addr a{};
  if (address.find(':') == std::string_view::npos || inet_pton(AF_INET6, std::string(address).c_str(), &a) != 1)
    return std::string(address);
  if (IN6_IS_ADDR_V4MAPPED(&a)) return std::string(address.substr(address.rfind(':') + 1));
  std::fill(a.s6_addr + 8, a.s6_addr + 16, 0);  // one window per /64: a host's rotating addresses are one
  char text[INET6_ADDRSTRLEN] = {};
  inet_ntop(AF_INET6, &a, text, sizeof text);
  return std::string(text) + "/64";
}

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
  // The windows over a minute old go, in one sweep at most once a second (not per request).
  if (now - last_sweep_ >= std::chrono::seconds(1)) {
    last_sweep_ = now;
    std::erase_if(by_address_, [&](const auto& kv) { return now - kv.second.start >= std::chrono::minutes(1); });
  }
  const web::Refusal too_many{429, "too many unknown links: wait a minute"};
  const std::string key = AddressKey(remote_address);
  auto window = by_address_.find(key);
  if (window != by_address_.end() && now - window->second.start >= std::chrono::minutes(1)) {
    by_address_.erase(window);
    window = by_address_.end();
  }
  if (window != by_address_.end() && window->second.unknown > kUnknownPerMinute) return too_many;
  if (window == by_address_.end()) {
    if (by_address_.size() >= kMaxAddresses) return too_many;  // many addresses guessing: unknown tokens wait
    window = by_address_.emplace(key, Window{now, 0}).first;
  }
  ++window->second.unknown;
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
