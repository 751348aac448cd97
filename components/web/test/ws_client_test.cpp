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
#include <functional>
#include <map>
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

// An echo server and a client connected to it that has had the server's hello: where most tests
// start. `tweak`, if given, changes the server's options (EchoOptions) before it starts. Members
// are destroyed in reverse: the client first, the handler last.
struct EchoLink {
  ::testing::AssertionResult Open(const std::function<void(WebServer::Options&)>& tweak = {}) {
    WebServer::Options o = EchoOptions(&handler);
    if (tweak) tweak(o);
    server = StartEcho(&handler, o);
    if (server == nullptr) return ::testing::AssertionFailure() << "the echo server did not start";
    auto c = WsClient::Connect("127.0.0.1", server->port(), "/ws?token=" + kToken, inbox.Callbacks(), seconds(5));
    if (!c.ok()) return ::testing::AssertionFailure() << c.status().ToString();
    client = std::move(*c);
    const std::string hello = inbox.Next();
    if (hello != "hello") return ::testing::AssertionFailure() << "the server's first frame was '" << hello << "'";
    return ::testing::AssertionSuccess();
  }
  EchoHandler handler;
  std::unique_ptr<WebServer> server;
  Inbox inbox;
  std::unique_ptr<WsClient> client;
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
  EchoLink link;
  ASSERT_TRUE(link.Open());
  // Named references, not a structured binding: clang 14 (the sanitizer build) does not let a
  // lambda capture a structured binding.
  auto& handler = link.handler;
  auto& inbox = link.inbox;
  auto& client = link.client;
  for (const std::string& text : {std::string("hi"), std::string(200, 'm'), std::string(70000, 'L'), std::string()}) {
    ASSERT_TRUE(client->SendText(text).ok());
    EXPECT_EQ(inbox.Next(), "echo:" + text) << text.size() << " bytes";
  }
  client->Close();
  EXPECT_TRUE(Eventually([&] { return handler.closes == 1; })) << "the server saw the client leave";
  EXPECT_EQ(inbox.Closes(), 0) << "on_close runs only when the peer ends the link";
  EXPECT_EQ(client->SendText("late").code(), Status::Code::kFailedPrecondition);
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
  EchoLink link;
  ASSERT_TRUE(link.Open());
  // Named references, not a structured binding: clang 14 (the sanitizer build) does not let a
  // lambda capture a structured binding.
  auto& handler = link.handler;
  auto& server = link.server;
  auto& inbox = link.inbox;
  auto& client = link.client;
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
  EXPECT_EQ(client->SendText("late").code(), Status::Code::kFailedPrecondition);
  client->Close();
  EXPECT_EQ(inbox.Closes(), 1);
  EXPECT_TRUE(server->clients().empty());
}

// A server that listens but never answers: the handshake's wait ends at the timeout.
TEST(WsClient, AServerThatNeverAnswersTimesOut) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)), 0);
  ASSERT_EQ(listen(fd, 4), 0);  // the kernel completes connections; nobody reads them
  socklen_t len = sizeof(a);
  getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  Inbox inbox;
  const auto start = std::chrono::steady_clock::now();
  auto client = WsClient::Connect("127.0.0.1", ntohs(a.sin_port), "/ws", inbox.Callbacks(), milliseconds(300));
  const auto took = std::chrono::steady_clock::now() - start;
  close(fd);
  ASSERT_FALSE(client.ok());
  EXPECT_EQ(client.status().code(), Status::Code::kIOError) << client.status().ToString();
  EXPECT_GE(took, milliseconds(250));
  EXPECT_LT(took, seconds(5)) << "the timeout was not kept";
}

// The peer's process going away (its sockets closed, no close frame): on_close, once.
TEST(WsClient, APeerThatGoesAwayRunsOnCloseOnce) {
  EchoLink link;
  ASSERT_TRUE(link.Open());
  // Named references, not a structured binding: clang 14 (the sanitizer build) does not let a
  // lambda capture a structured binding.
  auto& server = link.server;
  auto& inbox = link.inbox;
  auto& client = link.client;
  server.reset();
  ASSERT_TRUE(inbox.WaitClosed());
  EXPECT_NE(client->SendText("anyone?").code(), Status::Code::kOk);
  client->Close();
  EXPECT_EQ(inbox.Closes(), 1);
}

