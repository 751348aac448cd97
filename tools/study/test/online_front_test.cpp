// The participants' side of `dyad study serve` (online_front.hpp) on a real web server, without a
// graph: the ClientHandler calls only queue the page's event (civetweb's 100 KB worker stacks
// overflowed under ASan when OnOpen read the session log there), and the front's own thread does
// the work. The session log is made a FIFO that no one writes, so any read of it blocks: the
// calls must return all the same, and the page hears its phase once the test lets the read end.
// Also: the queue's 1 MiB per page, the overview's stop freeing a place, and the relay's 100 ms
// write limit (a python stand-in for the trial's graph that reads nothing). The scripted pages
// of serve_test.sh cover the rest (a link open twice, max_sessions, trials of a real graph).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "online_front.hpp"
#include "online_study_fixture.hpp"
#include "overview_channel.hpp"
#include "study_session.hpp"
#include "web_server.hpp"
#include "ws_client.hpp"

namespace dyad::study {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using namespace std::chrono_literals;

// Long enough never to be reached by a call that returns at once; reached only on a failure.
constexpr auto kGuard = 10s;

// The server's own handler of the pages' endpoint: it only notes who connected, so that the test
// calls the front's handler itself, on its own thread.
class Pages final : public web::ClientHandler {
 public:
  void OnOpen(web::ClientId client, web::Role) override {
    std::lock_guard<std::mutex> lock(mutex_);
    opened_.push_back(client);
    cv_.notify_all();
  }
  Status OnText(web::ClientId, std::string_view) override { return Status::OK(); }
  Status OnBinary(web::ClientId, std::span<const uint8_t>) override { return Status::OK(); }
  void OnClose(web::ClientId) override {}
  web::ClientId Opened(size_t n) {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait_for(lock, kGuard, [&] { return opened_.size() >= n; });
    return opened_.size() >= n ? opened_[n - 1] : 0;
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<web::ClientId> opened_;
};

// A participant's page: the frames the front sent it.
struct Page {
  std::mutex mutex;
  std::condition_variable cv;
  std::vector<Json> frames;
  bool closed = false;  // by the server
  std::unique_ptr<web::WsClient> ws;
  // The op of the frame n (1-based), or "" when none came.
  std::string Op(size_t n) {
    std::unique_lock<std::mutex> lock(mutex);
    cv.wait_for(lock, kGuard, [&] { return frames.size() >= n; });
    return frames.size() >= n ? frames[n - 1].value("op", "") : "";
  }
  size_t count() {
    std::lock_guard<std::mutex> lock(mutex);
    return frames.size();
  }
  bool Closed() {
    std::unique_lock<std::mutex> lock(mutex);
    cv.wait_for(lock, kGuard, [&] { return closed; });
    return closed;
  }
};

class OnlineFrontTest : public testing::OnlineStudyTest {
 protected:
  OnlineFrontTest() : OnlineStudyTest("dyad_online_front_") {}
  void SetUp() override {
    OnlineStudyTest::SetUp();
    web::WebServer::Options o;
    o.port = 0;
    o.admit = [](std::string_view token, std::string_view) -> std::variant<web::Admission, web::Refusal> {
      return web::Admission{web::Role::kSubject, std::string(token)};
    };
    o.endpoints.push_back(web::WebServer::Endpoint{"/subject/ws", {}, &pages_, {web::Role::kSubject}, false});
    auto server = web::WebServer::Start(o);
    ASSERT_TRUE(server.ok()) << server.status().ToString();
    server_ = std::move(*server);
    log_ = SessionLogPath(study_, "P01");
    fs::create_directories(fs::path(log_).parent_path());
    fs::permissions(fs::path(log_).parent_path(), fs::perms::owner_all);
    fifo_ = (dir_ / "log.fifo").string();
    ASSERT_EQ(mkfifo(fifo_.c_str(), 0600), 0);
  }
  void TearDown() override {
    server_.reset();
    OnlineStudyTest::TearDown();
  }
  // `participant`'s page connected to the server; its client id.
  web::ClientId Connect(Page& page, const std::string& participant = "P01") {
    web::WsClient::Callbacks cb;
    cb.on_text = [&page](std::string_view text) {
      std::lock_guard<std::mutex> lock(page.mutex);
      page.frames.push_back(Json::parse(text));
      page.cv.notify_all();
    };
    cb.on_close = [&page] {
      std::lock_guard<std::mutex> lock(page.mutex);
      page.closed = true;
      page.cv.notify_all();
    };
    auto ws = web::WsClient::Connect("127.0.0.1", server_->port(), "/subject/ws?token=" + participant, std::move(cb), 2s);
    EXPECT_TRUE(ws.ok()) << ws.status().ToString();
    if (ws.ok()) page.ws = std::move(*ws);
    return pages_.Opened(++connected_);
  }
  // P01's session log becomes the FIFO (its text kept aside): reading it blocks.
  void BlockTheLog() {
    if (fs::exists(log_)) fs::rename(log_, log_ + ".kept");
    else std::ofstream(log_ + ".kept").close();
    fs::create_hard_link(fifo_, log_);
  }
  // Once a reader has opened the FIFO (the front's thread reading the log): a writer's end of
  // it, held open so that the reader waits for its text (-1: no reader came).
  int Reader() {
    for (auto until = std::chrono::steady_clock::now() + kGuard; std::chrono::steady_clock::now() < until;) {
      if (const int fd = ::open(fifo_.c_str(), O_WRONLY | O_NONBLOCK); fd >= 0) return fd;
      std::this_thread::sleep_for(10ms);
    }
    return -1;
  }
  // The log back, and a read blocked on the FIFO let through (it reads the kept text: through
  // `writer` from Reader(), else each reader that comes), until `done` (the front has gone on).
  void UnblockTheLog(const std::function<bool()>& done, int writer = -1) {
    std::ifstream in(log_ + ".kept");
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    fs::rename(log_ + ".kept", log_);
    if (writer >= 0) {
      EXPECT_EQ(::write(writer, text.data(), text.size()), static_cast<ssize_t>(text.size()));
      ::close(writer);
    }
    for (auto until = std::chrono::steady_clock::now() + kGuard; !done() && std::chrono::steady_clock::now() < until;) {
      if (const int fd = ::open(fifo_.c_str(), O_WRONLY | O_NONBLOCK); fd >= 0) {  // a reader waits on it
        EXPECT_EQ(::write(fd, text.data(), text.size()), static_cast<ssize_t>(text.size()));
        ::close(fd);
      }
      std::this_thread::sleep_for(10ms);
    }
  }

