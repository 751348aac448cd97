// tools/study/serve_certificate.hpp: the certificate of `dyad study serve --tls-certificate PEM`
// (docs/study.md, "A study online", TLS), checked before anything listens, so a lab learns what is
// wrong with it from the command and not from a participant's browser.
//
// Contract of ReadServeCertificate(path, now):
//   - Refused (InvalidArgument; each message begins "--tls-certificate 'PATH': "): no such file or
//     not a regular file (a link to one is followed); readable by group or others (it holds the
//     private key: chmod 600 it); unreadable; no private key in it (a PEM of the certificate alone,
//     as web/cert.pem); no certificate; a key that is not the certificate's; a certificate not
//     yet valid or expired at `now`. The texts name `dyad security init ... --web-host`, which
//     makes the file (KEYSTORE/web/tls.pem: the private key, then the certificate).
//   - Accepted: the names it is issued for ("DNS:study.example.org", "IP:127.0.0.1": its
//     subjectAltName, else its CN) and its end of validity (UTC, "2027-12-07 09:56:00 UTC").
// Names(host): whether a browser opening https://HOST/ accepts the certificate's names for it
// (OpenSSL's own host and address matching, wildcards included).
#pragma once

#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include "dyad/status.hpp"

namespace dyad::study {

class ServeCertificate {
 public:
  ~ServeCertificate();
  ServeCertificate(ServeCertificate&&) noexcept;
  const std::vector<std::string>& names() const { return names_; }
  const std::string& not_after() const { return not_after_; }
  bool Names(const std::string& host) const;

 private:
  friend StatusOr<ServeCertificate> ReadServeCertificate(const std::string& path, std::time_t now);
  ServeCertificate() = default;
  struct Cert;
  std::unique_ptr<Cert> cert_;
  std::vector<std::string> names_;
  std::string not_after_;
};

StatusOr<ServeCertificate> ReadServeCertificate(const std::string& path, std::time_t now);

}  // namespace dyad::study
