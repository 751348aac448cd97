#include "serve_certificate.hpp"

#include <openssl/bio.h>
#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>
#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

namespace dyad::study {

struct ServeCertificate::Cert {
  X509* x509 = nullptr;
  ~Cert() { X509_free(x509); }
};

ServeCertificate::~ServeCertificate() = default;
ServeCertificate::ServeCertificate(ServeCertificate&&) noexcept = default;

bool ServeCertificate::Names(const std::string& host) const {
  std::string h = host;
  if (h.size() > 2 && h.front() == '[' && h.back() == ']') h = h.substr(1, h.size() - 2);  // [::1]
  if (X509_check_ip_asc(cert_->x509, h.c_str(), 0) == 1) return true;
  return X509_check_host(cert_->x509, h.c_str(), h.size(), 0, nullptr) == 1;
}

namespace {

const char* const kMakes =
    "dyad security init KEYSTORE --graph GRAPH --web-host HOST makes KEYSTORE/web/tls.pem: the private key, then the certificate";

// Its subjectAltName's DNS names and addresses, else its CN.
std::vector<std::string> AltNames(X509* x509) {
  std::vector<std::string> names;
  auto* sans = static_cast<GENERAL_NAMES*>(X509_get_ext_d2i(x509, NID_subject_alt_name, nullptr, nullptr));
  for (int i = 0; sans != nullptr && i < sk_GENERAL_NAME_num(sans); ++i) {
    const GENERAL_NAME* n = sk_GENERAL_NAME_value(sans, i);
    if (n->type == GEN_DNS) {
      names.push_back("DNS:" + std::string(reinterpret_cast<const char*>(ASN1_STRING_get0_data(n->d.dNSName)),
                                           ASN1_STRING_length(n->d.dNSName)));
    } else if (n->type == GEN_IPADD) {
      BIO* b = BIO_new(BIO_s_mem());
      GENERAL_NAME_print(b, const_cast<GENERAL_NAME*>(n));  // "IP Address:127.0.0.1"
      char* text = nullptr;
      const long len = BIO_get_mem_data(b, &text);
      std::string s(text, static_cast<size_t>(len));
      names.push_back("IP:" + s.substr(s.find(':') + 1));
      BIO_free(b);
    }
  }
  GENERAL_NAMES_free(sans);
  if (names.empty()) {
    char cn[256] = {0};
    if (X509_NAME_get_text_by_NID(X509_get_subject_name(x509), NID_commonName, cn, sizeof cn) > 0)
      names.push_back(std::string("CN:") + cn);
  }
  return names;
}

std::string Utc(const ASN1_TIME* t) {
  std::tm tm{};
  ASN1_TIME_to_tm(t, &tm);
  char text[40];
  std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S UTC", &tm);
  return text;
}

// The file's text, or why it cannot be the certificate.
StatusOr<std::string> ReadPrivatePem(const std::string& path, const std::string& key) {
  struct stat st {};
  if (stat(path.c_str(), &st) != 0) return Status::InvalidArgument(key + std::strerror(errno) + " (" + kMakes + ")");
  if (!S_ISREG(st.st_mode)) return Status::InvalidArgument(key + "not a regular file (" + kMakes + ")");
  if ((st.st_mode & 077) != 0)
    return Status::InvalidArgument(key + "holds the private key and is readable by others: chmod 600 it");
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  if (!in || !(text << in.rdbuf())) return Status::InvalidArgument(key + "cannot be read: " + std::strerror(errno));
  return text.str();
}

}  // namespace

StatusOr<ServeCertificate> ReadServeCertificate(const std::string& path, std::time_t now) {
  const std::string key = "--tls-certificate '" + path + "': ";
  auto text = ReadPrivatePem(path, key);
  if (!text.ok()) return text.status();
  auto read = [&](auto pem_read) {  // a key under a passphrase is not asked for: civetweb cannot use one
    BIO* b = BIO_new_mem_buf(text->data(), static_cast<int>(text->size()));
    auto* out = pem_read(
        b, nullptr, [](char*, int, int, void*) { return 0; }, nullptr);
    BIO_free(b);
    return out;
  };
  EVP_PKEY* pkey = read(PEM_read_bio_PrivateKey);
  ServeCertificate c;
  c.cert_ = std::make_unique<ServeCertificate::Cert>();
  c.cert_->x509 = read(PEM_read_bio_X509);
  const bool matches = pkey != nullptr && c.cert_->x509 != nullptr && X509_check_private_key(c.cert_->x509, pkey) == 1;
  EVP_PKEY_free(pkey);
  if (pkey == nullptr)
    return Status::InvalidArgument(
        key + "no private key in it without a passphrase (a certificate alone, as web/cert.pem, is not enough; " + kMakes + ")");
  if (c.cert_->x509 == nullptr) return Status::InvalidArgument(key + "no certificate in it (" + kMakes + ")");
  if (!matches) return Status::InvalidArgument(key + "its private key is not its certificate's");
  X509* x = c.cert_->x509;
  std::time_t at = now;
  c.not_after_ = Utc(X509_get0_notAfter(x));
  if (X509_cmp_time(X509_get0_notBefore(x), &at) > 0)
    return Status::InvalidArgument(key + "not valid before " + Utc(X509_get0_notBefore(x)) + " (is this machine's clock right?)");
  if (X509_cmp_time(X509_get0_notAfter(x), &at) < 0)
    return Status::InvalidArgument(key + "expired " + c.not_after_ +
                                   " (dyad security init KEYSTORE --graph GRAPH --web-host HOST --renew web issues another)");
  c.names_ = AltNames(x);
  return c;
}

}  // namespace dyad::study