  // kFakeGraph (below) as the dyad the front starts trials with, written beside the test, and
  // `participant` ready for a trial (consented, a subject token); the script's path.
  std::string UseFakeGraph(const std::string& participant = "P01");
  // The front's P01 taken to a trial: their page `waiting` opened and Ready, then (closed with
  // 1012 when the trial starts) their page `trial` opened; its client id (0: it went otherwise).
  web::ClientId StartTrial(OnlineFront& front, Page& waiting, Page& trial) {
    const web::ClientId first = Connect(waiting);
    front.OnOpen(first, web::Role::kSubject);
    if (waiting.Op(1) != "waiting" || !front.OnText(first, R"({"op":"ready"})").ok()) return 0;
    if (!waiting.Closed()) return 0;  // the trial starts: its page is closed (1012) and comes back
    const web::ClientId page = Connect(trial);
    front.OnOpen(page, web::Role::kSubject);
    return page;
  }

  Pages pages_;
  std::unique_ptr<web::WebServer> server_;
  std::string log_, fifo_;
  size_t connected_ = 0;
};

TEST_F(OnlineFrontTest, ThePageHandlerOnlyQueuesTheLogIsReadOnTheFrontsOwnThread) {
  OnlineFront front(study_, FrontOptions{"dyad", 2});
  front.SetServer(server_.get());
  Page page;
  const web::ClientId client = Connect(page);
  ASSERT_NE(client, 0u);

  BlockTheLog();
  auto open = std::async(std::launch::async, [&] { front.OnOpen(client, web::Role::kSubject); });
  const bool open_returned = open.wait_for(kGuard) == std::future_status::ready;
  EXPECT_TRUE(open_returned) << "OnOpen waited for the session log: it read it on the web server's thread";
  EXPECT_EQ(page.count(), 0u) << "the page's phase comes from the log, which no one could read yet";
  UnblockTheLog([&] { return page.count() > 0; });
  EXPECT_EQ(page.Op(1), "consent") << "the front's thread read the log once it could";

  BlockTheLog();
  auto text = std::async(std::launch::async, [&] { return front.OnText(client, R"({"op":"consent","agree":true})"); });
  const bool text_returned = text.wait_for(kGuard) == std::future_status::ready;
  EXPECT_TRUE(text_returned) << "OnText waited for the session log: it read it on the web server's thread";
  UnblockTheLog([&] { return page.count() > 1; });
  EXPECT_TRUE(text.get().ok());
  EXPECT_EQ(page.Op(2), "waiting") << "the consent marked, the page is offered trial 1";
  EXPECT_TRUE(ReadSession(study_, "P01").consent);
  EXPECT_TRUE(open_returned && text_returned);
  front.OnClose(client);
  front.StopAll();
}

TEST_F(OnlineFrontTest, APageClosedWhileItsOpenIsQueuedTakesNothingAndStopAllClosesAQueuedOne) {
  OnlineFront front(study_, FrontOptions{"dyad", 2});
  front.SetServer(server_.get());
  Page first, gone, last;
  const web::ClientId p01 = Connect(first), p02 = Connect(gone, "P02");
  ASSERT_NE(p02, 0u);
  BlockTheLog();
  // The front's thread reads P01's log (blocked there) while P02's page opens and closes, then
  // opens again and the front is stopped: each call returns, none waits for the front's thread.
  auto calls = std::async(std::launch::async, [&] {
    front.OnOpen(p01, web::Role::kSubject);
    front.OnOpen(p02, web::Role::kSubject);
    front.OnClose(p02);
  });
  const bool returned = calls.wait_for(kGuard) == std::future_status::ready;
  EXPECT_TRUE(returned) << "the page handler waited for the session log";
  const int writer = Reader();  // the front's thread is in P01's log: P02's next open stays queued
  EXPECT_GE(writer, 0) << "no one read P01's log";
  const web::ClientId again = Connect(last, "P02");
  auto stop = std::async(std::launch::async, [&] {
    front.OnOpen(again, web::Role::kSubject);
    front.StopAll();
  });
  EXPECT_TRUE(last.Closed()) << "a page whose open was queued at StopAll is closed, at once";
  UnblockTheLog([&] { return calls.wait_for(0s) == std::future_status::ready && stop.wait_for(0s) == std::future_status::ready; },
                writer);
  ASSERT_EQ(stop.wait_for(kGuard), std::future_status::ready) << "StopAll did not return";
  EXPECT_EQ(first.Op(1), "consent") << "P01's open, handled once the log could be read";
  EXPECT_EQ(front.live(OnlineFront::Clock::now()), 1) << "P02's page closed before its open was handled: no session";
  EXPECT_TRUE(SessionLock::Acquire(study_, "P02").ok()) << "P02's session lock was taken for a page already gone";
  EXPECT_EQ(last.count(), 0u) << "and told nothing: its open was not handled";
  EXPECT_EQ(gone.count(), 0u);
}

TEST_F(OnlineFrontTest, APageWhoseFramesQueueUpPastOneMiBIsRefusedTheNextOne) {
  OnlineFront front(study_, FrontOptions{"dyad", 2});
  front.SetServer(server_.get());
  Page page;
  const web::ClientId client = Connect(page);
  BlockTheLog();
  auto open = std::async(std::launch::async, [&] { front.OnOpen(client, web::Role::kSubject); });
  EXPECT_EQ(open.wait_for(kGuard), std::future_status::ready) << "OnOpen waited for the session log";
  const int writer = Reader();  // the front's thread is held in the log: the frames queue up
  ASSERT_GE(writer, 0) << "no one read P01's log";
  const std::string frame(16 << 10, 'x');  // the front's largest frame (16 KiB)
  for (int i = 0; i < 64; ++i) ASSERT_TRUE(front.OnText(client, frame).ok()) << "frame " << i + 1 << ": 1 MiB may wait";
  const Status over = front.OnText(client, frame);
  EXPECT_EQ(over.code(), Status::Code::kFailedPrecondition) << "the server closes the page with this (1008)";
  EXPECT_NE(over.message().find("more than the study's server could take"), std::string::npos) << over.message();
  UnblockTheLog([&] { return page.count() > 0; }, writer);
  EXPECT_EQ(page.Op(1), "consent") << "what was queued before is handled";
  front.StopAll();
}

// A trial's "graph" for the front's relay, run in place of dyad with the trial's arguments (which
// it writes into a file "args" beside the port file, one a line). It exits (0) on a file "end"
// there, or waits for a file "go" beside the port file the front names
// (web.port_file), binds a loopback port and writes it there, answers the relay's WebSocket handshake and leaves a mark
// "connected" beside it. Then, with a file "stuck" there, it reads nothing (a graph stuck; its receive buffer small) until its
// SIGINT; else it writes each text frame it reads, one a line, into "relayed".
constexpr const char* kFakeGraph = R"(#!/usr/bin/env python3
import base64, hashlib, os, signal, socket, sys, time
signal.signal(signal.SIGINT, lambda *_: os._exit(0))
port_file = next(a.split("port_file=", 1)[1] for a in sys.argv if ".port_file=" in a).strip(chr(39) + chr(34))  # unquoted
here = os.path.dirname(port_file)
with open(os.path.join(here, "args"), "w") as f:
    f.write("\n".join(sys.argv[1:]) + "\n")
while not os.path.exists(os.path.join(here, "go")):
    if os.path.exists(os.path.join(here, "end")):
        sys.exit(0)
    time.sleep(0.01)
stuck = os.path.exists(os.path.join(here, "stuck"))
s = socket.socket()
if stuck:
    s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
s.bind(("127.0.0.1", 0))
s.listen(1)
with open(port_file, "w") as f:
    f.write("%d\n" % s.getsockname()[1])
c, _ = s.accept()
request = b""
while b"\r\n\r\n" not in request:
    request += c.recv(1)
key = [l.split(b":", 1)[1].strip() for l in request.split(b"\r\n") if l.lower().startswith(b"sec-websocket-key:")][0]
accept = base64.b64encode(hashlib.sha1(key + b"258EAFA5-E914-47DA-95CA-C5AB0DC85B11").digest())
c.sendall(b"HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Accept: " + accept + b"\r\n\r\n")
open(os.path.join(here, "connected"), "w").close()
while stuck:
    signal.pause()
def read(n):
    data = b""
    while len(data) < n:
        chunk = c.recv(n - len(data))
        if not chunk:
            signal.pause()
        data += chunk
    return data
while True:
    head = read(2)
    n = head[1] & 127
    if n == 126:
        n = int.from_bytes(read(2), "big")
    mask = read(4)
    data = bytes(b ^ mask[i % 4] for i, b in enumerate(read(n)))
    if head[0] & 15 == 1:
        with open(os.path.join(here, "relayed"), "a") as f:
            f.write(data.decode() + "\n")
)";

std::string OnlineFrontTest::UseFakeGraph(const std::string& participant) {
  const std::string graph = (dir_ / "fake_graph.py").string();
  std::ofstream(graph) << kFakeGraph;
  fs::permissions(graph, fs::perms::owner_all);
  study_.subject_web = "web";
  EXPECT_TRUE(MarkConsent(study_, participant, "in the test").ok());
  const fs::path tokens = fs::path(study_.data) / participant / "web-tokens";
  std::ofstream(tokens) << "subject 0123456789abcdef0123456789abcdef\n";
  fs::permissions(tokens, fs::perms::owner_read | fs::perms::owner_write);
  return graph;
}

// Whether `done` came true within `limit` (looked at every 10 ms).
bool Within(std::chrono::milliseconds limit, const std::function<bool()>& done) {
  for (const auto until = std::chrono::steady_clock::now() + limit; !done();) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(10ms);
  }
  return true;
}

