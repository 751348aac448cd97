// WsClient against the WebServer on port 0: text both ways, the server closing, refused
// handshakes, nothing listening, Close() from another thread and from its own callbacks, large
// frames, and the relay's shape (a client relaying through one server to another).
#include "ws_client.hpp"

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <atomic>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <thread>

#include "web_server.hpp"

namespace dyad::web {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

const std::string kToken = "subject-token-0123456789";

bool Eventually(const std::function<bool()>& done, seconds limit = seconds(10)) {
  const auto until = std::chrono::steady_clock::now() + limit;
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(milliseconds(5));
  }
  return true;
}

// A server's side: says hello on open, answers "echo:<text>" to every text frame.
class EchoHandler final : public ClientHandler {
 public:
  void OnOpen(ClientId client, Role) override {
    {
      std::lock_guard<std::mutex> lock(mutex);
      open.push_back(client);
    }
    if (server != nullptr) server->SendText(client, "hello");
  }
  Status OnText(ClientId client, std::string_view text) override {
    ++texts;
    if (server != nullptr) server->SendText(client, "echo:" + std::string(text));
    return Status::OK();
  }
  Status OnBinary(ClientId, std::span<const uint8_t>) override { return Status::OK(); }
  void OnClose(ClientId) override { ++closes; }
  ClientId Last() {
    std::lock_guard<std::mutex> lock(mutex);
    return open.empty() ? 0 : open.back();
  }
  size_t Opened() {
    std::lock_guard<std::mutex> lock(mutex);
    return open.size();
  }
  WebServer* server = nullptr;  // set once started
  std::mutex mutex;
  std::vector<ClientId> open;
  std::atomic<int> texts{0}, closes{0};
};

WebServer::Options EchoOptions(EchoHandler* handler) {
  WebServer::Options o;
  o.port = 0;
  o.tokens = {{Role::kSubject, kToken}};
  o.endpoints = {WebServer::Endpoint{"/ws", {}, handler, {Role::kSubject}, /*viewers=*/false}};
  return o;
}

std::unique_ptr<WebServer> StartEcho(EchoHandler* handler, WebServer::Options o) {
  auto server = WebServer::Start(o);
  if (!server.ok()) ADD_FAILURE() << server.status().ToString();
  if (!server.ok()) return nullptr;
  handler->server = server->get();
  return std::move(*server);
}

// What a client received, for the test's thread to wait on.
struct Inbox {
  std::mutex mutex;
  std::condition_variable cv;
  std::deque<std::string> texts;
  int closes = 0;
  WsClient::Callbacks Callbacks() {
    return {[this](std::string_view t) {
              std::lock_guard<std::mutex> lock(mutex);
              texts.emplace_back(t);
              cv.notify_all();
            },
            [this] {
              std::lock_guard<std::mutex> lock(mutex);
              ++closes;
              cv.notify_all();
            }};
  }
  // The next text, or "" after `limit`.
  std::string Next(seconds limit = seconds(10)) {
    std::unique_lock<std::mutex> lock(mutex);
    if (!cv.wait_for(lock, limit, [&] { return !texts.empty(); })) return "";
    std::string t = std::move(texts.front());
    texts.pop_front();
    return t;
  }
  bool WaitClosed(seconds limit = seconds(10)) {
    std::unique_lock<std::mutex> lock(mutex);
    return cv.wait_for(lock, limit, [&] { return closes > 0; });
  }
  int Closes() {
    std::lock_guard<std::mutex> lock(mutex);
    return closes;
  }
};

// A loopback port nothing listens on (bound, then closed).
int FreePort() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a));
  socklen_t len = sizeof(a);
  getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  close(fd);
  return ntohs(a.sin_port);
}

TEST(WsClient, SendsAndReceivesTextFrames) {
  EchoHandler handler;
  auto server = StartEcho(&handler, EchoOptions(&handler));
  ASSERT_NE(server, nullptr);
  Inbox inbox;
  auto client = WsClient::Connect("127.0.0.1", server->port(), "/ws?token=" + kToken, inbox.Callbacks(), seconds(5));
  ASSERT_TRUE(client.ok()) << client.status().ToString();
  EXPECT_EQ(inbox.Next(), "hello");
  for (const std::string& text : {std::string("hi"), std::string(200, 'm'), std::string(70000, 'L'), std::string()}) {
    ASSERT_TRUE((*client)->SendText(text).ok());
    EXPECT_EQ(inbox.Next(), "echo:" + text) << text.size() << " bytes";
  }
  (*client)->Close();
  EXPECT_TRUE(Eventually([&] { return handler.closes == 1; })) << "the server saw the client leave";
  EXPECT_EQ(inbox.Closes(), 0) << "on_close runs only when the peer ends the link";
  EXPECT_EQ((*client)->SendText("late").code(), Status::Code::kFailedPrecondition);
}

