#include "keystore.hpp"

#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <ostream>
#include <sstream>

#include <arpa/inet.h>
#include <fcntl.h>
#include <stdio.h>
#include <unistd.h>

#include <openssl/bio.h>
#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/pkcs7.h>
#include <openssl/rand.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>

#include <dyad/keystore_graph.hpp>
#include <dyad/private_file.hpp>
#include <dyad/security.hpp>
#include <dyad/wire_names.hpp>

#include "access_documents.hpp"

namespace dyad::cli {
namespace {

namespace fs = std::filesystem;

template <typename T, void (*F)(T*)>
struct Free {
  void operator()(T* p) const { F(p); }
};
using Key = std::unique_ptr<EVP_PKEY, Free<EVP_PKEY, EVP_PKEY_free>>;
using Cert = std::unique_ptr<X509, Free<X509, X509_free>>;
using Bio = std::unique_ptr<BIO, Free<BIO, BIO_free_all>>;
using Pkcs7 = std::unique_ptr<PKCS7, Free<PKCS7, PKCS7_free>>;

// OpenSSL's reason for the last failure, for messages.
std::string SslError() {
  const unsigned long e = ERR_get_error();
  if (e == 0) return "unknown OpenSSL error";
  char buf[256];
  ERR_error_string_n(e, buf, sizeof buf);
  ERR_clear_error();
  return buf;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string BioText(BIO* b) {
  char* data = nullptr;
  const long n = BIO_get_mem_data(b, &data);
  return std::string(data, static_cast<size_t>(n));
}

StatusOr<Key> ReadKey(const std::string& path) {
  Bio b(BIO_new_file(path.c_str(), "r"));
  Key k(b ? PEM_read_bio_PrivateKey(b.get(), nullptr, nullptr, nullptr) : nullptr);
  if (!k) return Status::InvalidArgument(path + ": not a PEM private key (" + SslError() + ")");
  return k;
}

StatusOr<Cert> ReadCert(const std::string& path) {
  Bio b(BIO_new_file(path.c_str(), "r"));
  Cert c(b ? PEM_read_bio_X509(b.get(), nullptr, nullptr, nullptr) : nullptr);
  if (!c) return Status::InvalidArgument(path + ": not a PEM certificate (" + SslError() + ")");
  return c;
}

StatusOr<Key> NewKey() {
  Key k(EVP_EC_gen("P-256"));
  if (!k) return Status::Internal("cannot make an EC P-256 key: " + SslError());
  return k;
}

bool AddExtension(X509* cert, X509* issuer, int nid, const char* value) {
  X509V3_CTX ctx;
  X509V3_set_ctx_nodb(&ctx);
  X509V3_set_ctx(&ctx, issuer, cert, nullptr, nullptr, 0);
  X509_EXTENSION* ext = X509V3_EXT_conf_nid(nullptr, &ctx, nid, value);
  if (ext == nullptr) return false;
  const bool ok = X509_add_ext(cert, ext, -1) == 1;
  X509_EXTENSION_free(ext);
  return ok;
}

// A certificate of `key` for `subject` ("CN=..."), signed by `issuer_key` (issuer: null for a
// self-signed CA).
enum class Use { kCa, kIdentity, kTlsServer };

StatusOr<Cert> Issue(EVP_PKEY* key, const std::string& subject, X509* issuer, EVP_PKEY* issuer_key, int days, Use use,
                     const std::string& alt_names = "") {
  Cert c(X509_new());
  X509_NAME* name = X509_NAME_new();
  const std::string cn = subject.substr(subject.find('=') + 1);
  bool ok = c && name &&
            X509_NAME_add_entry_by_txt(name, "CN", MBSTRING_UTF8, reinterpret_cast<const unsigned char*>(cn.c_str()), -1, -1,
                                       0) == 1 &&
            X509_set_version(c.get(), 2) == 1 && X509_set_subject_name(c.get(), name) == 1 &&
            X509_set_issuer_name(c.get(), issuer ? X509_get_subject_name(issuer) : name) == 1 &&
            X509_set_pubkey(c.get(), key) == 1;
  X509_NAME_free(name);
  unsigned char serial[16];
  ok = ok && RAND_bytes(serial, sizeof serial) == 1;
  serial[0] &= 0x7f;  // a positive serial number
  BIGNUM* bn = ok ? BN_bin2bn(serial, sizeof serial, nullptr) : nullptr;
  ok = ok && bn != nullptr && BN_to_ASN1_INTEGER(bn, X509_get_serialNumber(c.get())) != nullptr;
  BN_free(bn);
  ok = ok && X509_gmtime_adj(X509_getm_notBefore(c.get()), -3600) != nullptr &&  // an hour of clock skew
       X509_gmtime_adj(X509_getm_notAfter(c.get()), static_cast<long>(days) * 86400) != nullptr;
  X509* signer = issuer ? issuer : c.get();
  if (use == Use::kCa) {
    ok = ok && AddExtension(c.get(), signer, NID_basic_constraints, "critical,CA:TRUE") &&
         AddExtension(c.get(), signer, NID_key_usage, "critical,keyCertSign,cRLSign,digitalSignature");
  } else if (use == Use::kTlsServer) {
    ok = ok && AddExtension(c.get(), signer, NID_basic_constraints, "critical,CA:FALSE") &&
         AddExtension(c.get(), signer, NID_key_usage, "critical,digitalSignature") &&
         AddExtension(c.get(), signer, NID_ext_key_usage, "serverAuth") &&
         AddExtension(c.get(), signer, NID_subject_alt_name, alt_names.c_str()) &&
         AddExtension(c.get(), signer, NID_authority_key_identifier, "keyid");
  } else {
    ok = ok && AddExtension(c.get(), signer, NID_basic_constraints, "critical,CA:FALSE") &&
         AddExtension(c.get(), signer, NID_key_usage, "critical,digitalSignature,keyAgreement");
  }
  ok = ok && AddExtension(c.get(), signer, NID_subject_key_identifier, "hash") &&
       X509_sign(c.get(), issuer_key, EVP_sha256()) > 0;
  if (!ok) return Status::Internal("cannot issue a certificate for " + subject + ": " + SslError());
  return c;
}

std::string KeyPem(EVP_PKEY* k) {
  Bio b(BIO_new(BIO_s_mem()));
  PEM_write_bio_PrivateKey(b.get(), k, nullptr, nullptr, 0, nullptr, nullptr);
  return BioText(b.get());
}

std::string CertPem(X509* c) {
  Bio b(BIO_new(BIO_s_mem()));
  PEM_write_bio_X509(b.get(), c);
  return BioText(b.get());
}

// `text` as a clear-signed S/MIME message (openssl smime -sign -text).
StatusOr<std::string> SmimeSigned(const std::string& text, X509* cert, EVP_PKEY* key) {
  Bio in(BIO_new_mem_buf(text.data(), static_cast<int>(text.size())));
  const int flags = PKCS7_DETACHED | PKCS7_TEXT | PKCS7_STREAM;
  Pkcs7 p7(PKCS7_sign(cert, key, nullptr, in.get(), flags));
  Bio out(BIO_new(BIO_s_mem()));
  if (!p7 || !out || SMIME_write_PKCS7(out.get(), p7.get(), in.get(), flags) != 1)
    return Status::Internal("cannot sign: " + SslError());
  return BioText(out.get());
}

std::string Utc(time_t t) {
  char buf[32];
  std::tm tm{};
  gmtime_r(&t, &tm);
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
  return buf;
}

// One CA of the keystore: its certificate (DIR/<name>.cert.pem) and key (DIR/ca/<name>.key.pem).
class Authority {
 public:
  Authority(std::string name, std::string cert_path, std::string key_path)
      : name_(std::move(name)), cert_path_(std::move(cert_path)), key_path_(std::move(key_path)) {}

  // Reads the certificate, or makes the CA when neither its certificate nor its key exists.
  Status Open(const std::string& subject, int days, std::ostream& out) {
    if (fs::exists(fs::symlink_status(cert_path_))) {
      auto c = ReadCert(cert_path_);
      if (!c.ok()) return c.status();
      cert_ = std::move(c.value());
      out << "kept     " << cert_path_ << "\n";
      return Status::OK();
    }
    if (fs::exists(fs::symlink_status(key_path_)))
      return Status::FailedPrecondition(key_path_ + ": a CA key without its certificate " + cert_path_ +
                                        ": restore the certificate (or remove the key to make a new CA)");
    auto k = NewKey();
    if (!k.ok()) return k.status();
    auto c = Issue(k.value().get(), subject, nullptr, k.value().get(), days, Use::kCa);
    if (!c.ok()) return c.status();
    // The CA folder is made only here, for a new CA: an empty one would be where a restored
    // offline folder is then moved into (`mv OFFLINE keys/ca` nesting it as keys/ca/OFFLINE).
    if (Status s = CreatePrivateDirectories(fs::path(key_path_).parent_path().string()); !s.ok()) return s;
    if (Status s = WritePrivateFile(key_path_, KeyPem(k.value().get()), CreateMode::kNew); !s.ok()) return s;
    if (Status s = WritePrivateFile(cert_path_, CertPem(c.value().get()), CreateMode::kNew); !s.ok()) return s;
    key_ = std::move(k.value());
    cert_ = std::move(c.value());
    out << "made     " << name_ << ": " << cert_path_ << ", " << key_path_ << "\n";
    return Status::OK();
  }

  // The key, read when first needed: a CA kept offline is only needed to issue or sign.
  StatusOr<EVP_PKEY*> key(const std::string& why) {
    if (key_) return key_.get();
    if (!fs::exists(fs::symlink_status(key_path_))) return MissingKey(why);
    auto k = ReadKey(key_path_);
    if (!k.ok()) return k.status();
    key_ = std::move(k.value());
    return key_.get();
  }
  X509* cert() const { return cert_.get(); }

 private:
  // The key is needed and not at key_path_: say where it was looked for, how to point elsewhere,
  // and where it is when an offline folder was moved into an existing CA folder.
  Status MissingKey(const std::string& why) const {
    const fs::path ca_dir = fs::path(key_path_).parent_path(), file = fs::path(key_path_).filename();
    std::string message = key_path_ + ": the " + name_ + "'s key is not here, and it is needed to " + why +
                          ". Bring the CA folder back for this step (mv /path/to/offline/ca " + ca_dir.string() +
                          ") or name it with --ca DIR";
    std::error_code ec;
    for (fs::directory_iterator it(ca_dir, ec), end; !ec && it != end; it.increment(ec))
      if (it->is_directory(ec) && fs::exists(fs::symlink_status(it->path() / file, ec)))
        message += "; it is at " + (it->path() / file).string() + ": the folder was moved inside " + ca_dir.string() +
                   " (move its files up, or use --ca " + it->path().string() + ")";
    return Status::FailedPrecondition(message);
  }

  std::string name_, cert_path_, key_path_;
  Cert cert_;
  Key key_;
};

// Writes `text` signed into `signed_path` (and `text` into `xml_path`) unless the XML is
// already what is there.
Status SignDocument(const std::string& xml_path, const std::string& signed_path, const std::string& text, Authority& ca,
                    std::ostream& out) {
  if (fs::exists(fs::symlink_status(signed_path)) && fs::exists(fs::symlink_status(xml_path)) && ReadText(xml_path) == text) {
    out << "kept     " << signed_path << "\n";
    return Status::OK();
  }
  auto key = ca.key("sign " + signed_path);
  if (!key.ok()) return key.status();
  auto signed_text = SmimeSigned(text, ca.cert(), key.value());
  if (!signed_text.ok()) return signed_text.status().WithContext(signed_path);
  // The signed document first: the XML is what a rerun compares, so a crash between the two
  // writes leaves an XML that differs and the next init signs again (never a stale .p7s kept).
  if (Status s = WritePrivateFile(signed_path, signed_text.value(), CreateMode::kReplace); !s.ok()) return s;
  if (Status s = WritePrivateFile(xml_path, text, CreateMode::kReplace); !s.ok()) return s;
  out << "signed   " << signed_path << "\n";
  return Status::OK();
}

// "IP:a,DNS:b" for the hosts (an address is an IP entry, anything else a DNS name).
std::string AltNames(const std::vector<std::string>& hosts) {
  std::string out;
  for (const std::string& h : hosts) {
    unsigned char buf[16];
    const bool ip = inet_pton(AF_INET, h.c_str(), buf) == 1 || inet_pton(AF_INET6, h.c_str(), buf) == 1;
    if (!out.empty()) out += ',';
    out.append(ip ? "IP:" : "DNS:").append(h);
  }
  return out;
}

// The web CA and web/tls.pem (see the header); the hosts a certificate was issued for are kept
// in web/hosts, so a rerun with other hosts reissues it.
Status InitWebCertificate(const Graph& graph, const KeystoreOptions& options, const fs::path& ca_dir, std::ostream& out) {
  const fs::path dir = fs::path(options.dir), web = dir / "web";
  if (Status s = CreatePrivateDirectories(web.string()); !s.ok()) return s;
  Authority web_ca("web CA", (dir / "web_ca.cert.pem").string(), (ca_dir / "web_ca.key.pem").string());
  if (Status s = web_ca.Open("CN=dyad web CA " + graph.name, options.ca_days, out); !s.ok()) return s;
  const std::string alt = AltNames(options.web_hosts), tls_path = (web / "tls.pem").string(),
                    hosts_path = (web / "hosts").string();
  const bool have = fs::exists(fs::symlink_status(tls_path)) && fs::exists(fs::symlink_status(hosts_path));
  const bool renew = options.renew.count("all") > 0 || options.renew.count("web") > 0;
  if (have && !renew && ReadText(hosts_path) == alt + "\n") {
    out << "kept     web: " << tls_path << "\n";
    return Status::OK();
  }
  auto ca_key = web_ca.key("issue the web certificate");
  if (!ca_key.ok()) return ca_key.status();
  auto k = NewKey();
  if (!k.ok()) return k.status();
  auto c = Issue(k.value().get(), "CN=" + options.web_hosts.front(), web_ca.cert(), ca_key.value(), options.identity_days,
                 Use::kTlsServer, alt);
  if (!c.ok()) return c.status();
  const CreateMode mode = have ? CreateMode::kReplace : CreateMode::kNew;
  if (Status s = WritePrivateFile(tls_path, KeyPem(k.value().get()) + CertPem(c.value().get()), mode); !s.ok()) return s;
  if (Status s = WritePrivateFile((web / "cert.pem").string(), CertPem(c.value().get()), CreateMode::kReplace); !s.ok()) return s;
  if (Status s = WritePrivateFile(hosts_path, alt + "\n", CreateMode::kReplace); !s.ok()) return s;
  out << (have ? "renewed  " : "issued   ") << "web (" << alt << "): " << tls_path << "\n";
  return Status::OK();
}

// The validity of `cert` as the permissions grant's dates.
std::pair<std::string, std::string> Validity(X509* cert) {
  std::tm tm{};
  ASN1_TIME_to_tm(X509_get0_notBefore(cert), &tm);
  const time_t not_before = timegm(&tm);
  ASN1_TIME_to_tm(X509_get0_notAfter(cert), &tm);
  return {Utc(not_before), Utc(timegm(&tm))};
}

// Removes what a crashed init left of `identity`'s staging folders (".<identity>.new-*").
void RemoveStaleStaging(const fs::path& identities, const std::string& identity) {
  std::error_code ec;
  const std::string prefix = "." + identity + ".new-";
  for (fs::directory_iterator it(identities, ec), end; !ec && it != end; it.increment(ec))
    if (it->path().filename().string().rfind(prefix, 0) == 0) fs::remove_all(it->path(), ec);
}

// A new key, certificate and signed permissions for `identity`, made whole in a staging folder
// and then put in place in one step: renamed when the identity is new, exchanged with the old
// folder (renameat2 RENAME_EXCHANGE) on renewal. A failure or a crash at any point leaves the
// identity as it was (nothing, or the old pair): never a key without its certificate, never a
// renewed key beside the old certificate.
Status IssueIdentity(const Graph& graph, const std::map<std::string, TopicAccess>& access, const KeystoreOptions& options,
                     const std::string& identity, const std::string& subject, Authority& identity_ca, Authority& permissions_ca,
                     std::ostream& out) {
  const fs::path identities = fs::path(options.dir) / "identities", own = identities / identity;
  auto ca_key = identity_ca.key("issue identity " + identity);
  if (!ca_key.ok()) return ca_key.status();
  auto k = NewKey();
  if (!k.ok()) return k.status();
  auto c = Issue(k.value().get(), subject, identity_ca.cert(), ca_key.value(), options.identity_days, Use::kIdentity);
  if (!c.ok()) return c.status();
  RemoveStaleStaging(identities, identity);
  const fs::path staging = identities / ("." + identity + ".new-" + std::to_string(getpid()));
  auto made = [&]() -> Status {
    if (Status s = CreatePrivateDirectories(staging.string()); !s.ok()) return s;
    if (Status s = WritePrivateFile((staging / "key.pem").string(), KeyPem(k.value().get()), CreateMode::kNew); !s.ok()) return s;
    if (Status s = WritePrivateFile((staging / "cert.pem").string(), CertPem(c.value().get()), CreateMode::kNew); !s.ok()) return s;
    const auto [from, to] = Validity(c.value().get());
    std::ostringstream quiet;  // the staging folder's name is not what the user should read
    return SignDocument((staging / "permissions.xml").string(), (staging / "permissions.p7s").string(),
                        PermissionsXml(graph, identity, subject, access, from, to), permissions_ca, quiet);
  }();
  std::error_code ec;
  if (!made.ok()) {
    fs::remove_all(staging, ec);
    return made;
  }
  const bool existed = fs::exists(fs::symlink_status(own, ec));
  if (::renameat2(AT_FDCWD, staging.c_str(), AT_FDCWD, own.c_str(), existed ? RENAME_EXCHANGE : RENAME_NOREPLACE) != 0) {
    const int err = errno;
    fs::remove_all(staging, ec);
    return Status::IOError(own.string() + ": cannot put the new identity in place: " + std::strerror(err));
  }
  if (existed) fs::remove_all(staging, ec);  // now the old identity
  if (Status s = SyncDirectory(identities.string()); !s.ok()) return s;
  out << (existed ? "renewed  " : "issued   ") << identity << ": " << (own / "cert.pem").string() << "\n";
  return Status::OK();
}

// The keystore's names key (dyad/wire_names.hpp): made once, 0600, then kept.
StatusOr<std::string> NamesKey(const fs::path& dir, std::ostream& out) {
  const std::string path = (dir / kNamesKeyFile).string();
  if (!fs::exists(fs::symlink_status(path))) {
    auto text = NewNamesKeyText();
    if (!text.ok()) return text.status();
    if (Status s = WritePrivateFile(path, text.value(), CreateMode::kNew); !s.ok()) return s;
    out << "made     " << path << " (the names on the wire)\n";
  }
  return ReadNamesKey(path);
}

// The graph the keystore is for (dyad/keystore_graph.hpp): written once, when the keystore has
// none (a new one, or one made before dyad recorded it); CheckKeystoreGraph refused another's.
Status RecordGraph(const Graph& graph, const fs::path& dir, std::ostream& out) {
  auto owner = ReadKeystoreGraph(dir.string());
  if (!owner.ok()) return owner.status();
  if (!owner.value().empty()) return Status::OK();
  const std::string path = (dir / kKeystoreGraphFile).string();
  if (Status s = WritePrivateFile(path, graph.name + "\n", CreateMode::kNew); !s.ok()) return s;
  out << "made     " << path << " (this keystore is graph '" << graph.name << "''s: a keystore serves one graph)\n";
  return Status::OK();
}

std::string CommonName(X509* cert) {
  char cn[256] = {0};
  if (cert == nullptr || X509_NAME_get_text_by_NID(X509_get_subject_name(cert), NID_commonName, cn, sizeof cn) < 0) return "";
  return cn;
}

// A CA kept from a keystore made before names were opaque: its subject names the graph, and every
// handshake carries it (in each certificate it issued). Say so; only a new keystore changes it.
void NoteNamedCa(const Graph& graph, const Authority& ca, const std::string& path, std::ostream& out) {
  const std::string cn = CommonName(ca.cert());
  // The exact subjects such a keystore gave its CAs ("dyad identity CA" alone is today's).
  if (cn == "dyad identity CA " + graph.name || cn == "dyad permissions CA " + graph.name)
    out << "note     " << path << ": its subject (CN=" << cn
        << ") names the graph, and every handshake shows it to anyone listening: a new keystore hides it\n";
}

// Issues or renews `identity` when asked, when it is missing, or when its certificate's subject
// is not its opaque one (a keystore made before names were opaque); else keeps it and signs its
// permissions again when their text changed.
Status InitIdentity(const Graph& graph, const std::map<std::string, TopicAccess>& access, const KeystoreOptions& options,
                    const std::string& identity, const std::string& names_key, Authority& identity_ca, Authority& permissions_ca,
                    std::ostream& out) {
  const fs::path own = fs::path(options.dir) / "identities" / identity;
  const std::string cert_path = (own / "cert.pem").string(), key_path = (own / "key.pem").string();
  const std::string readable = IdentitySubject(graph, identity);
  const std::string opaque = WireSubject(names_key, readable.substr(readable.find('=') + 1));
  if (opaque.empty()) return Status::Internal("cannot make the opaque subject of " + identity + " (libcrypto failed)");
  const std::string subject = "CN=" + opaque;
  const bool renew = options.renew.count("all") > 0 || options.renew.count(identity) > 0;
  const bool have = fs::exists(fs::symlink_status(cert_path)) && fs::exists(fs::symlink_status(key_path));
  if (!have || renew) return IssueIdentity(graph, access, options, identity, subject, identity_ca, permissions_ca, out);
  auto cert = ReadCert(cert_path);
  if (!cert.ok()) return cert.status();
  if ("CN=" + CommonName(cert.value().get()) != subject) {
    out << "renewing " << identity << ": its subject is not this keystore's opaque one (CN=" << CommonName(cert.value().get())
        << "; a keystore made before names were opaque, or a new names.key)\n";
    return IssueIdentity(graph, access, options, identity, subject, identity_ca, permissions_ca, out);
  }
  out << "kept     " << identity << ": " << cert_path << "\n";
  // The grant is valid as long as the certificate.
  const auto [from, to] = Validity(cert.value().get());
  const std::string xml = PermissionsXml(graph, identity, subject, access, from, to);
  return SignDocument((own / "permissions.xml").string(), (own / "permissions.p7s").string(), xml, permissions_ca, out);
}

}  // namespace

Status InitKeystore(const Graph& graph, const std::map<std::string, TopicAccess>& access, const KeystoreOptions& options,
                    std::ostream& out) {
  const fs::path dir(options.dir), identities = dir / "identities";
  const fs::path ca_dir = options.ca_dir.empty() ? dir / "ca" : fs::path(options.ca_dir);
  // One graph per keystore: another graph's is refused before anything is made or renewed.
  if (Status s = CheckKeystoreGraph(graph, options.dir); !s.ok()) return s;
  for (const fs::path& d : {dir, identities})
    if (Status s = CreatePrivateDirectories(d.string()); !s.ok()) return s;
  if (Status s = RecordGraph(graph, dir, out); !s.ok()) return s;
  Authority identity_ca("identity CA", (dir / "identity_ca.cert.pem").string(), (ca_dir / "identity_ca.key.pem").string());
  Authority permissions_ca("permissions CA", (dir / "permissions_ca.cert.pem").string(),
                           (ca_dir / "permissions_ca.key.pem").string());
  // The CAs' subjects name nothing: every handshake shows them (dyad/wire_names.hpp).
  if (Status s = identity_ca.Open("CN=dyad identity CA", options.ca_days, out); !s.ok()) return s;
  if (Status s = permissions_ca.Open("CN=dyad permissions CA", options.ca_days, out); !s.ok()) return s;
  NoteNamedCa(graph, identity_ca, (dir / "identity_ca.cert.pem").string(), out);
  NoteNamedCa(graph, permissions_ca, (dir / "permissions_ca.cert.pem").string(), out);
  if (Status s = SignDocument((dir / "governance.xml").string(), (dir / "governance.p7s").string(), GovernanceXml(),
                              permissions_ca, out);
      !s.ok())
    return s;
  auto names_key = NamesKey(dir, out);
  if (!names_key.ok()) return names_key.status();
  for (const std::string& identity : GraphIdentities(graph))
    if (Status s = InitIdentity(graph, access, options, identity, names_key.value(), identity_ca, permissions_ca, out); !s.ok())
      return s;
  if (!options.web_hosts.empty()) return InitWebCertificate(graph, options, ca_dir, out);
  return Status::OK();
}

}  // namespace dyad::cli
