// tools/study/front_admission.hpp: who a request to `dyad study serve` is (docs/study.md, "A study
// online"): each participant's subject token, from their token file DATA/P/<web>-tokens (what
// `dyad study links` writes and each trial's web component reads), maps to that participant.
//
// Contract of Admit (WebServer's Options::admit: thread-safe):
//   - A participant's token: Admission{kSubject, participant}. Tokens are compared in constant
//     time (web::TokenMatches), every known token each time.
//   - The serve's experimenter token (SetExperimenterToken; DATA/serve-tokens, overview_channel.hpp):
//     Admission{kExperimenter, ""} (the experimenter's overview).
//   - Any other token (or none): Refusal 404 "not found". Before answering, the token files that
//     were missing are read again, at most once a second (links made while the front runs).
//   - An address with more than 10 unknown tokens within a minute (from its first) gets 429
//     "too many unknown links: wait a minute" for every further unknown token until that minute
//     is over: guessing costs a minute per 10 guesses. A known token is never refused (behind a
//     proxy or NAT every participant shares the guesser's address): only unknown ones count.
//     IPv6 addresses count by their /64 (one host's many addresses, one window). At most
//     kMaxAddresses windows are kept (those over a minute old swept at most once a second):
//     when that many addresses are guessing, an unknown token from a new one gets 429 too.
//   - A token file that cannot be used (not a regular 0600 file, no subject line) is said once,
//     on `problems` at load, and that participant has no link.
#pragma once

#include <chrono>
#include <cstddef>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "dyad/thread_annotations.hpp"
#include "study_file.hpp"
#include "web_server.hpp"

namespace dyad::study {

class FrontAdmission {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr int kUnknownPerMinute = 10;
  static constexpr size_t kMaxAddresses = 4096;

  // Reads every participant's token file now; what is wrong with one goes to `problems`.
  FrontAdmission(const Study& s, std::vector<std::string>* problems);

  std::variant<web::Admission, web::Refusal> Admit(std::string_view token, std::string_view remote_address,
                                                   Clock::time_point now);
  // The experimenter's overview token (empty: none admitted).
  void SetExperimenterToken(std::string token);
  // How many participants have a link (a usable token file).
  int with_links() const;
  // The rate limit's key of an address: itself; an IPv6 address's /64 ("2001:db8::/64"); an
  // IPv4-mapped IPv6 address's IPv4 text.
  static std::string AddressKey(std::string_view address);

 private:
  void ReadMissing(std::vector<std::string>* problems) REQUIRES(mutex_);
  struct Window {
    Clock::time_point start;
    int unknown = 0;
  };

  const Study& study_;
  mutable Mutex mutex_;
  std::vector<std::pair<std::string, std::string>> tokens_ GUARDED_BY(mutex_);  // (token, participant)
  std::vector<std::string> missing_ GUARDED_BY(mutex_);                         // participants without one
  std::string experimenter_ GUARDED_BY(mutex_);                                 // the overview's token ("": none)
  Clock::time_point last_read_ GUARDED_BY(mutex_);
  Clock::time_point last_sweep_ GUARDED_BY(mutex_);
  std::map<std::string, Window, std::less<>> by_address_ GUARDED_BY(mutex_);
};

}  // namespace dyad::study