TEST(WsClient, NothingListeningIsNotFoundWithinTheTimeout) {
  const int port = FreePort();
  Inbox inbox;
  const auto start = std::chrono::steady_clock::now();
  auto client = WsClient::Connect("127.0.0.1", port, "/ws?token=" + kToken, inbox.Callbacks(), seconds(2));
  ASSERT_FALSE(client.ok());
  EXPECT_LT(std::chrono::steady_clock::now() - start, seconds(2));
  EXPECT_EQ(client.status().code(), Status::Code::kNotFound) << client.status().ToString();
  EXPECT_NE(client.status().message().find("ws://127.0.0.1:" + std::to_string(port) + "/ws"), std::string::npos)
      << client.status().ToString();
  EXPECT_EQ(client.status().message().find(kToken), std::string::npos) << "the token is kept out of errors";
}

// With `tokens` a refused handshake is closed unanswered (as always); with `admit` it gets the
// Refusal's status and body, which the client's error carries.
TEST(WsClient, ARefusedHandshakeIsAnIOErrorWithTheServersAnswer) {
  EchoHandler handler;
  auto tokens = StartEcho(&handler, EchoOptions(&handler));
  ASSERT_NE(tokens, nullptr);
  Inbox inbox;
  auto client = WsClient::Connect("127.0.0.1", tokens->port(), "/ws?token=wrong", inbox.Callbacks(), seconds(5));
  ASSERT_FALSE(client.ok());
  EXPECT_EQ(client.status().code(), Status::Code::kIOError);
  EXPECT_NE(client.status().message().find("without answering"), std::string::npos) << client.status().ToString();

  WebServer::Options o = EchoOptions(&handler);
  o.tokens.clear();
  o.admit = [](std::string_view token, std::string_view) -> std::variant<Admission, Refusal> {
    if (token == "busy") return Refusal{503, "Please come back later.\n"};
    return Refusal{404, "This link is not known here.\n"};
  };
  auto admit = StartEcho(&handler, o);
  ASSERT_NE(admit, nullptr);
  client = WsClient::Connect("127.0.0.1", admit->port(), "/ws?token=nope", inbox.Callbacks(), seconds(5));
  ASSERT_FALSE(client.ok());
  EXPECT_EQ(client.status().code(), Status::Code::kIOError);
  EXPECT_NE(client.status().message().find("HTTP 404 Not Found: This link is not known here."), std::string::npos)
      << client.status().ToString();
  client = WsClient::Connect("127.0.0.1", admit->port(), "/ws?token=busy", inbox.Callbacks(), seconds(5));
  ASSERT_FALSE(client.ok());
  EXPECT_NE(client.status().message().find("HTTP 503 Service Unavailable: Please come back later."), std::string::npos)
      << client.status().ToString();
  EXPECT_EQ(handler.Opened(), 0u);
}

// The server's Close(): the frames queued before it arrive, then on_close runs, once.
TEST(WsClient, TheServerClosingRunsOnCloseOnceAfterTheQueuedFrames) {
  EchoHandler handler;
  auto server = StartEcho(&handler, EchoOptions(&handler));
  ASSERT_NE(server, nullptr);
  Inbox inbox;
  auto client = WsClient::Connect("127.0.0.1", server->port(), "/ws?token=" + kToken, inbox.Callbacks(), seconds(5));
  ASSERT_TRUE(client.ok()) << client.status().ToString();
  ASSERT_EQ(inbox.Next(), "hello");
  const ClientId id = handler.Last();
  server->SendText(id, "one");
  server->SendText(id, "two");
  server->Close(id, 1008, "This link is already open in another window.");
  server->SendText(id, "after the close");
  server->Close(id, 1000, "again");  // nothing: closing already
  EXPECT_EQ(inbox.Next(), "one");
  EXPECT_EQ(inbox.Next(), "two");
  ASSERT_TRUE(inbox.WaitClosed());
  EXPECT_TRUE(Eventually([&] { return handler.closes == 1; })) << "OnClose ran on the server";
  std::this_thread::sleep_for(milliseconds(100));
  EXPECT_EQ(inbox.Closes(), 1);
  EXPECT_EQ(inbox.Next(seconds(0)), "") << "nothing after the close frame";
  EXPECT_EQ((*client)->SendText("late").code(), Status::Code::kFailedPrecondition);
  (*client)->Close();
  EXPECT_EQ(inbox.Closes(), 1);
  EXPECT_TRUE(server->clients().empty());
}

}  // namespace
}  // namespace dyad::web
