// `dyad security init`: the keystore it makes is read back by an independent reader (the openssl
// command), files are private, a rerun keeps keys, --renew rotates one identity, CA keys can be
// kept offline; `dyad validate` refuses a keystore that is incomplete, leaky or expired.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include <dyad/security.hpp>
#include <dyad/wire_names.hpp>

#include "dyad/testing/child_process.hpp"
#include "dyad/testing/cli.hpp"
#include "introspection_commands.hpp"
#include "runtime_commands.hpp"
#include "security_commands.hpp"

namespace dyad::cli {
namespace {

namespace fs = std::filesystem;
using dyad::testing::ReadFile;

unsigned Mode(const fs::path& p) {
  struct stat st {};
  lstat(p.c_str(), &st);
  return st.st_mode & 07777;
}

class KeystoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("dyad_keystore_" + std::to_string(getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    keys_ = dir_ / "keys";
    graph_ = WriteGraph("");
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  // Two processes: pub writes ca and cb, rec records ca (the recorder subscribes in Configure).
  fs::path WriteGraph(const std::string& extra, const std::string& name = "g.yaml") {
    std::ofstream(dir_ / name) << "graph: sec\nprocesses:\n  pub: {}\n  rec: {}\n" << extra
                               << "components:\n"
                                  "  a: {type: counter_source, rate_hz: 10, process: pub, outputs: {out: ca}}\n"
                                  "  b: {type: counter_source, rate_hz: 10, process: pub, outputs: {out: cb}}\n"
                                  "  r: {type: recorder, rate_hz: 1, process: rec, params: {file: "
                               << (dir_ / "out.mcap").string() << ", topics: [ca]}}\n";
    return dir_ / name;
  }
  dyad::testing::CliRun Init(std::vector<std::string> extra = {}, const fs::path& graph = {}) {
    std::vector<std::string> args = {"security", "init", keys_.string(), "--graph", (graph.empty() ? graph_ : graph).string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return dyad::testing::RunCommand(AddSecurityCommands, args);
  }
  // The openssl command's stdout; *code its exit status.
  // (Line ends as LF: S/MIME's text mode carries the signed text with CRLF.)
  std::string OpenSsl(const std::vector<std::string>& args, int* code) {
    std::vector<std::string> argv = {"/usr/bin/openssl"};
    argv.insert(argv.end(), args.begin(), args.end());
    dyad::testing::ChildProcess c(argv, dir_, "openssl" + std::to_string(runs_++));
    *code = c.Wait(60);
    std::string out = c.out() + c.err();
    std::erase(out, '\r');
    return out;
  }
  fs::path Identity(const std::string& id, const std::string& file) { return keys_ / "identities" / id / file; }
  // The opaque subject "CN=dyad~..." of the readable `name` (dyad/wire_names.hpp), with the
  // keystore's names key.
  std::string Subject(const std::string& name) {
    auto key = ReadNamesKey((keys_ / kNamesKeyFile).string());
    EXPECT_TRUE(key.ok()) << key.status().message();
    return "CN=" + WireSubject(key.ok() ? key.value() : "", name);
  }

  fs::path dir_, keys_, graph_;
  int runs_ = 0;
};

// The text between <tag> and </tag> (the first one), for reading a permissions grant.
std::string Section(const std::string& xml, const std::string& tag) {
  const size_t a = xml.find("<" + tag + ">"), b = xml.find("</" + tag + ">");
  return a == std::string::npos || b == std::string::npos ? "" : xml.substr(a, b - a);
}

TEST_F(KeystoreTest, OpenSslVerifiesTheIdentitiesAndTheSignedDocuments) {
  auto r = Init();
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* id : {"process.pub", "process.rec", "host.local"}) {
    int code = -1;
    const std::string verified = OpenSsl({"verify", "-CAfile", (keys_ / "identity_ca.cert.pem").string(),
                                          Identity(id, "cert.pem").string()},
                                         &code);
    EXPECT_EQ(code, 0) << id << ": " << verified;
    EXPECT_NE(verified.find(": OK"), std::string::npos) << verified;
    // Not issued by the permissions CA: the two CAs are distinct.
    OpenSsl({"verify", "-CAfile", (keys_ / "permissions_ca.cert.pem").string(), Identity(id, "cert.pem").string()}, &code);
    EXPECT_NE(code, 0) << id;
    const std::string subject = OpenSsl({"x509", "-noout", "-subject", "-nameopt", "RFC2253", "-in", Identity(id, "cert.pem").string()}, &code);
    // Opaque: every handshake shows it (dyad/wire_names.hpp).
    const std::string readable = id[0] == 'h' ? "dyad/sec/host/local" : "dyad/sec/" + std::string(id).substr(8);
    EXPECT_NE(subject.find("subject=" + Subject(readable) + "\n"), std::string::npos) << subject;
    EXPECT_EQ(subject.find("sec"), std::string::npos) << subject;
    const std::string issuer = OpenSsl({"x509", "-noout", "-issuer", "-in", Identity(id, "cert.pem").string()}, &code);
    EXPECT_EQ(issuer.find("sec"), std::string::npos) << "the CA's subject names the graph: " << issuer;
    // The signed permissions verify against the permissions CA and carry exactly the XML.
    const std::string content = OpenSsl({"smime", "-verify", "-text", "-in", Identity(id, "permissions.p7s").string(), "-CAfile",
                                         (keys_ / "permissions_ca.cert.pem").string()},
                                        &code);
    EXPECT_EQ(code, 0) << content;
    EXPECT_NE(content.find(ReadFile(Identity(id, "permissions.xml"))), std::string::npos) << content;
  }
  int code = -1;
  const std::string gov = OpenSsl({"smime", "-verify", "-text", "-in", (keys_ / "governance.p7s").string(), "-CAfile",
                                   (keys_ / "permissions_ca.cert.pem").string()},
                                  &code);
  EXPECT_EQ(code, 0) << gov;
  EXPECT_NE(gov.find("<allow_unauthenticated_participants>false</allow_unauthenticated_participants>"), std::string::npos);
  EXPECT_NE(gov.find("<data_protection_kind>ENCRYPT</data_protection_kind>"), std::string::npos);

  // Private: folders 0700, every file 0600.
  for (const auto& e : fs::recursive_directory_iterator(keys_))
    EXPECT_EQ(Mode(e.path()), e.is_directory() ? 0700u : 0600u) << e.path();
  EXPECT_EQ(Mode(keys_), 0700u);
}

// --web-host: a TLS server certificate for exactly those hosts, issued by a web CA of its own
// (what a browser is asked to trust signs nothing else), private, kept on a rerun with the same
// hosts and reissued with others.
TEST_F(KeystoreTest, WebHostsGetATlsServerCertificateFromTheWebCa) {
  auto r = Init({"--web-host", "127.0.0.1", "--web-host", "lab-pc.local"});
  ASSERT_EQ(r.code, 0) << r.err;
  const fs::path tls = keys_ / "web" / "tls.pem", cert = keys_ / "web" / "cert.pem", ca = keys_ / "web_ca.cert.pem";
  EXPECT_EQ(Mode(tls), 0600u);
  EXPECT_EQ(Mode(keys_ / "ca" / "web_ca.key.pem"), 0600u);
  int code = 0;
  const std::string verify = OpenSsl({"verify", "-purpose", "sslserver", "-CAfile", ca.string(), cert.string()}, &code);
  EXPECT_EQ(code, 0) << verify;
  OpenSsl({"verify", "-CAfile", (keys_ / "identity_ca.cert.pem").string(), cert.string()}, &code);
  EXPECT_NE(code, 0) << "the identity CA must not vouch for the web certificate";
  const std::string ext = OpenSsl({"x509", "-in", cert.string(), "-noout", "-ext", "subjectAltName,extendedKeyUsage"}, &code);
  EXPECT_NE(ext.find("IP Address:127.0.0.1, DNS:lab-pc.local"), std::string::npos) << ext;
  EXPECT_NE(ext.find("TLS Web Server Authentication"), std::string::npos) << ext;
  // tls.pem holds the key that goes with the certificate.
  const std::string key_pub = OpenSsl({"pkey", "-in", tls.string(), "-pubout"}, &code);
  const std::string cert_pub = OpenSsl({"x509", "-in", tls.string(), "-noout", "-pubkey"}, &code);
  EXPECT_EQ(key_pub, cert_pub);

  const std::string before = ReadFile(tls);
  auto same = Init({"--web-host", "127.0.0.1", "--web-host", "lab-pc.local"});
  ASSERT_EQ(same.code, 0) << same.err;
  EXPECT_EQ(ReadFile(tls), before) << same.out;
  auto other = Init({"--web-host", "10.0.0.7"});
  ASSERT_EQ(other.code, 0) << other.err;
  EXPECT_NE(other.out.find("renewed  web (IP:10.0.0.7)"), std::string::npos) << other.out;
  EXPECT_NE(OpenSsl({"x509", "-in", cert.string(), "-noout", "-ext", "subjectAltName"}, &code).find("IP Address:10.0.0.7"),
            std::string::npos);
}

TEST_F(KeystoreTest, PermissionsGrantWhatEachProcessWritesAndReads) {
  ASSERT_EQ(Init().code, 0);
  const std::string pub = ReadFile(Identity("process.pub", "permissions.xml"));
  const std::string rec = ReadFile(Identity("process.rec", "permissions.xml"));
  const std::string host = ReadFile(Identity("host.local", "permissions.xml"));
  EXPECT_NE(pub.find("<subject_name>" + Subject("dyad/sec/pub") + "</subject_name>"), std::string::npos) << pub;
  // The document travels in clear in every handshake: it names neither the graph nor the process.
  for (const std::string& doc : {pub, rec, host}) {
    EXPECT_EQ(doc.find("dyad/sec/"), std::string::npos) << doc;
    EXPECT_EQ(doc.find("process."), std::string::npos) << doc;
    EXPECT_EQ(doc.find("host.local"), std::string::npos) << doc;
  }
  EXPECT_EQ(ReadFile(keys_ / "governance.xml").find("dyad/sec/"), std::string::npos);
  EXPECT_NE(Section(pub, "publish").find("<topic>ca</topic>"), std::string::npos) << pub;
  EXPECT_NE(Section(pub, "publish").find("<topic>cb</topic>"), std::string::npos) << pub;
  EXPECT_EQ(Section(pub, "subscribe").find("<topic>ca</topic>"), std::string::npos) << pub;
  EXPECT_NE(Section(rec, "subscribe").find("<topic>ca</topic>"), std::string::npos) << rec;
  EXPECT_EQ(Section(rec, "subscribe").find("<topic>cb</topic>"), std::string::npos) << "the recorder records ca only:\n" << rec;
  EXPECT_EQ(Section(rec, "publish").find("<topic>ca</topic>"), std::string::npos) << rec;
  EXPECT_NE(Section(rec, "publish").find("<topic>dyad/stats</topic>"), std::string::npos) << rec;
  EXPECT_NE(pub.find("<partition>dyad/*</partition>"), std::string::npos) << pub;
  EXPECT_NE(pub.find("<default>DENY</default>"), std::string::npos);
  EXPECT_NE(Section(host, "publish").find("<topic>dyad/launchers</topic>"), std::string::npos) << host;
  EXPECT_NE(Section(host, "subscribe").find("<topic>*</topic>"), std::string::npos) << host;
}

TEST_F(KeystoreTest, TheGuestIdentityIsGrantedExactlyTheGraphsGuestsSection) {
  const fs::path g = WriteGraph("security:\n  keystore: keys\n  guests: {publish: [cb, 'robot/*'], subscribe: [ca]}\n", "guests.yaml");
  auto init = Init({}, g);
  ASSERT_EQ(init.code, 0) << init.err;
  EXPECT_NE(init.out.find("issued   guest"), std::string::npos) << init.out;
  const std::string guest = ReadFile(Identity("guest", "permissions.xml"));
  EXPECT_NE(guest.find("<subject_name>" + Subject("dyad/sec/guest/tools") + "</subject_name>"), std::string::npos) << guest;
  const std::string publish = Section(guest, "publish"), subscribe = Section(guest, "subscribe");
  EXPECT_NE(publish.find("<topic>cb</topic>"), std::string::npos) << guest;
  EXPECT_NE(publish.find("<topic>robot/*</topic>"), std::string::npos) << guest;
  EXPECT_EQ(publish.find("<topic>ca</topic>"), std::string::npos) << guest;
  EXPECT_EQ(publish.find("dyad/launchers"), std::string::npos) << "a guest is no launcher:\n" << guest;
  EXPECT_EQ(publish.find("dyad/param_requests"), std::string::npos) << guest;
  EXPECT_NE(subscribe.find("<topic>ca</topic>"), std::string::npos) << guest;
  EXPECT_EQ(subscribe.find("<topic>*</topic>"), std::string::npos) << "a guest does not read everything:\n" << guest;
  int code = -1;
  const std::string subject =
      OpenSsl({"x509", "-noout", "-subject", "-in", Identity("guest", "cert.pem").string()}, &code);
  EXPECT_EQ(code, 0);
  EXPECT_NE(subject.find(Subject("dyad/sec/guest/tools").substr(3)), std::string::npos) << subject;
  // No section, no guest identity.
  ASSERT_EQ(Init().code, 0);
  EXPECT_TRUE(fs::exists(Identity("guest", "cert.pem")));  // kept from before, unused by this graph
  EXPECT_TRUE(TopicGranted({"cb", "robot/*"}, "robot/command"));
  EXPECT_FALSE(TopicGranted({"cb", "robot/*"}, "ca"));
  // A section that is not a list is refused at its line.
  const fs::path bad = WriteGraph("security:\n  keystore: keys\n  guests: {publish: cb, read: [ca]}\n", "bad.yaml");
  auto refused = Init({}, bad);
  EXPECT_EQ(refused.code, 2);
  EXPECT_NE(refused.err.find("bad.yaml:7:21: security.guests.publish: must be a list of topics"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("security.guests"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("read"), std::string::npos) << "the unknown key is named:\n" << refused.err;
  const fs::path empty = WriteGraph("security:\n  keystore: keys\n  guests: {}\n", "empty.yaml");
  auto nothing = Init({}, empty);
  EXPECT_EQ(nothing.code, 2);
  EXPECT_NE(nothing.err.find("empty.yaml:7:11: security.guests: grants nothing"), std::string::npos) << nothing.err;
}

TEST_F(KeystoreTest, ARerunKeepsKeysAndRenewReplacesOnlyTheNamedIdentity) {
  ASSERT_EQ(Init().code, 0);
  const std::string pub_key = ReadFile(Identity("process.pub", "key.pem"));
  const std::string rec_key = ReadFile(Identity("process.rec", "key.pem"));
  const std::string ca_cert = ReadFile(keys_ / "identity_ca.cert.pem");
  auto again = Init();
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_EQ(again.out.find("issued"), std::string::npos) << again.out;
  EXPECT_EQ(again.out.find("signed"), std::string::npos) << "nothing changed, nothing re-signed:\n" << again.out;
  EXPECT_EQ(ReadFile(Identity("process.pub", "key.pem")), pub_key);

  auto renew = Init({"--renew", "process.pub"});
  ASSERT_EQ(renew.code, 0) << renew.err;
  EXPECT_NE(renew.out.find("renewed  process.pub"), std::string::npos) << renew.out;
  EXPECT_NE(ReadFile(Identity("process.pub", "key.pem")), pub_key);
  EXPECT_EQ(ReadFile(Identity("process.rec", "key.pem")), rec_key);
  EXPECT_EQ(ReadFile(keys_ / "identity_ca.cert.pem"), ca_cert);
  EXPECT_EQ(Mode(Identity("process.pub", "key.pem")), 0600u);
  int code = -1;
  OpenSsl({"verify", "-CAfile", (keys_ / "identity_ca.cert.pem").string(), Identity("process.pub", "cert.pem").string()}, &code);
  EXPECT_EQ(code, 0);

  auto bad = Init({"--renew", "process.nobody"});
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("--renew process.nobody: not an identity of graph 'sec' (process.pub, process.rec, host.local)"),
            std::string::npos)
      << bad.err;
}

// A graph called "dyad" is not named by the CAs' subject "dyad identity CA" (no note); a new
// names.key makes every subject another, so a rerun reissues each identity and says why.
TEST_F(KeystoreTest, ANewNamesKeyReissuesEveryIdentityAndAShortGraphNameIsNoCaSubject) {
  std::string text = ReadFile(graph_);
  text.replace(text.find("graph: sec"), 10, "graph: dyad");
  std::ofstream(dir_ / "short.yaml") << text;
  auto first = Init({}, dir_ / "short.yaml");
  ASSERT_EQ(first.code, 0) << first.err;
  EXPECT_EQ(first.out.find("note"), std::string::npos) << first.out;
  fs::remove(keys_ / kNamesKeyFile);
  auto again = Init({}, dir_ / "short.yaml");
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_NE(again.out.find("renewing process.pub: its subject is not this keystore's opaque one"), std::string::npos)
      << again.out;
  EXPECT_EQ(again.out.find("note"), std::string::npos) << again.out;
}

TEST_F(KeystoreTest, CaKeysKeptOfflineAreNeededOnlyToIssue) {
  ASSERT_EQ(Init().code, 0);
  fs::rename(keys_ / "ca", dir_ / "offline_ca");
  auto kept = Init();
  EXPECT_EQ(kept.code, 0) << "nothing to issue or sign: the CA keys are not needed\n" << kept.err;
  // A graph that gained a process needs the identity CA's key.
  const fs::path bigger = WriteGraph("", "g2.yaml");
  std::string text = ReadFile(bigger);
  text.replace(text.find("rec: {}"), 7, "rec: {}\n  extra: {}");
  text += "  x: {type: counter_source, rate_hz: 10, process: extra, outputs: {out: cc}}\n";
  std::ofstream(bigger) << text;
  auto needs = Init({}, bigger);
  EXPECT_EQ(needs.code, 1);
  EXPECT_NE(needs.err.find((keys_ / "ca" / "identity_ca.key.pem").string() + ": the identity CA's key is not here"), std::string::npos)
      << needs.err;
  fs::rename(dir_ / "offline_ca", keys_ / "ca");
  auto issued = Init({}, bigger);
  ASSERT_EQ(issued.code, 0) << issued.err;
  EXPECT_NE(issued.out.find("issued   process.extra"), std::string::npos) << issued.out;
}

TEST_F(KeystoreTest, AFailedIssueOrRenewalLeavesEachIdentityAsItWas) {
  ASSERT_EQ(Init().code, 0);
  const std::string key = ReadFile(Identity("process.pub", "key.pem")), cert = ReadFile(Identity("process.pub", "cert.pem"));
  // The identity CA's key is here, the permissions CA's is not: a renewal can make the new pair
  // but cannot sign its permissions, so it fails, and the old pair must still be the pair.
  fs::rename(keys_ / "ca" / "permissions_ca.key.pem", dir_ / "permissions_ca.key.pem");
  auto renew = Init({"--renew", "process.pub"});
  EXPECT_EQ(renew.code, 1);
  EXPECT_NE(renew.err.find("permissions_ca.key.pem: the permissions CA's key is not here"), std::string::npos) << renew.err;
  EXPECT_EQ(ReadFile(Identity("process.pub", "key.pem")), key);
  EXPECT_EQ(ReadFile(Identity("process.pub", "cert.pem")), cert);
  // A new process fails the same way: no folder of it is left, empty or half made.
  const fs::path bigger = WriteGraph("", "g2.yaml");
  std::string text = ReadFile(bigger);
  text.replace(text.find("rec: {}"), 7, "rec: {}\n  extra: {}");
  text += "  x: {type: counter_source, rate_hz: 10, process: extra, outputs: {out: cc}}\n";
  std::ofstream(bigger) << text;
  EXPECT_EQ(Init({}, bigger).code, 1);
  EXPECT_FALSE(fs::exists(fs::symlink_status(Identity("process.extra", ""))));
  for (const auto& e : fs::directory_iterator(keys_ / "identities"))
    EXPECT_EQ(e.path().filename().string().find(".new-"), std::string::npos) << e.path();
  fs::rename(dir_ / "permissions_ca.key.pem", keys_ / "ca" / "permissions_ca.key.pem");
  auto issued = Init({"--renew", "process.pub"}, bigger);
  ASSERT_EQ(issued.code, 0) << issued.err;
  EXPECT_NE(issued.out.find("renewed  process.pub"), std::string::npos) << issued.out;
  EXPECT_NE(issued.out.find("issued   process.extra"), std::string::npos) << issued.out;
  EXPECT_NE(ReadFile(Identity("process.pub", "key.pem")), key);
  EXPECT_EQ(Mode(keys_ / "identities" / "process.extra"), 0700u);
  EXPECT_EQ(Mode(Identity("process.extra", "key.pem")), 0600u);
}

TEST_F(KeystoreTest, ValidateRefusesAKeyThatIsNotTheKeyOfItsCertificate) {
  const fs::path secured = WriteGraph("security: {keystore: keys}\n", "secured.yaml");
  ASSERT_EQ(Init().code, 0);
  // What a renewal cut between its two writes left: another key beside the certificate. Each
  // file passes the file checks (present, regular, 0600, a valid certificate).
  fs::copy_file(Identity("process.rec", "key.pem"), Identity("process.pub", "key.pem"), fs::copy_options::overwrite_existing);
  auto v = dyad::testing::RunCommand(AddRuntimeCommands, {"validate", secured.string()});
  EXPECT_EQ(v.code, 2);
  EXPECT_NE(v.err.find("identity 'process.pub': " + Identity("process.pub", "key.pem").string() + ": not the key of " +
                       Identity("process.pub", "cert.pem").string()),
            std::string::npos)
      << v.err;
}

TEST_F(KeystoreTest, ValidateRefusesAKeystoreThatIsIncompleteLeakyOrExpired) {
  const fs::path secured = WriteGraph("security: {keystore: keys}\n", "secured.yaml");
  auto validate = [&] { return dyad::testing::RunCommand(AddRuntimeCommands, {"validate", secured.string()}); };
  auto missing = validate();
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("secured.yaml:5:22: security.keystore: " + keys_.string() + ": no such folder"), std::string::npos)
      << missing.err;
  ASSERT_EQ(Init().code, 0);
  auto ok = validate();
  EXPECT_EQ(ok.code, 0) << ok.err;

  fs::permissions(Identity("process.rec", "key.pem"), fs::perms(0644));
  auto leaky = validate();
  EXPECT_EQ(leaky.code, 2);
  EXPECT_NE(leaky.err.find("identity 'process.rec': " + Identity("process.rec", "key.pem").string() +
                           ": a private key readable by others (mode 0644; chmod 600 it)"),
            std::string::npos)
      << leaky.err;
  fs::permissions(Identity("process.rec", "key.pem"), fs::perms(0600));

  fs::rename(Identity("process.pub", "key.pem"), dir_ / "elsewhere.pem");
  fs::create_symlink(dir_ / "elsewhere.pem", Identity("process.pub", "key.pem"));
  auto linked = validate();
  EXPECT_NE(linked.err.find(Identity("process.pub", "key.pem").string() + ": a symbolic link"), std::string::npos) << linked.err;
  fs::remove(Identity("process.pub", "key.pem"));
  fs::rename(dir_ / "elsewhere.pem", Identity("process.pub", "key.pem"));

  fs::remove(Identity("host.local", "permissions.p7s"));
  auto incomplete = validate();
  EXPECT_NE(incomplete.err.find("identity 'host.local': " + Identity("host.local", "permissions.p7s").string() + ": missing"),
            std::string::npos)
      << incomplete.err;
  ASSERT_EQ(Init().code, 0);  // re-signs what is missing

  // Certificates are checked against the clock: in two years the identities have expired.
  std::vector<Diagnostic> diags;
  const Graph g = LoadGraph(secured.string(), {}, &diags);
  ASSERT_TRUE(diags.empty());
  EXPECT_TRUE(CheckKeystore(g, static_cast<int64_t>(std::time(nullptr))).empty());
  const auto later = CheckKeystore(g, static_cast<int64_t>(std::time(nullptr)) + 2 * 366 * 86400);
  ASSERT_EQ(later.size(), 3u);  // the three identities; the CAs last ten years
  EXPECT_NE(later[0].find("certificate expired"), std::string::npos) << later[0];
  const auto earlier = CheckKeystore(g, static_cast<int64_t>(std::time(nullptr)) - 86400);
  ASSERT_FALSE(earlier.empty());
  EXPECT_NE(earlier[0].find("not valid yet"), std::string::npos) << earlier[0];
}

// One graph per keystore (dyad/keystore_graph.hpp): the permissions' partition is dyad/* and the
// CA admits whatever it issued, so a second graph's identities under the same CA could publish
// into the first. init records the graph; an init for another graph is refused before anything is
// issued or renewed (the old init renewed every identity under the other graph's subjects), and
// validate refuses a graph whose keystore is another's, naming both; a keystore without the
// record (an older dyad's) is refused by validate and adopted by the next init.
TEST_F(KeystoreTest, AKeystoreServesOneGraph) {
  ASSERT_EQ(Init().code, 0);
  const fs::path record = keys_ / "graph.name";
  EXPECT_EQ(ReadFile(record), "sec\n");
  EXPECT_EQ(Mode(record), 0600u);
  const std::string cert = ReadFile(Identity("process.pub", "cert.pem"));
  auto renamed = [&](const std::string& extra, const std::string& name) {
    std::string text = ReadFile(WriteGraph(extra, name));
    text.replace(text.find("graph: sec"), 10, "graph: other");
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  };
  const fs::path other = renamed("", "other.yaml");
  auto refused = Init({}, other);
  EXPECT_EQ(refused.code, 1);
  EXPECT_NE(refused.err.find("dyad security init: keystore " + keys_.string() + " was made for graph 'sec' (" + record.string() +
                             "), not for graph 'other' (" + other.string() + "): a keystore serves one graph"),
            std::string::npos)
      << refused.err;
  EXPECT_NE(refused.err.find("Make a keystore per graph: `dyad security init NEW_DIR --graph " + other.string() + "`"),
            std::string::npos)
      << refused.err;
  EXPECT_EQ(refused.out, "") << "nothing issued, renewed or signed for 'other'";
  EXPECT_EQ(ReadFile(Identity("process.pub", "cert.pem")), cert);
  EXPECT_EQ(ReadFile(record), "sec\n");

  const fs::path mine = WriteGraph("security: {keystore: keys}\n", "secured.yaml");
  const fs::path theirs = renamed("security: {keystore: keys}\n", "secured_other.yaml");
  auto validate = [](const fs::path& g) { return dyad::testing::RunCommand(AddRuntimeCommands, {"validate", g.string()}); };
  auto ok = validate(mine);
  EXPECT_EQ(ok.code, 0) << ok.err;
  auto wrong = validate(theirs);
  EXPECT_EQ(wrong.code, 2);
  EXPECT_NE(
      wrong.err.find("secured_other.yaml:5:22: security.keystore: keystore " + keys_.string() + " was made for graph 'sec' (" +
                     record.string() + "), not for graph 'other' (" + theirs.string() + ")"),
      std::string::npos)
      << wrong.err;

  fs::remove(record);  // a keystore made by an older dyad
  auto unrecorded = validate(mine);
  EXPECT_EQ(unrecorded.code, 2);
  EXPECT_NE(unrecorded.err.find(record.string() + ": missing (the graph this keystore is for"), std::string::npos)
      << unrecorded.err;
  auto adopted = Init();
  ASSERT_EQ(adopted.code, 0) << adopted.err;
  EXPECT_NE(adopted.out.find("made     " + record.string() + " (this keystore is graph 'sec''s"), std::string::npos)
      << adopted.out;
  EXPECT_EQ(ReadFile(Identity("process.pub", "cert.pem")), cert);
  EXPECT_EQ(validate(mine).code, 0);
}

// `dyad status`, `topics`, `param` and `graph --live` read the runtime's own topics, which only a
// host's identity may: on a machine that is none of a secured graph's hosts (this one: its name is
// neither 'lab' nor 'robot') they are refused before joining, saying exactly what to pass (and, in
// a graph with guests, why the guest identity does not do).
TEST_F(KeystoreTest, AWatcherOnAMachineThatIsNoneOfTheHostsIsToldWhatToPass) {
  const std::string placed =
      "graph: sec\nprocesses:\n  pub: {host: lab}\n  rec: {host: robot}\nsecurity: {keystore: keys}\n"
      "components:\n  a: {type: counter_source, rate_hz: 10, process: pub, outputs: {out: ca}}\n"
      "  s: {type: counter_sink, trigger: in, process: rec, inputs: {in: ca}}\n";
  std::ofstream(dir_ / "hosts.yaml") << placed;
  std::ofstream(dir_ / "guests.yaml") << std::string(placed).replace(placed.find("keystore: keys}"), 15,
                                                                     "keystore: keys, guests: {subscribe: [ca]}}");
  ASSERT_EQ(Init({}, dir_ / "guests.yaml").code, 0);
  char machine[256] = {0};
  gethostname(machine, sizeof machine - 1);
  ASSERT_NE(std::string(machine), "lab");
  const std::string told = "this machine ('" + std::string(machine) +
                           "') is none of the graph's hosts: pass the host it is, or whose identity it may use here: --host lab "
                           "or --host robot";
  for (const char* tool : {"status", "topics"}) {
    const std::string graph = (dir_ / "hosts.yaml").string();
    auto r = dyad::testing::RunCommand(AddIntrospectionCommands, {tool, "--graph", graph, "--wait", "0"});
    EXPECT_EQ(r.code, 2) << tool;
    EXPECT_NE(r.err.find(graph + ": " + told + "\n"), std::string::npos) << tool << ": " << r.err;
    auto g =
        dyad::testing::RunCommand(AddIntrospectionCommands, {tool, "--graph", (dir_ / "guests.yaml").string(), "--wait", "0"});
    EXPECT_EQ(g.code, 2) << tool;
    EXPECT_NE(g.err.find(told + " (not as the graph's guest: this tool reads the runtime's own topics"), std::string::npos)
        << tool << ": " << g.err;
  }
  auto live =
      dyad::testing::RunCommand(AddRuntimeCommands, {"graph", "--live", (dir_ / "hosts.yaml").string(), "--host", "nowhere"});
  EXPECT_EQ(live.code, 2);
  EXPECT_NE(live.err.find("this machine ('nowhere') is none of the graph's hosts"), std::string::npos) << live.err;
}

// A graph on two hosts (pub on lab, rec on robot) with guests, for `dyad security export`.
constexpr char kPlacedGraph[] =
    "graph: sec\nprocesses:\n  pub: {host: lab}\n  rec: {host: robot}\n"
    "security: {keystore: keys, guests: {subscribe: [ca]}}\n"
    "components:\n  a: {type: counter_source, rate_hz: 10, process: pub, outputs: {out: ca}}\n"
    "  s: {type: counter_sink, trigger: in, process: rec, inputs: {in: ca}}\n";

// Every file and folder under `dir`, relative, with its mode ("0600 identities/host.lab/key.pem").
std::set<std::string> Listing(const fs::path& dir) {
  std::set<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", Mode(e.path()));
    out.insert(std::string(mode) + " " + fs::relative(e.path(), dir).string());
  }
  return out;
}

// What every subset holds beside its identities: the CA certificates, governance, names.key and
// subset.yaml; never a CA key.
std::set<std::string> SubsetBase(const std::vector<std::string>& identities) {
  std::set<std::string> out = {"0600 identity_ca.cert.pem",
                               "0600 permissions_ca.cert.pem",
                               "0600 governance.xml",
                               "0600 governance.p7s",
                               "0600 names.key",
                               "0600 graph.name",
                               "0600 subset.yaml",
                               "0700 identities"};
  for (const std::string& id : identities) {
    out.insert("0700 identities/" + id);
    for (const char* f : {"cert.pem", "key.pem", "permissions.xml", "permissions.p7s"})
      out.insert("0600 identities/" + id + "/" + f);
  }
  return out;
}

// `dyad security export --host robot`: exactly robot's identities (its host's and its process's),
// the CA certificates and no CA key, each file 0600 and the same bytes as the whole keystore's
// (openssl reads each certificate's subject alike); never over an existing folder, never from a
// subset, never for a host the graph does not have.
TEST_F(KeystoreTest, ExportForAHostHoldsExactlyItsIdentitiesAndNoCaKey) {
  std::ofstream(dir_ / "hosts.yaml") << kPlacedGraph;
  const std::string graph = (dir_ / "hosts.yaml").string();
  ASSERT_EQ(Init({}, dir_ / "hosts.yaml").code, 0);
  ASSERT_TRUE(fs::exists(keys_ / "ca" / "identity_ca.key.pem"));
  const fs::path out = dir_ / "robot_keys";
  auto r = dyad::testing::RunCommand(AddSecurityCommands,
                                     {"security", "export", keys_.string(), "--graph", graph, "--host", "robot", out.string()});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(Mode(out), 0700u);
  EXPECT_EQ(Listing(out), SubsetBase({"host.robot", "process.rec"}));
  EXPECT_NE(ReadFile(out / "subset.yaml").find("host: robot\n"), std::string::npos) << ReadFile(out / "subset.yaml");
  for (const char* cert :
       {"identity_ca.cert.pem", "permissions_ca.cert.pem", "identities/host.robot/cert.pem", "identities/process.rec/cert.pem"}) {
    int a = -1, b = -1;
    const std::string exported = OpenSsl({"x509", "-noout", "-subject", "-in", (out / cert).string()}, &a);
    EXPECT_EQ(a, 0) << exported;
    EXPECT_EQ(exported, OpenSsl({"x509", "-noout", "-subject", "-in", (keys_ / cert).string()}, &b)) << cert;
  }
  EXPECT_EQ(ReadFile(out / "identities/process.rec/key.pem"), ReadFile(Identity("process.rec", "key.pem")));
  EXPECT_EQ(ReadFile(out / "names.key"), ReadFile(keys_ / kNamesKeyFile));

  auto again = dyad::testing::RunCommand(AddSecurityCommands,
                                         {"security", "export", keys_.string(), "--graph", graph, "--host", "lab", out.string()});
  EXPECT_EQ(again.code, 2);
  EXPECT_NE(again.err.find(out.string() + ": exists (a folder): export makes a new folder"), std::string::npos) << again.err;
  EXPECT_FALSE(fs::exists(out / "identities" / "host.lab"));
  auto nested = dyad::testing::RunCommand(
      AddSecurityCommands, {"security", "export", out.string(), "--graph", graph, "--host", "robot", (dir_ / "again").string()});
  EXPECT_EQ(nested.code, 2);
  EXPECT_NE(nested.err.find("a subset itself"), std::string::npos) << nested.err;
  auto stranger = dyad::testing::RunCommand(
      AddSecurityCommands, {"security", "export", keys_.string(), "--graph", graph, "--host", "nowhere", (dir_ / "x").string()});
  EXPECT_EQ(stranger.code, 2);
  EXPECT_NE(stranger.err.find("--host nowhere: not a host of graph 'sec' (its hosts: lab, robot)"), std::string::npos)
      << stranger.err;
  EXPECT_FALSE(fs::exists(dir_ / "again"));
  EXPECT_FALSE(fs::exists(dir_ / "x"));
}

// --web: the web component's TLS key and certificate go only where asked (the machine that runs
// it), as the same bytes, 0600; without them in the keystore, --web is refused naming the option.
TEST_F(KeystoreTest, AnExportHoldsTheWebCertificateOnlyWithWeb) {
  std::ofstream(dir_ / "hosts.yaml") << kPlacedGraph;
  const std::string graph = (dir_ / "hosts.yaml").string();
  ASSERT_EQ(Init({}, dir_ / "hosts.yaml").code, 0);
  auto refused = dyad::testing::RunCommand(AddSecurityCommands, {"security", "export", keys_.string(), "--graph", graph, "--host",
                                                                 "lab", "--web", (dir_ / "none").string()});
  EXPECT_EQ(refused.code, 2);
  EXPECT_NE(refused.err.find("web/tls.pem: --web, and the keystore has no web certificate"), std::string::npos) << refused.err;
  EXPECT_FALSE(fs::exists(dir_ / "none"));
  ASSERT_EQ(Init({"--web-host", "127.0.0.1"}, dir_ / "hosts.yaml").code, 0);
  for (const bool web : {false, true}) {
    const fs::path out = dir_ / (web ? "with_web" : "without_web");
    std::vector<std::string> args = {"security", "export", keys_.string(), "--graph", graph, "--host", "lab", out.string()};
    if (web) args.push_back("--web");
    auto r = dyad::testing::RunCommand(AddSecurityCommands, args);
    ASSERT_EQ(r.code, 0) << r.err;
    std::set<std::string> expected = SubsetBase({"host.lab", "process.pub"});
    expected.insert("0600 web_ca.cert.pem");
    if (web) expected.insert({"0700 web", "0600 web/tls.pem", "0600 web/cert.pem", "0600 web/hosts"});
    EXPECT_EQ(Listing(out), expected) << web;
  }
  EXPECT_EQ(ReadFile(dir_ / "with_web" / "web" / "tls.pem"), ReadFile(keys_ / "web" / "tls.pem"));
}

// --guest: the guest identity only; a graph without security.guests has none to export.
TEST_F(KeystoreTest, AGuestSubsetHoldsOnlyTheGuestIdentity) {
  std::ofstream(dir_ / "hosts.yaml") << kPlacedGraph;
  ASSERT_EQ(Init({}, dir_ / "hosts.yaml").code, 0);
  const fs::path out = dir_ / "guest_keys";
  auto r = dyad::testing::RunCommand(AddSecurityCommands, {"security", "export", keys_.string(), "--graph",
                                                           (dir_ / "hosts.yaml").string(), "--guest", out.string()});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(Listing(out), SubsetBase({"guest"}));
  EXPECT_NE(ReadFile(out / "subset.yaml").find("guest: true\n"), std::string::npos) << ReadFile(out / "subset.yaml");

  const fs::path open = dir_ / "no_guests.yaml";
  std::ofstream(open) << std::string(kPlacedGraph).replace(std::string(kPlacedGraph).find(", guests: {subscribe: [ca]}"), 27, "");
  auto none = dyad::testing::RunCommand(
      AddSecurityCommands, {"security", "export", keys_.string(), "--graph", open.string(), "--guest", (dir_ / "none").string()});
  EXPECT_EQ(none.code, 2);
  EXPECT_NE(none.err.find("--guest: graph 'sec' has no security.guests, so no guest identity"), std::string::npos) << none.err;
  EXPECT_FALSE(fs::exists(dir_ / "none"));
}

// On a machine that holds only its subset, `dyad validate` checks that machine's identities (a
// whole keystore would have to hold every one), a problem of one of them is still found, and a
// tool that needs an identity the subset does not hold is refused naming it, the host the subset
// was made for, and the export that would give it. `dyad security init` works only on the whole.
TEST_F(KeystoreTest, ValidateOnASubsetChecksItsIdentitiesAndAnotherHostsIsRefused) {
  std::ofstream(dir_ / "hosts.yaml") << kPlacedGraph;
  ASSERT_EQ(Init({}, dir_ / "hosts.yaml").code, 0);
  const fs::path out = dir_ / "robot_keys";
  ASSERT_EQ(dyad::testing::RunCommand(AddSecurityCommands, {"security", "export", keys_.string(), "--graph",
                                                            (dir_ / "hosts.yaml").string(), "--host", "robot", out.string()})
                .code,
            0);
  std::string on_robot = kPlacedGraph;
  on_robot.replace(on_robot.find("keystore: keys"), 14, "keystore: robot_keys");
  const fs::path graph = dir_ / "robot.yaml";
  std::ofstream(graph) << on_robot;
  auto ok = dyad::testing::RunCommand(AddRuntimeCommands, {"validate", graph.string()});
  EXPECT_EQ(ok.code, 0) << ok.err;

  auto status =
      dyad::testing::RunCommand(AddIntrospectionCommands, {"status", "--graph", graph.string(), "--host", "lab", "--wait", "0"});
  EXPECT_EQ(status.code, 2);
  EXPECT_NE(status.err.find("identity 'host.lab' is not in keystore " + out.string() + ": it is the subset for host 'robot' (" +
                            (out / "subset.yaml").string() +
                            "), which holds only process.rec, host.robot; on the machine "
                            "with the whole keystore, `dyad security export " +
                            keys_.string() + " --graph " + (dir_ / "hosts.yaml").string() +
                            " --host lab OUT` makes the subset that holds it"),
            std::string::npos)
      << status.err;
  auto here = dyad::testing::RunCommand(AddIntrospectionCommands, {"status", "--graph", graph.string(), "--wait", "0"});
  EXPECT_EQ(here.err.find("none of the graph's hosts"), std::string::npos) << "the subset says which host this is: " << here.err;
  EXPECT_EQ(here.err.find("is not in keystore"), std::string::npos) << here.err;

  fs::remove(out / "identities" / "process.rec" / "permissions.p7s");
  auto broken = dyad::testing::RunCommand(AddRuntimeCommands, {"validate", graph.string()});
  EXPECT_EQ(broken.code, 2);
  EXPECT_NE(broken.err.find("identity 'process.rec': " + (out / "identities/process.rec/permissions.p7s").string() + ": missing"),
            std::string::npos)
      << broken.err;
  EXPECT_EQ(broken.err.find("process.pub"), std::string::npos) << broken.err;

  auto init = dyad::testing::RunCommand(AddSecurityCommands, {"security", "init", out.string(), "--graph", graph.string()});
  EXPECT_EQ(init.code, 2);
  EXPECT_NE(init.err.find("is a subset (subset.yaml, made by `dyad security export`): init works on the whole keystore"),
            std::string::npos)
      << init.err;
  EXPECT_FALSE(fs::exists(out / "identities" / "process.pub"));
}

TEST_F(KeystoreTest, SecurityWithADiscoveryServerIsRefused) {
  ASSERT_EQ(Init().code, 0);
  const fs::path g = WriteGraph("network: {discovery: server, server: '127.0.0.1:11888'}\nsecurity: {keystore: keys}\n", "ds.yaml");
  auto r = dyad::testing::RunCommand(AddRuntimeCommands, {"validate", g.string()});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("Fast DDS 2.9 has no secure discovery server: use network.discovery: peers"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace dyad::cli