TEST_F(OnlineFrontTest, AFrameTheTrialsGraphDoesNotTakeDropsThePagesRelayNotTheTrial) {
  OnlineFront front(study_, FrontOptions{UseFakeGraph(), 2, 15});
  front.SetServer(server_.get());
  const fs::path here = fs::path(study_.data) / "P01";
  std::ofstream(here / "stuck").close();
  std::ofstream(here / "go").close();
  Page waiting, trial;
  const web::ClientId second = StartTrial(front, waiting, trial);
  ASSERT_NE(second, 0u) << "the trial did not start";
  ASSERT_TRUE(Within(kGuard, [&] { return fs::exists(here / "connected"); }))
      << "the page was never relayed to the trial's graph";
  // The page's frames, until the graph's socket is full: a write that waits past 100 ms drops the
  // relay and closes the page (it reconnects), rather than holding the front's one thread.
  const std::string frame(16 << 10, 'x');
  size_t sent = 0;
  for (int i = 0; i < 4096 && trial.count() == 0; ++i) {
    if (front.OnText(second, frame).ok()) ++sent;
    else std::this_thread::sleep_for(1ms);  // 1 MiB waits for the front's thread: it is behind
    std::lock_guard<std::mutex> lock(trial.mutex);
    if (trial.closed) break;
  }
  EXPECT_TRUE(trial.Closed()) << "the page was not closed after " << sent << " frames of 16 KiB that its graph did not read";
  EXPECT_EQ(front.running(), 1) << "the trial goes on (the page reconnects to it)";
  front.StopAll();  // the graph's SIGINT
  EXPECT_EQ(front.running(), 0);
}