// Close() from another thread while the server floods the client and the client sends: once it
// returns, no callback runs (checked over many rounds, each closing at a different moment), and
// a SendText racing it fails cleanly.
TEST(WsClient, CloseFromAnotherThreadWhileFramesFlowEndsEveryCallback) {
  EchoHandler handler;
  auto server = StartEcho(&handler, EchoOptions(&handler));
  ASSERT_NE(server, nullptr);
  for (int round = 0; round < 20; ++round) {
    std::atomic<bool> returned{false};
    std::atomic<int> received{0}, late{0}, closes{0};
    WsClient::Callbacks callbacks{[&](std::string_view) {
                                    if (returned) ++late;
                                    ++received;
                                  },
                                  [&] { ++closes; }};  // the server never closes here
    auto client = WsClient::Connect("127.0.0.1", server->port(), "/ws?token=" + kToken, std::move(callbacks), seconds(5));
    ASSERT_TRUE(client.ok()) << client.status().ToString();
    ASSERT_TRUE(Eventually([&] { return handler.Opened() == static_cast<size_t>(round + 1); }));
    const ClientId id = handler.Last();
    std::atomic<bool> stop{false};
    // Paced (about 10k frames/s each way): a flood faster than the link would outgrow the
    // server's buffer for control frames, which disconnects the client (another test's case).
    std::thread flood([&] {
      for (int i = 0; !stop; ++i) {
        server->SendText(id, std::string(100, 'f'));
        if (i % 10 == 0) std::this_thread::sleep_for(milliseconds(1));
      }
    });
    std::thread sender([&] {
      for (int i = 0; !stop; ++i) {
        (void)(*client)->SendText("x");  // errors once closed: expected
        if (i % 10 == 0) std::this_thread::sleep_for(milliseconds(1));
      }
    });
    ASSERT_TRUE(Eventually([&] { return received > 10 + round * 5; }));
    (*client)->Close();
    returned = true;
    std::this_thread::sleep_for(milliseconds(20));
    stop = true;
    flood.join();
    sender.join();
    EXPECT_EQ(late, 0) << "round " << round << ": on_text ran after Close() returned";
    EXPECT_EQ(closes, 0) << "round " << round << ": on_close ran (after Close(), or the server dropped the client)";
    EXPECT_EQ((*client)->SendText("after").code(), Status::Code::kFailedPrecondition);
    client->reset();
    ASSERT_TRUE(Eventually([&] { return handler.closes == round + 1; })) << "round " << round;
  }
}

// Closing and destroying a client inside its own callbacks (the relay does both).
TEST(WsClient, ACallbackMayCloseOrDestroyItsOwnClient) {
  EchoHandler handler;
  auto server = StartEcho(&handler, EchoOptions(&handler));
  ASSERT_NE(server, nullptr);
  std::unique_ptr<WsClient> client;
  std::mutex mutex;
  std::atomic<int> texts{0}, closes{0};
  // The server's hello may come before Connect returns: `client` is set under the mutex.
  WsClient::Callbacks closes_itself{[&](std::string_view) {
                                      ++texts;
                                      std::lock_guard<std::mutex> lock(mutex);
                                      client->Close();  // on the client's own thread
                                    },
                                    [&] { ++closes; }};
  StatusOr<std::unique_ptr<WsClient>> c = Status::NotFound("not yet");
  {
    std::lock_guard<std::mutex> lock(mutex);
    c = WsClient::Connect("127.0.0.1", server->port(), "/ws?token=" + kToken, std::move(closes_itself), seconds(5));
    ASSERT_TRUE(c.ok()) << c.status().ToString();
    client = std::move(*c);
  }
  server->SendText(handler.Last(), "more");
  ASSERT_TRUE(Eventually([&] { return handler.closes == 1; })) << "the server saw the close";
  EXPECT_EQ(texts, 1) << "nothing after the callback that closed it";
  EXPECT_EQ(closes, 0);
  {
    std::lock_guard<std::mutex> lock(mutex);
    client.reset();
  }

  std::atomic<bool> destroyed{false};
  WsClient::Callbacks destroys_itself{nullptr, [&] {
                                        std::lock_guard<std::mutex> lock(mutex);
                                        client.reset();  // ~WsClient on the client's own thread
                                        destroyed = true;
                                      }};
  {
    std::lock_guard<std::mutex> lock(mutex);
    c = WsClient::Connect("127.0.0.1", server->port(), "/ws?token=" + kToken, std::move(destroys_itself), seconds(5));
    ASSERT_TRUE(c.ok()) << c.status().ToString();
    client = std::move(*c);
  }
  ASSERT_TRUE(Eventually([&] { return handler.Opened() == 2; }));
  server->Close(handler.Last(), 1012, "the phase changed");
  ASSERT_TRUE(Eventually([&] { return destroyed.load(); }));
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_EQ(client, nullptr);
}

