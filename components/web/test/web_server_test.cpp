// The server against raw clients: tokens and their roles on pages and WebSockets, a client that
// stops reading (disconnected, not left queuing), TLS; and its small helpers.
#include "web_server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <openssl/ssl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>
#include <thread>
#include <vector>

#include "ws_client.hpp"

namespace dyad::web {
namespace {

TEST(TokenMatches, OnlyTheExactTokenAndNeverAnEmptyOne) {
  EXPECT_TRUE(TokenMatches("0123abcd", "0123abcd"));
  EXPECT_FALSE(TokenMatches("0123abce", "0123abcd"));
  EXPECT_FALSE(TokenMatches("0123abc", "0123abcd"));    // a prefix
  EXPECT_FALSE(TokenMatches("0123abcdX", "0123abcd"));  // longer
  EXPECT_FALSE(TokenMatches("", ""));                   // no token configured: nothing matches
  EXPECT_FALSE(TokenMatches(std::string_view("0123\0bcd", 8), "0123abcd"));
}

// Bound to 0.0.0.0 the server used to print http://0.0.0.0:8765/..., which opens nothing.
TEST(UrlHosts, AWildcardBecomesTheMachinesAddresses) {
  EXPECT_EQ(UrlHosts("127.0.0.1"), std::vector<std::string>{"127.0.0.1"});
  EXPECT_EQ(UrlHosts("::1"), std::vector<std::string>{"[::1]"});
  const auto hosts = UrlHosts("0.0.0.0");
  ASSERT_FALSE(hosts.empty());
  for (const auto& h : hosts) {
    EXPECT_NE(h, "0.0.0.0");
    EXPECT_EQ(h.find(':'), std::string::npos) << h;  // IPv4 addresses
  }
}

const std::string kViewer = "viewer-0123456789ab", kSubject = "subject-0123456789a", kExperimenter = "experimenter-012345";

// Records what the server tells it.
class RecordingHandler final : public ClientHandler {
 public:
  void OnOpen(ClientId client, Role role) override {
    last_client = client;
    last_role = role;
    ++opens;
  }
  Status OnText(ClientId, std::string_view) override { return Status::OK(); }
  Status OnBinary(ClientId, std::span<const uint8_t>) override { return Status::OK(); }
  void OnClose(ClientId) override { ++closes; }
  std::atomic<int> opens{0}, closes{0};
  std::atomic<ClientId> last_client{0};
  std::atomic<Role> last_role{Role::kViewer};
};

WebServer::Options TestOptions(RecordingHandler* handler) {
  WebServer::Options o;
  o.port = 0;
  o.tokens = {{Role::kViewer, kViewer}, {Role::kSubject, kSubject}, {Role::kExperimenter, kExperimenter}};
  o.pages["/watch"] = WebServer::Page{"text/plain", "the page\n", {Role::kViewer, Role::kExperimenter}, ""};
  o.endpoints = {WebServer::Endpoint{"/ws", {}, handler, {Role::kSubject, Role::kExperimenter}}};
  return o;
}

// A TCP connection to the server, optionally with a small receive buffer (set before connecting,
// so the window stays small).
int Connect(int port, int receive_buffer = 0) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (receive_buffer > 0) setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof(receive_buffer));
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)) != 0) {
    close(fd);
    return -1;
  }
  return fd;
}