// The lines the recording graph has written (none yet: empty).
std::vector<std::string> Relayed(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// During a trial a page's frames go to its graph from the thread that read them, and keep their
// order: a frame that came before the relay was up waits for the front's one thread, and the
// frames after it wait behind it, even once the relay is up; a pong (the front's own, never
// relayed) holds nothing back. The front's thread is held meanwhile by another page: P02's
// session log, a FIFO that no one writes.
TEST_F(OnlineFrontTest, ATrialsFramesAreRelayedAtOnceAndInOrderWhileTheFrontsThreadIsHeld) {
  OnlineFront front(study_, FrontOptions{UseFakeGraph(), 2, 15});
  front.SetServer(server_.get());
  const fs::path here = fs::path(study_.data) / "P01";
  Page waiting, trial, other, again;
  const web::ClientId page = StartTrial(front, waiting, trial);  // its relay starts (the graph waits for "go")
  ASSERT_NE(page, 0u) << "the trial did not start";

  const std::string log02 = SessionLogPath(study_, "P02");
  fs::create_directories(fs::path(log02).parent_path());
  fs::create_hard_link(fifo_, log02);
  const web::ClientId p02 = Connect(other, "P02");
  front.OnOpen(p02, web::Role::kSubject);
  int writer = Reader();
  ASSERT_GE(writer, 0) << "the front's thread did not read P02's log";
  const std::string f1 = R"({"op":"pointer","x":1,"y":2,"engaged":true,"wall":1})";
  const std::string f2 = R"({"op":"pointer","x":3,"y":4,"engaged":false,"wall":2})";
  const std::string f3 = R"({"op":"pointer","x":5,"y":6,"engaged":true,"wall":3})";
  ASSERT_TRUE(front.OnText(page, f1).ok());  // no relay yet: queued for the front's thread
  std::ofstream(here / "go").close();
  ASSERT_TRUE(Within(kGuard, [&] { return fs::exists(here / "connected"); })) << "the relay never reached the graph";
  std::this_thread::sleep_for(200ms);  // the relay's thread stores its link
  ASSERT_TRUE(front.OnText(page, f2).ok());
  std::this_thread::sleep_for(300ms);
  EXPECT_TRUE(Relayed(here / "relayed").empty()) << "a frame overtook its page's earlier one, which waits for the front's thread";
  fs::remove(log02);
  std::ofstream(log02).close();
  ASSERT_EQ(::close(writer), 0);  // P02's read ends (an empty log): the front's thread goes on
  Within(kGuard, [&] { return Relayed(here / "relayed").size() >= 2; });
  EXPECT_EQ(Relayed(here / "relayed"), (std::vector<std::string>{f1, f2})) << "the front's thread relays both, in order";

  // The front's thread held again (P02's page closed and opened again: its log read again).
  front.OnClose(p02);
  fs::remove(log02);
  fs::create_hard_link(fifo_, log02);
  front.OnOpen(Connect(again, "P02"), web::Role::kSubject);
  writer = Reader();
  ASSERT_GE(writer, 0) << "the front's thread did not read P02's log again";
  ASSERT_TRUE(front.OnText(page, R"({"op":"pong","id":1})").ok());
  ASSERT_TRUE(front.OnText(page, f3).ok());
  Within(2s, [&] { return Relayed(here / "relayed").size() >= 3; });
  EXPECT_EQ(Relayed(here / "relayed"), (std::vector<std::string>{f1, f2, f3}))
      << "a trial's frame waited for the front's thread (held by another page; the page's own pong queued)";
  fs::remove(log02);
  std::ofstream(log02).close();
  ::close(writer);
  front.StopAll();
}

TEST_F(OnlineFrontTest, StoppingASessionBetweenTrialsFreesItsPlaceAtOnce) {
  OnlineFront front(study_, FrontOptions{"dyad", 1});  // max_sessions 1
  front.SetServer(server_.get());
  Page p01, early, p02;
  front.OnOpen(Connect(p01), web::Role::kSubject);
  EXPECT_EQ(p01.Op(1), "consent");
  front.OnOpen(Connect(early, "P02"), web::Role::kSubject);
  EXPECT_EQ(early.Op(1), "refused");
  EXPECT_NE(early.frames.at(0).value("message", "").find("Please come back later"), std::string::npos) << early.frames[0];
  EXPECT_TRUE(early.Closed());

  ASSERT_TRUE(front.StopSession("P01", "the participant asked to stop").ok());
  EXPECT_EQ(p01.Op(2), "refused") << "P01's page is told the session has ended";
  EXPECT_TRUE(p01.Closed());
  EXPECT_EQ(front.live(OnlineFront::Clock::now()), 0) << "P01's place is free at once, not reconnect_s later";
  front.OnOpen(Connect(p02, "P02"), web::Role::kSubject);
  EXPECT_EQ(p02.Op(1), "consent") << "P02 is let in";
  front.StopAll();
}

// Each running trial's graph is started on a domain of its own (FrontOptions::domains), given back
// once its graph has exited and taken again last: with two domains, P01's first trial runs on 40,
// its next on 41 (40, given back just now, waits its turn), and P02's then on 40 again.
TEST_F(OnlineFrontTest, EachRunningTrialGetsADomainOfItsOwnGivenBackWhenItsGraphExits) {
  FrontOptions o{UseFakeGraph(), 2, 15};
  UseFakeGraph("P02");
  o.domains = DomainRange{40, 41};
  OnlineFront front(study_, o);
  front.SetServer(server_.get());
  const fs::path p01 = fs::path(study_.data) / "P01", p02 = fs::path(study_.data) / "P02";
  // The domain_id the graph started for `here` was given ("" if none started within kGuard).
  const auto domain_of = [](const fs::path& here) -> std::string {
    Within(kGuard, [&] { return Relayed(here / "args").size() > 2; });
    for (const std::string& a : Relayed(here / "args"))
      if (a.rfind("domain_id=", 0) == 0) return a.substr(10);
    return "";
  };
  // Ends the graph running for `here` (it exits on "end") and waits until the front saw it end.
  const auto end = [&front](const fs::path& here) {
    std::ofstream(here / "end").close();
    const bool ended = Within(kGuard, [&] { return front.running() == 0; });
    fs::remove(here / "end");
    fs::remove(here / "args");
    return ended;
  };
  Page waiting, trial, waiting_again, trial_again, other;
  ASSERT_NE(StartTrial(front, waiting, trial), 0u) << "P01's first trial did not start";
  EXPECT_EQ(domain_of(p01), "40");
  const auto views = front.Snapshot(OnlineFront::Clock::now());
  ASSERT_EQ(views.size(), 1u);
  EXPECT_EQ(views[0].domain, 40) << "the overview shows the trial's domain";
  OverviewChannel overview(study_, &front, 2);
  const auto state_now = [&overview] { return nlohmann::json::parse(overview.State(OnlineFront::Clock::now())); };
  EXPECT_EQ(state_now()["sessions"][0]["domain"], 40) << "the overview's state gives it (for dyad echo --domain)";
  ASSERT_TRUE(end(p01)) << "P01's graph did not end";
  EXPECT_TRUE(state_now()["sessions"][0]["domain"].is_null()) << "no trial running, no domain: " << state_now().dump();

  ASSERT_NE(StartTrial(front, waiting_again, trial_again), 0u) << "P01's next trial did not start";
  EXPECT_EQ(domain_of(p01), "41") << "40, given back just now, is taken after 41";
  ASSERT_TRUE(end(p01)) << "P01's graph did not end";

  const web::ClientId page = Connect(other, "P02");
  front.OnOpen(page, web::Role::kSubject);
  ASSERT_EQ(other.Op(1), "waiting");
  ASSERT_TRUE(front.OnText(page, R"({"op":"ready"})").ok());
  EXPECT_EQ(domain_of(p02), "40") << "a domain given back is taken again";
  front.StopAll();
}

}  // namespace
}  // namespace dyad::study