// Frames at the server's max_frame_bytes pass; one byte more and the server ends the link
// (1009), which the client hears as on_close. A large frame from the server arrives whole.
TEST(WsClient, FramesUpToTheServersLimitPassAndLargerOnesEndTheLink) {
  constexpr size_t kLimit = 256 << 10;
  EchoLink link;
  ASSERT_TRUE(link.Open([&](WebServer::Options& o) { o.max_frame_bytes = kLimit; }));
  // Named references, not a structured binding: clang 14 (the sanitizer build) does not let a
  // lambda capture a structured binding.
  auto& handler = link.handler;
  auto& server = link.server;
  auto& inbox = link.inbox;
  auto& client = link.client;
  const std::string at_limit(kLimit, 'a');
  ASSERT_TRUE(client->SendText(at_limit).ok());
  EXPECT_EQ(inbox.Next(), "echo:" + at_limit);
  const std::string big(3 << 20, 'b');  // server -> client: past the server's own receive limit
  server->SendText(handler.Last(), big);
  EXPECT_EQ(inbox.Next(), big);
  ASSERT_TRUE(client->SendText(at_limit + "!").ok());
  ASSERT_TRUE(inbox.WaitClosed()) << "the server kept a client whose frame exceeded its limit";
  EXPECT_EQ(handler.texts, 1);
  EXPECT_TRUE(Eventually([&] { return handler.closes == 1; }));
}

// The relay's shape (dyad study serve): a page connects to the front; the front connects a
// WsClient to the graph's server and relays text both ways; either side leaving ends the other.
class Relay final : public ClientHandler {
 public:
  void OnOpen(ClientId page, Role) override {
    WsClient::Callbacks up{[this, page](std::string_view text) { front->SendText(page, std::string(text)); },
                           [this, page] { front->Close(page, 1012, "the trial's page is gone"); }};
    auto c = WsClient::Connect("127.0.0.1", graph_port, "/ws?token=" + kToken, std::move(up), seconds(5));
    std::lock_guard<std::mutex> lock(mutex);
    if (c.ok()) upstream[page] = std::move(*c);
    else errors.push_back(c.status().ToString());
  }
  Status OnText(ClientId page, std::string_view text) override {
    std::lock_guard<std::mutex> lock(mutex);
    auto it = upstream.find(page);
    return it == upstream.end() ? Status::FailedPrecondition("no upstream") : it->second->SendText(text);
  }
  Status OnBinary(ClientId, std::span<const uint8_t>) override { return Status::OK(); }
  void OnClose(ClientId page) override {
    std::unique_ptr<WsClient> up;
    {
      std::lock_guard<std::mutex> lock(mutex);
      auto it = upstream.find(page);
      if (it == upstream.end()) return;
      up = std::move(it->second);
      upstream.erase(it);
    }
    up.reset();  // outside the lock: Close() waits for a callback that may want it
  }
  WebServer* front = nullptr;
  int graph_port = 0;
  std::mutex mutex;
  std::map<ClientId, std::unique_ptr<WsClient>> upstream;
  std::vector<std::string> errors;
};

TEST(WsClient, RelaysAPageThroughOneServerToAnother) {
  EchoHandler graph_handler;
  auto graph = StartEcho(&graph_handler, EchoOptions(&graph_handler));
  ASSERT_NE(graph, nullptr);
  Relay relay;
  relay.graph_port = graph->port();
  WebServer::Options fo;
  fo.port = 0;
  fo.admit = [](std::string_view token, std::string_view) -> std::variant<Admission, Refusal> {
    if (token == kToken) return Admission{Role::kSubject, "P01"};
    return Refusal{404, "unknown link\n"};
  };
  fo.endpoints = {WebServer::Endpoint{"/ws", {}, &relay, {Role::kSubject}, false}};
  auto front = WebServer::Start(fo);
  ASSERT_TRUE(front.ok()) << front.status().ToString();
  relay.front = front->get();

  Inbox page;
  auto client = WsClient::Connect("127.0.0.1", (*front)->port(), "/ws?token=" + kToken, page.Callbacks(), seconds(5));
  ASSERT_TRUE(client.ok()) << client.status().ToString();
  EXPECT_EQ(page.Next(), "hello") << "the graph's first frame, relayed";
  for (int i = 0; i < 50; ++i) ASSERT_TRUE((*client)->SendText("p" + std::to_string(i)).ok());
  for (int i = 0; i < 50; ++i) ASSERT_EQ(page.Next(), "echo:p" + std::to_string(i)) << "in order, both ways";
  (*client)->Close();
  EXPECT_TRUE(Eventually([&] { return graph_handler.closes == 1; })) << "the page leaving ends the upstream";

  Inbox second;
  client = WsClient::Connect("127.0.0.1", (*front)->port(), "/ws?token=" + kToken, second.Callbacks(), seconds(5));
  ASSERT_TRUE(client.ok()) << client.status().ToString();
  ASSERT_EQ(second.Next(), "hello");
  graph->Close(graph_handler.Last(), 1001, "the trial ended");
  EXPECT_TRUE(second.WaitClosed()) << "the graph leaving ends the page's link";
  EXPECT_TRUE(Eventually([&] {
    std::lock_guard<std::mutex> lock(relay.mutex);
    return relay.upstream.empty();
  }));
  std::lock_guard<std::mutex> lock(relay.mutex);
  EXPECT_TRUE(relay.errors.empty()) << relay.errors.front();
}

}  // namespace
}  // namespace dyad::web