// Sends `request` and reads the response head (up to the blank line) or everything until the end.
std::string Exchange(int fd, const std::string& request) {
  if (send(fd, request.data(), request.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(request.size())) return "";
  std::string out;
  char buf[4096];
  while (out.find("\r\n\r\n") == std::string::npos) {
    const ssize_t n = recv(fd, buf, sizeof(buf), 0);
    if (n <= 0) break;
    out.append(buf, static_cast<size_t>(n));
  }
  return out;
}

std::string Get(int port, const std::string& target) {
  const int fd = Connect(port);
  std::string r = Exchange(fd, "GET " + target + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n");
  close(fd);
  return r;
}

// The whole response, up to the server's end of the connection.
std::string GetWhole(int port, const std::string& target) {
  const int fd = Connect(port);
  std::string r = Exchange(fd, "GET " + target + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n");
  char buf[4096];
  for (ssize_t n; (n = recv(fd, buf, sizeof(buf), 0)) > 0;) r.append(buf, static_cast<size_t>(n));
  close(fd);
  return r;
}

std::string Upgrade(const std::string& target) {
  return "GET " + target +
         " HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
         "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n";
}

bool WaitFor(const std::function<bool()>& done, std::chrono::seconds limit) {
  const auto until = std::chrono::steady_clock::now() + limit;
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

TEST(WebServer, APageNeedsATokenOfARoleItAdmits) {
  RecordingHandler handler;
  auto server = WebServer::Start(TestOptions(&handler));
  ASSERT_TRUE(server.ok()) << server.status().ToString();
  const int port = (*server)->port();
  EXPECT_EQ(Get(port, "/watch").rfind("HTTP/1.1 401", 0), 0u);
  EXPECT_EQ(Get(port, "/watch?token=not-a-token-at-all").rfind("HTTP/1.1 401", 0), 0u);
  EXPECT_EQ(Get(port, "/watch?token=" + kSubject).rfind("HTTP/1.1 403", 0), 0u) << "the subject may not watch here";
  const std::string ok = Get(port, "/watch?token=" + kViewer);
  EXPECT_EQ(ok.rfind("HTTP/1.1 200", 0), 0u) << ok;
  EXPECT_NE(ok.find("Referrer-Policy: no-referrer"), std::string::npos) << "the URL holds the token: never sent on";
  EXPECT_NE(ok.find("X-Frame-Options: DENY"), std::string::npos);
}

// A server without a "/" page (the study page's) answers 404 for any other path; civetweb's own
// error path (no document root) crashed on the browser's /favicon.ico.
TEST(WebServer, AnyOtherPathIsNotFound) {
  RecordingHandler handler;
  auto server = WebServer::Start(TestOptions(&handler));
  ASSERT_TRUE(server.ok()) << server.status().ToString();
  const int port = (*server)->port();
  for (const std::string& path : std::vector<std::string>{"/favicon.ico", "/", "/watch/more?token=" + kViewer, "/nope?token=" + kViewer})
    EXPECT_EQ(Get(port, path).rfind("HTTP/1.1 404", 0), 0u) << path;
  EXPECT_EQ(Get(port, "/watch?token=" + kViewer).rfind("HTTP/1.1 200", 0), 0u) << "the server survived";
}

TEST(WebServer, AWebSocketNeedsATokenOfARoleItsEndpointAdmits) {
  RecordingHandler handler;
  auto server = WebServer::Start(TestOptions(&handler));
  ASSERT_TRUE(server.ok()) << server.status().ToString();
  const int port = (*server)->port();
  for (const std::string& refused : {std::string("/ws"), "/ws?token=" + kViewer, "/ws?token=" + kSubject + "x"}) {
    const int fd = Connect(port);
    EXPECT_EQ(Exchange(fd, Upgrade(refused)).find("101 Switching Protocols"), std::string::npos) << refused;
    close(fd);
  }
  EXPECT_EQ(handler.opens, 0);
  const int fd = Connect(port);
  EXPECT_NE(Exchange(fd, Upgrade("/ws?token=" + kSubject)).find("101 Switching Protocols"), std::string::npos);
  ASSERT_TRUE(WaitFor([&] { return handler.opens == 1; }, std::chrono::seconds(5)));
  EXPECT_EQ(handler.last_role.load(), Role::kSubject);
  close(fd);
}

// Options::admit decides pages and WebSockets instead of tokens: its Refusal is the HTTP answer
// (status and body), its Admission's role is checked against the page's and endpoint's roles,
// and its `who` and the peer's address are the client's.
TEST(WebServer, AnAdmitCallbackDecidesPagesAndWebSocketsAndNamesTheClient) {
  RecordingHandler handler;
  WebServer::Options o = TestOptions(&handler);
  o.tokens.clear();
  std::mutex seen_mutex;
  std::vector<std::pair<std::string, std::string>> seen;  // token, remote address
  o.admit = [&](std::string_view token, std::string_view remote) -> std::variant<Admission, Refusal> {
    {
      std::lock_guard<std::mutex> lock(seen_mutex);
      seen.emplace_back(token, remote);
    }
    if (token == "p07") return Admission{Role::kSubject, "P07"};
    if (token == "watcher") return Admission{Role::kViewer, ""};
    if (token == "knocker") return Refusal{429, "Too many unknown links from your address; try again in a minute.\n"};
    if (token == "full") return Refusal{503, "Please come back later.\n"};
    if (token == "ok-status") return Refusal{200, "not a refusal status\n"};
    return Refusal{404, "This link is not known here.\n"};
  };
  auto server = WebServer::Start(o);
  ASSERT_TRUE(server.ok()) << server.status().ToString();
  const int port = (*server)->port();
  const std::string unknown = GetWhole(port, "/watch?token=nope");
  EXPECT_EQ(unknown.rfind("HTTP/1.1 404 Not Found\r\n", 0), 0u) << unknown;
  EXPECT_NE(unknown.find("\r\n\r\nThis link is not known here.\n"), std::string::npos) << unknown;
  EXPECT_EQ(Get(port, "/watch").rfind("HTTP/1.1 404", 0), 0u) << "no token is the callback's too";
  const std::string knocker = GetWhole(port, "/watch?token=knocker");
  EXPECT_EQ(knocker.rfind("HTTP/1.1 429 Too Many Requests\r\n", 0), 0u) << knocker;
  EXPECT_NE(knocker.find("try again in a minute"), std::string::npos) << knocker;
  EXPECT_EQ(Get(port, "/watch?token=full").rfind("HTTP/1.1 503 Service Unavailable\r\n", 0), 0u);
  EXPECT_EQ(Get(port, "/watch?token=ok-status").rfind("HTTP/1.1 500", 0), 0u) << "a refusal never reads as a success";
  EXPECT_EQ(Get(port, "/watch?token=p07").rfind("HTTP/1.1 403", 0), 0u) << "the page admits viewers only";
  EXPECT_EQ(Get(port, "/watch?token=watcher").rfind("HTTP/1.1 200", 0), 0u);
  {
    std::lock_guard<std::mutex> lock(seen_mutex);
    ASSERT_FALSE(seen.empty());
    EXPECT_EQ(seen.front(), (std::pair<std::string, std::string>{"nope", "127.0.0.1"}));
    EXPECT_EQ(seen[1].first, "");
  }

  int fd = Connect(port);
  const std::string refused = Exchange(fd, Upgrade("/ws?token=full"));
  EXPECT_EQ(refused.rfind("HTTP/1.1 503 Service Unavailable\r\n", 0), 0u) << "a refused handshake gets the status: " << refused;
  close(fd);
  fd = Connect(port);
  EXPECT_EQ(Exchange(fd, Upgrade("/ws?token=watcher")).find("101"), std::string::npos) << "the endpoint admits no viewer";
  close(fd);
  EXPECT_EQ(handler.opens, 0);
  fd = Connect(port);
  ASSERT_NE(Exchange(fd, Upgrade("/ws?token=p07")).find("101 Switching Protocols"), std::string::npos);
  ASSERT_TRUE(WaitFor([&] { return handler.opens == 1; }, std::chrono::seconds(5)));
  const ClientId client = handler.last_client;
  EXPECT_EQ(handler.last_role.load(), Role::kSubject);
  EXPECT_EQ((*server)->who(client), "P07");
  EXPECT_EQ((*server)->remote_address(client), "127.0.0.1");
  close(fd);
  ASSERT_TRUE(WaitFor([&] { return handler.closes == 1; }, std::chrono::seconds(5)));
  EXPECT_EQ((*server)->who(client), "") << "gone";
  EXPECT_EQ((*server)->remote_address(client), "");
}

// Reads one unmasked server frame from `fd`: its opcode and payload (-1 when the link ended).
int ReadFrame(int fd, std::string* buffer, std::string* payload) {
  char chunk[4096];
  for (;;) {
    if (buffer->size() >= 2) {
      const auto* b = reinterpret_cast<const unsigned char*>(buffer->data());
      size_t length = b[1] & 0x7f, head = 2;
      if (length == 126 && buffer->size() >= 4) length = (size_t{b[2]} << 8) | b[3], head = 4;
      if (length < 126 || head == 4) {
        if (buffer->size() >= head + length) {
          *payload = buffer->substr(head, length);
          const int opcode = b[0] & 0x0f;
          buffer->erase(0, head + length);
          return opcode;
        }
      }
    }
    const ssize_t n = recv(fd, chunk, sizeof(chunk), 0);
    if (n <= 0) return -1;
    buffer->append(chunk, static_cast<size_t>(n));
  }
}

// Close(): the frames queued before it, then a close frame with the code and reason, then the
// end of the connection (OnClose); frames queued after it are not sent.
TEST(WebServer, CloseSendsWhatWasQueuedThenTheCodeAndReason) {
  RecordingHandler handler;
  auto server = WebServer::Start(TestOptions(&handler));
  ASSERT_TRUE(server.ok()) << server.status().ToString();
  const int fd = Connect((*server)->port());
  std::string buffer = Exchange(fd, Upgrade("/ws?token=" + kSubject));
  ASSERT_NE(buffer.find("101 Switching Protocols"), std::string::npos);
  buffer.erase(0, buffer.find("\r\n\r\n") + 4);
  ASSERT_TRUE(WaitFor([&] { return handler.opens == 1; }, std::chrono::seconds(5)));
  const ClientId client = handler.last_client;
  (*server)->SendText(client, "{\"op\":\"refused\"}");
  (*server)->SendData(client, 3, "data");
  (*server)->Close(client, 1012, "the phase changed");
  (*server)->SendText(client, "too late");
  std::string payload;
  EXPECT_EQ(ReadFrame(fd, &buffer, &payload), 0x1);
  EXPECT_EQ(payload, "{\"op\":\"refused\"}");
  EXPECT_EQ(ReadFrame(fd, &buffer, &payload), 0x2);
  EXPECT_EQ(payload, "data");
  ASSERT_EQ(ReadFrame(fd, &buffer, &payload), 0x8);
  ASSERT_GE(payload.size(), 2u);
  EXPECT_EQ((static_cast<unsigned char>(payload[0]) << 8) | static_cast<unsigned char>(payload[1]), 1012);
  EXPECT_EQ(payload.substr(2), "the phase changed");
  EXPECT_EQ(ReadFrame(fd, &buffer, &payload), -1) << "nothing after the close frame";
  EXPECT_TRUE(WaitFor([&] { return handler.closes == 1; }, std::chrono::seconds(5)));
  (*server)->Close(client, 1000, "gone already");  // nothing
  close(fd);
}

TEST(WebServer, TokensMustBeGivenAndDistinct) {
  RecordingHandler handler;
  WebServer::Options o = TestOptions(&handler);
  o.tokens[Role::kSubject] = kViewer;
  EXPECT_EQ(WebServer::Start(o).status().code(), Status::Code::kInvalidArgument);
  o.tokens.clear();
  EXPECT_EQ(WebServer::Start(o).status().code(), Status::Code::kInvalidArgument);
}

// libcivetweb 1.15 keeps, in each worker's connection, the subprotocol the last WebSocket it
// served accepted, and answers the next client with it even when that one asked for none
// (civetweb#1091, fixed after 1.15). Node's ws and the browsers then refuse the connection: a page
// opened after a Foxglove viewer could not connect. Every worker here serves a viewer first.
TEST(WebServer, AClientThatAsksForNoSubprotocolIsAnsweredWithNone) {
  RecordingHandler handler;
  WebServer::Options o = TestOptions(&handler);
  o.max_clients = 1;  // the fewest workers, so each serves both kinds
  o.endpoints.push_back(WebServer::Endpoint{"/viewer", {"foxglove.websocket.v1"}, &handler, {Role::kExperimenter}});
  auto server = WebServer::Start(o);
  ASSERT_TRUE(server.ok()) << server.status().ToString();
  const int port = (*server)->port();
  std::string with_protocol = Upgrade("/viewer?token=" + kExperimenter);
  with_protocol.insert(with_protocol.size() - 2, "Sec-WebSocket-Protocol: foxglove.websocket.v1\r\n");
  int connections = 0;
  for (int round = 0; round < 12; ++round) {
    for (const bool asks : {true, false}) {
      const int fd = Connect(port);
      const std::string head = Exchange(fd, asks ? with_protocol : Upgrade("/ws?token=" + kExperimenter));
      close(fd);
      ASSERT_NE(head.find("101 Switching Protocols"), std::string::npos) << "round " << round << (asks ? ", the viewer: " : ", the page: ") << head;
      EXPECT_EQ(head.find("Sec-WebSocket-Protocol"), asks ? head.find("Sec-WebSocket-Protocol: foxglove.websocket.v1")
                                                          : std::string::npos)
          << "round " << round << (asks ? ", the viewer" : ", the page") << ":\n" << head;
      // The one client slot is free again once the server has seen the close.
      ++connections;
      ASSERT_TRUE(WaitFor([&] { return handler.closes == connections; }, std::chrono::seconds(5)));
    }
  }
}

// A client that stops reading: once a write has waited `write_timeout_ms`, the server ends the
// connection (the handler hears OnClose) instead of keeping a sender-less client queuing.
TEST(WebServer, AClientThatStopsReadingIsDisconnectedAfterTheWriteTimeout) {
  RecordingHandler handler;
  WebServer::Options o = TestOptions(&handler);
  o.write_timeout_ms = 300;
  o.client_buffer_bytes = 256 << 10;
  auto server = WebServer::Start(o);
  ASSERT_TRUE(server.ok()) << server.status().ToString();
  const int fd = Connect((*server)->port(), 4096);
  ASSERT_NE(Exchange(fd, Upgrade("/ws?token=" + kExperimenter)).find("101"), std::string::npos);
  ASSERT_TRUE(WaitFor([&] { return handler.opens == 1; }, std::chrono::seconds(5)));
  const std::string frame(60 << 10, 'x');
  const bool closed = WaitFor(
      [&] {
        (*server)->SendData(handler.last_client, 1, frame);
        return handler.closes == 1;
      },
      std::chrono::seconds(30));
  EXPECT_TRUE(closed) << "a client that never reads was kept";
  EXPECT_TRUE((*server)->clients().empty());
  close(fd);
}

// Control frames are never dropped, so a client that never reads them is disconnected once they
// outgrow its buffer (here long before the write timeout could).
TEST(WebServer, ControlFramesPastTheBufferDisconnectTheClient) {
  RecordingHandler handler;
  WebServer::Options o = TestOptions(&handler);
  o.write_timeout_ms = 600000;
  o.client_buffer_bytes = 64 << 10;
  auto server = WebServer::Start(o);
  ASSERT_TRUE(server.ok()) << server.status().ToString();
  const int fd = Connect((*server)->port(), 4096);
  ASSERT_NE(Exchange(fd, Upgrade("/ws?token=" + kExperimenter)).find("101"), std::string::npos);
  ASSERT_TRUE(WaitFor([&] { return handler.opens == 1; }, std::chrono::seconds(5)));
  const std::string status(8 << 10, 's');
  const bool closed = WaitFor(
      [&] {
        for (int i = 0; i < 16; ++i) (*server)->SendText(handler.last_client, status);
        return handler.closes == 1;
      },
      std::chrono::seconds(30));
  EXPECT_TRUE(closed) << "control frames grew without bound";
  close(fd);
}

// A throwaway self-signed certificate for 127.0.0.1, made by the openssl command.
std::string MakeCertificate(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  const std::string key = (dir / "key.pem").string(), cert = (dir / "cert.pem").string(), both = (dir / "tls.pem").string();
  const std::string cmd = "openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:P-256 -nodes -days 2 -subj /CN=127.0.0.1 "
                          "-addext subjectAltName=IP:127.0.0.1 -keyout " + key + " -out " + cert + " 2>/dev/null && cat " + key +
                          " " + cert + " > " + both;
  return std::system(cmd.c_str()) == 0 ? both : "";
}

TEST(WebServer, WithACertificateItSpeaksTlsOnly) {
  const auto dir = std::filesystem::temp_directory_path() / ("dyad_web_tls_" + std::to_string(getpid()));
  const std::string pem = MakeCertificate(dir);
  if (pem.empty()) GTEST_SKIP() << "no openssl command";
  RecordingHandler handler;
  WebServer::Options o = TestOptions(&handler);
  o.tls_certificate = pem;
  auto server = WebServer::Start(o);
  ASSERT_TRUE(server.ok()) << server.status().ToString();
  const int port = (*server)->port();

  SSL_CTX* ctx = SSL_CTX_new(TLS_client_method());
  ASSERT_EQ(SSL_CTX_load_verify_locations(ctx, (dir / "cert.pem").c_str(), nullptr), 1);
  SSL_CTX_set_verify(ctx, SSL_VERIFY_PEER, nullptr);
  const int fd = Connect(port);
  SSL* ssl = SSL_new(ctx);
  SSL_set_fd(ssl, fd);
  SSL_set1_host(ssl, "127.0.0.1");
  ASSERT_EQ(SSL_connect(ssl), 1) << "TLS handshake failed (certificate not verified?)";
  const std::string request = "GET /watch?token=" + kExperimenter + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n";
  ASSERT_EQ(SSL_write(ssl, request.data(), static_cast<int>(request.size())), static_cast<int>(request.size()));
  std::string response;
  char buf[4096];
  for (int n; (n = SSL_read(ssl, buf, sizeof(buf))) > 0;) response.append(buf, static_cast<size_t>(n));
  EXPECT_EQ(response.rfind("HTTP/1.1 200", 0), 0u) << response;
  EXPECT_NE(response.find("the page"), std::string::npos);
  SSL_free(ssl);
  close(fd);
  SSL_CTX_free(ctx);

  EXPECT_EQ(Get(port, "/watch?token=" + kExperimenter).find("200 OK"), std::string::npos) << "plain HTTP answered";
  std::filesystem::remove_all(dir);
}

TEST(WebServer, AnUnusableCertificateIsAClearError) {
  const auto dir = std::filesystem::temp_directory_path() / ("dyad_web_badtls_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string pem = (dir / "tls.pem").string();
  std::FILE* f = std::fopen(pem.c_str(), "w");
  std::fputs("not a certificate\n", f);
  std::fclose(f);
  RecordingHandler handler;
  WebServer::Options o = TestOptions(&handler);
  o.tls_certificate = pem;
  auto server = WebServer::Start(o);
  ASSERT_FALSE(server.ok());
  EXPECT_NE(server.status().message().find(pem), std::string::npos) << server.status().ToString();
  std::filesystem::remove_all(dir);
}

// Which thread each text frame reached the handler on, per client, in order.
class ThreadRecordingHandler final : public ClientHandler {
 public:
  void OnOpen(ClientId, Role) override {}
  Status OnText(ClientId client, std::string_view text) override {
    std::lock_guard<std::mutex> lock(mutex);
    frames[client].push_back({std::string(text), std::this_thread::get_id()});
    return Status::OK();
  }
  Status OnBinary(ClientId, std::span<const uint8_t>) override { return Status::OK(); }
  void OnClose(ClientId) override {}
  size_t count() {
    std::lock_guard<std::mutex> lock(mutex);
    size_t n = 0;
    for (const auto& f : frames) n += f.second.size();
    return n;
  }
  std::mutex mutex;
  std::map<ClientId, std::vector<std::pair<std::string, std::thread::id>>> frames;
};

// An endpoint whose handler only queues (the study server's) gets each client's frames on that
// client's own worker: two clients on two threads, none of them the handler thread, which takes
// every client's frames of an ordinary endpoint one at a time. Each client's frames in order.
TEST(WebServer, AHandlerThatOnlyQueuesIsCalledOnEachClientsOwnWorker) {
  for (const bool only_queues : {false, true}) {
    SCOPED_TRACE(only_queues ? "handler_only_queues" : "on the handler thread");
    ThreadRecordingHandler handler;
    WebServer::Options o;
    o.port = 0;
    o.tokens = {{Role::kSubject, kSubject}};
    o.endpoints = {WebServer::Endpoint{"/ws", {}, &handler, {Role::kSubject}, false, only_queues}};
    auto server = WebServer::Start(o);
    ASSERT_TRUE(server.ok()) << server.status().ToString();
    auto a = WsClient::Connect("127.0.0.1", (*server)->port(), "/ws?token=" + kSubject, {}, std::chrono::seconds(5));
    auto b = WsClient::Connect("127.0.0.1", (*server)->port(), "/ws?token=" + kSubject, {}, std::chrono::seconds(5));
    ASSERT_TRUE(a.ok() && b.ok());
    for (int i = 0; i < 3; ++i) {
      ASSERT_TRUE((*a)->SendText("a" + std::to_string(i)).ok());
      ASSERT_TRUE((*b)->SendText("b" + std::to_string(i)).ok());
    }
    ASSERT_TRUE(WaitFor([&] { return handler.count() == 6; }, std::chrono::seconds(5)));
    std::lock_guard<std::mutex> lock(handler.mutex);
    ASSERT_EQ(handler.frames.size(), 2u);
    std::vector<std::thread::id> threads;
    for (const auto& [client, frames] : handler.frames) {
      const char name = frames[0].first[0];
      for (size_t i = 0; i < frames.size(); ++i) {
        EXPECT_EQ(frames[i].first, std::string(1, name) + std::to_string(i));
        EXPECT_EQ(frames[i].second, frames[0].second) << "one client's frames on one thread";
        EXPECT_NE(frames[i].second, std::this_thread::get_id());
      }
      threads.push_back(frames[0].second);
    }
    if (only_queues) EXPECT_NE(threads[0], threads[1]) << "each client's own worker";
    else EXPECT_EQ(threads[0], threads[1]) << "the one handler thread";
  }
}

}  // namespace
}  // namespace dyad::web
