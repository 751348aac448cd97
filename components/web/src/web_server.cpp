#include "web_server.hpp"

#include <arpa/inet.h>
#include <civetweb.h>
#include <dirent.h>
#include <dlfcn.h>
#include <ifaddrs.h>
#include <net/if.h>
#include <openssl/crypto.h>
#include <pthread.h>
#include <sched.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <cstring>
#include <filesystem>
#include <random>

namespace dyad::web {

std::string RandomToken() {
  std::random_device rd;
  static const char* hex = "0123456789abcdef";
  std::string t;
  for (int i = 0; i < 32; ++i) t.push_back(hex[rd() % 16]);
  return t;
}

namespace {

constexpr int kCloseTooBig = 1009, kCloseUnsupported = 1003, kClosePolicy = 1008;

// Writes a close frame (code + reason) directly; the connection closes when the data handler
// returns 0.
void WriteClose(mg_connection* conn, int code, const std::string& reason) {
  std::string payload;
  payload.push_back(static_cast<char>((code >> 8) & 0xff));
  payload.push_back(static_cast<char>(code & 0xff));
  payload.append(reason.substr(0, 120));  // a close frame's payload is at most 125 bytes
  mg_websocket_write(conn, MG_WEBSOCKET_OPCODE_CONNECTION_CLOSE, payload.data(), payload.size());
}

// Writes a response whole, its head and body in one mg_write. Not mg_printf: it formats into an
// 8 KB buffer on the stack (civetweb's MG_BUF_LEN), and this runs on a worker whose 100 KB stack
// an OpenSSL 3 SSL_write nearly fills (web_server.hpp, "Stacks").
void WriteWhole(mg_connection* conn, std::string head, const std::string& body) {
  head.append(body);
  mg_write(conn, head.data(), head.size());
}

// Writes a whole plain-text HTTP response (mg_send_http_error crashes in libcivetweb 1.15
// without a document_root) and returns its status.
int WriteResponse(mg_connection* conn, int status, const char* reason, const std::string& text) {
  WriteWhole(conn,
             "HTTP/1.1 " + std::to_string(status) + " " + reason +
                 "\r\nContent-Type: text/plain; charset=utf-8\r\nContent-Length: " + std::to_string(text.size()) +
                 "\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n",
             text);
  return status;
}

// The reason phrase of an HTTP status a Refusal may carry.
const char* ReasonPhrase(int status) {
  switch (status) {
    case 400:
      return "Bad Request";
    case 401:
      return "Unauthorized";
    case 403:
      return "Forbidden";
    case 404:
      return "Not Found";
    case 409:
      return "Conflict";
    case 410:
      return "Gone";
    case 429:
      return "Too Many Requests";
    case 500:
      return "Internal Server Error";
    case 503:
      return "Service Unavailable";
  }
  return "Refused";
}

// The address of a socket's end as "ip" and port.
bool AddressOf(const sockaddr_storage& a, std::string* ip, int* port) {
  char text[INET6_ADDRSTRLEN] = {0};
  if (a.ss_family == AF_INET) {
    const auto* in = reinterpret_cast<const sockaddr_in*>(&a);
    inet_ntop(AF_INET, &in->sin_addr, text, sizeof(text));
    *port = ntohs(in->sin_port);
  } else if (a.ss_family == AF_INET6) {
    const auto* in6 = reinterpret_cast<const sockaddr_in6*>(&a);
    inet_ntop(AF_INET6, &in6->sin6_addr, text, sizeof(text));
    *port = ntohs(in6->sin6_port);
  } else {
    return false;
  }
  *ip = text;
  return true;
}

// Shuts down this process's socket of the TCP connection from `peer_ip`:`peer_port` to our
// `local_port` (civetweb has no call that closes a server connection from another thread; the
// worker reading it then sees the end and closes it the normal way). One scan of our fds.
void ShutdownConnection(const std::string& peer_ip, int peer_port, int local_port) {
  DIR* dir = opendir("/proc/self/fd");
  if (dir == nullptr) return;
  while (dirent* e = readdir(dir)) {
    char* end = nullptr;
    const long fd = std::strtol(e->d_name, &end, 10);
    if (end == e->d_name || *end != '\0' || fd == dirfd(dir)) continue;
    sockaddr_storage peer{}, local{};
    socklen_t peer_len = sizeof(peer), local_len = sizeof(local);
    if (getpeername(static_cast<int>(fd), reinterpret_cast<sockaddr*>(&peer), &peer_len) != 0 ||
        getsockname(static_cast<int>(fd), reinterpret_cast<sockaddr*>(&local), &local_len) != 0)
      continue;
    std::string ip, unused;
    int port = 0, lport = 0;
    if (!AddressOf(peer, &ip, &port) || !AddressOf(local, &unused, &lport)) continue;
    if (port == peer_port && lport == local_port && ip == peer_ip) {
      shutdown(static_cast<int>(fd), SHUT_RDWR);
      break;
    }
  }
  closedir(dir);
}

// Makes civetweb's TLS usable with OpenSSL 3 (see the header): loads libdyad_civetweb_ssl.so,
// found next to the code that holds this function (the web plugin) or where it was built.
Status LoadCivetwebSslShim() {
  static const Status loaded = [] {
    std::vector<std::string> candidates;
    Dl_info info{};
    if (dladdr(reinterpret_cast<void*>(&LoadCivetwebSslShim), &info) != 0 && info.dli_fname != nullptr)
      candidates.push_back((std::filesystem::path(info.dli_fname).parent_path() / "web" / "libdyad_civetweb_ssl.so").string());
    candidates.push_back(DYAD_CIVETWEB_SSL_SHIM);
    std::string tried;
    for (const auto& path : candidates) {
      if (dlopen(path.c_str(), RTLD_NOW | RTLD_GLOBAL) != nullptr) {
        if ((mg_init_library(MG_FEATURES_TLS | MG_FEATURES_WEBSOCKET) & MG_FEATURES_TLS) == 0)
          return Status::IOError("TLS: civetweb could not load OpenSSL (libssl.so; install libssl-dev)");
        return Status::OK();
      }
      tried += (tried.empty() ? "" : ", ") + path;
    }
    return Status::IOError("TLS: cannot load libdyad_civetweb_ssl.so (tried " + tried + ")");
  }();
  return loaded;
}

thread_local std::string* start_log = nullptr;  // civetweb's messages while mg_start runs

std::string QueryValue(const char* query, const std::string& key) {
  if (query == nullptr) return "";
  char buf[512];
  const int n = mg_get_var(query, std::strlen(query), key.c_str(), buf, sizeof(buf));
  return n >= 0 ? std::string(buf, static_cast<size_t>(n)) : "";
}

}  // namespace

const char* RoleName(Role role) {
  switch (role) {
    case Role::kViewer: return "viewer";
    case Role::kSubject: return "subject";
    case Role::kExperimenter: return "experimenter";
  }
  return "?";
}

bool TokenMatches(std::string_view given, std::string_view expected) {
  if (expected.empty() || given.size() != expected.size()) return false;
  return CRYPTO_memcmp(given.data(), expected.data(), expected.size()) == 0;
}

std::vector<std::string> UrlHosts(const std::string& address) {
  if (address != "0.0.0.0" && address != "::" && address != "[::]")
    return {address.find(':') != std::string::npos ? "[" + address + "]" : address};
  std::vector<std::string> hosts;
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) == 0) {
    for (ifaddrs* i = list; i != nullptr; i = i->ifa_next) {
      if (i->ifa_addr == nullptr || i->ifa_addr->sa_family != AF_INET || (i->ifa_flags & IFF_LOOPBACK) ||
          !(i->ifa_flags & IFF_UP))
        continue;
      char text[INET_ADDRSTRLEN] = {0};
      inet_ntop(AF_INET, &reinterpret_cast<sockaddr_in*>(i->ifa_addr)->sin_addr, text, sizeof(text));
      hosts.push_back(text);
    }
    freeifaddrs(list);
  }
  if (hosts.empty()) hosts.push_back("127.0.0.1");
  return hosts;
}

bool IsLoopback(const std::string& address) {
  return address.rfind("127.", 0) == 0 || address == "localhost" || address == "::1";
}

// civetweb's worker threads have small stacks (an ASan build overflowed one parsing a small JSON
// message): client messages are handled on this thread of ours, with a normal stack, one at a
// time, while the worker waits. Each waiting worker is woken by its own task's end only: with one
// condition variable for all, every task's end woke every worker waiting (a study server's dozens
// of pages: a wake-up of each per frame, and the frames' latency grew with their number).
class WebServer::HandlerThread {
 public:
  HandlerThread() : thread_([this] { Loop(); }) {}
  ~HandlerThread() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    work_.notify_one();
    thread_.join();
  }
  // Runs `task` on the handler thread and returns when it is done.
  void Run(const std::function<void()>& task) {
    Pending pending;
    pending.task = &task;
    std::unique_lock<std::mutex> lock(mutex_);
    tasks_.push_back(&pending);
    work_.notify_one();
    pending.ended.wait(lock, [&] { return pending.done; });
  }

 private:
  struct Pending {
    const std::function<void()>* task = nullptr;
    bool done = false;
    std::condition_variable ended;
  };
  void Loop() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      work_.wait(lock, [&] { return stop_ || !tasks_.empty(); });
      if (tasks_.empty()) return;  // stop_ and nothing left
      Pending* pending = tasks_.front();
      tasks_.pop_front();
      lock.unlock();
      (*pending->task)();
      lock.lock();
      pending->done = true;
      pending->ended.notify_one();  // under the lock: the waiter cannot leave (and free it) first
    }
  }
  std::mutex mutex_;
  std::condition_variable work_;
  std::deque<Pending*> tasks_;
  bool stop_ = false;
  std::thread thread_;
};

struct WebServer::EndpointState {
  WebServer* server = nullptr;
  ClientHandler* handler = nullptr;
  bool viewers = true;
  bool handler_only_queues = false;
  std::set<Role> roles;
  std::vector<const char*> protocol_ptrs;
  mg_websocket_subprotocols protocols{};
};

struct WebServer::Client {
  ClientId id = 0;
  mg_connection* conn = nullptr;
  Admission admission;
  std::string remote_address;
  SendQueue queue;
  std::mutex write_mutex;  // held while writing; closing takes it, so no write outlives the connection
  bool closed = false;
  // Close(): the close frame the sender writes after the queued frames.
  std::mutex close_mutex;  // guards the three below
  bool closing = false;
  int close_code = 1000;
  std::string close_reason;
  std::thread sender;
  Client(size_t limit, std::chrono::steady_clock::duration flush_interval) : queue(limit, flush_interval) {}
};

StatusOr<std::unique_ptr<WebServer>> WebServer::Start(const Options& options) {
  if (options.tokens.empty() && !options.admit)
    return Status::InvalidArgument("web server: no token for any role (every client needs one)");
  for (const auto& [role, token] : options.tokens) {
    if (token.empty()) return Status::InvalidArgument(std::string("web server: the ") + RoleName(role) + "'s token is empty");
    for (const auto& [other, other_token] : options.tokens)
      if (other < role && token == other_token)
        return Status::InvalidArgument(std::string("web server: the ") + RoleName(role) + " and the " + RoleName(other) +
                                       " have the same token (a token must say its role)");
  }
  const bool tls = !options.tls_certificate.empty();
  if (tls) {
    if (Status st = LoadCivetwebSslShim(); !st.ok()) return st;
  } else {
    mg_init_library(MG_FEATURES_WEBSOCKET);
  }
  std::unique_ptr<WebServer> s(new WebServer());
  s->options_ = options;
  s->handler_thread_ = std::make_unique<HandlerThread>();
  const std::string ports = (options.address.find(':') != std::string::npos ? "[" + options.address + "]" : options.address) +
                            ":" + std::to_string(options.port) + (tls ? "s" : "");
  const std::string threads = std::to_string(options.max_clients + 4);
  const std::string timeout = std::to_string(options.write_timeout_ms);
  std::vector<const char*> opts = {"listening_ports", ports.c_str(), "num_threads", threads.c_str(), "request_timeout_ms",
                                   timeout.c_str(), "websocket_timeout_ms", "3600000",
                                   // Small frames (pointer samples, acks) go out at once, not after Nagle's 40 ms.
                                   "tcp_nodelay", "1"};
  if (tls) {
    // TLS 1.2 and later only (4); the browsers' own defaults for the rest.
    for (const char* o : {"ssl_certificate", options.tls_certificate.c_str(), "ssl_protocol_version", "4"}) opts.push_back(o);
  }
  opts.push_back(nullptr);
  mg_callbacks callbacks{};
  // No stderr noise per client; what goes wrong while starting is kept for the error.
  callbacks.log_message = [](const mg_connection*, const char* message) {
    if (start_log != nullptr) start_log->append(start_log->empty() ? "" : "; ").append(message);
    return 1;
  };
  std::string log;
  start_log = &log;
  s->ctx_ = mg_start(&callbacks, s.get(), opts.data());
  start_log = nullptr;
  if (s->ctx_ == nullptr) {
    if (tls && log.find("ssl") != std::string::npos)
      return Status::IOError("web server: cannot use the TLS certificate '" + options.tls_certificate + "' (" + log + ")");
    return Status::IOError("web server: cannot listen on " + ports + " (in use, or not an address of this machine)" +
                           (log.empty() ? "" : ": " + log));
  }
  mg_server_port sp[4];
  const int n = mg_get_server_ports(s->ctx_, 4, sp);
  s->port_ = n > 0 ? sp[0].port : options.port;
  for (auto& [uri, page] : s->options_.pages) {
    page.uri = uri;
    mg_set_request_handler(s->ctx_, uri.c_str(), &WebServer::OnPage, &page);
  }
  // Every other path is ours to answer too: civetweb's own 404 (no document root) crashes.
  if (!s->options_.pages.count("/")) mg_set_request_handler(s->ctx_, "/", &WebServer::OnPage, &s->not_found_);
  for (const auto& e : s->options_.endpoints) {
    auto st = std::make_unique<EndpointState>();
    st->server = s.get();
    st->handler = e.handler;
    st->viewers = e.viewers;
    st->handler_only_queues = e.handler_only_queues;
    st->roles = e.roles;
    for (const auto& p : e.subprotocols) st->protocol_ptrs.push_back(p.c_str());
    st->protocols.nb_subprotocols = static_cast<int>(st->protocol_ptrs.size());
    st->protocols.subprotocols = st->protocol_ptrs.data();
    mg_set_websocket_handler_with_subprotocols(s->ctx_, e.uri.c_str(), st->protocol_ptrs.empty() ? nullptr : &st->protocols,
                                               &WebServer::OnConnect, &WebServer::OnReady, &WebServer::OnData,
                                               &WebServer::OnClosed, st.get());
    s->endpoints_.push_back(std::move(st));
  }
  return s;
}

int WebServer::OnPage(mg_connection* conn, void* page_ptr) {
  const auto* page = static_cast<const Page*>(page_ptr);
  const mg_request_info* info = mg_get_request_info(conn);
  auto* self = static_cast<WebServer*>(mg_get_user_data(mg_get_context(conn)));
  // Exact URIs only: civetweb matches prefixes ("/" would answer every path).
  // Answered here: civetweb's own file handling is off (no document_root) and must not run.
  if (info->local_uri == nullptr || page->uri != info->local_uri) return WriteResponse(conn, 404, "Not Found", "not found\n");
  const std::variant<Admission, Refusal> admission = self->AdmissionOf(info);
  if (const auto* refusal = std::get_if<Refusal>(&admission))
    return WriteResponse(conn, refusal->status, ReasonPhrase(refusal->status), refusal->body);
  const Role role = std::get<Admission>(admission).role;
  if (!page->roles.count(role))
    return WriteResponse(conn, 403, "Forbidden", std::string("The ") + RoleName(role) + "'s token does not open this page.\n");
  WriteWhole(conn,
             "HTTP/1.1 200 OK\r\nContent-Type: " + page->mime + "\r\nContent-Length: " + std::to_string(page->body.size()) +
                 "\r\nCache-Control: no-store\r\nReferrer-Policy: no-referrer\r\nX-Frame-Options: DENY\r\n"
                 "X-Content-Type-Options: nosniff\r\nConnection: close\r\n\r\n",
             page->body);
  return 200;
}

std::optional<Role> WebServer::RoleOf(const char* query_string) const {
  const std::string given = QueryValue(query_string, "token");
  std::optional<Role> role;
  for (const auto& [r, token] : options_.tokens)  // no early exit: every comparison is made
    if (TokenMatches(given, token)) role = r;
  return role;
}

std::variant<Admission, Refusal> WebServer::AdmissionOf(const mg_request_info* info) const {
  if (options_.admit) {
    std::variant<Admission, Refusal> answer = options_.admit(QueryValue(info->query_string, "token"), info->remote_addr);
    if (auto* refusal = std::get_if<Refusal>(&answer); refusal != nullptr && (refusal->status < 400 || refusal->status > 599))
      refusal->status = 500;  // a success status would read as admitted
    return answer;
  }
  if (const std::optional<Role> role = RoleOf(info->query_string)) return Admission{*role, ""};
  return Refusal{401, "This page needs the link dyad printed, with its ?token=... (no token, or not this server's).\n"};
}

void WebServer::Disconnect(Client& c) {
  const mg_request_info* info = mg_get_request_info(c.conn);
  if (info != nullptr) ShutdownConnection(info->remote_addr, info->remote_port, port_);
}

// civetweb's master thread polls its listening socket 2 s at a time and sees mg_stop's flag only
// between polls: a connection of our own wakes it (else every stop, a Ctrl-C of the graph
// included, waited up to 2 s).
void WakeListener(const std::string& address, int port) {
  const bool v6 = address.find(':') != std::string::npos;
  const std::string target = address == "0.0.0.0" ? "127.0.0.1" : address == "::" ? "::1" : address;
  const int fd = socket(v6 ? AF_INET6 : AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return;
  sockaddr_storage a{};
  socklen_t len = 0;
  if (v6) {
    auto* in6 = reinterpret_cast<sockaddr_in6*>(&a);
    in6->sin6_family = AF_INET6;
    in6->sin6_port = htons(static_cast<uint16_t>(port));
    inet_pton(AF_INET6, target.c_str(), &in6->sin6_addr);
    len = sizeof(sockaddr_in6);
  } else {
    auto* in = reinterpret_cast<sockaddr_in*>(&a);
    in->sin_family = AF_INET;
    in->sin_port = htons(static_cast<uint16_t>(port));
    inet_pton(AF_INET, target.c_str(), &in->sin_addr);
    len = sizeof(sockaddr_in);
  }
  connect(fd, reinterpret_cast<sockaddr*>(&a), len);
  close(fd);
}

WebServer::~WebServer() {
  // Every client's socket shut down first: its worker, polling 2 s at a time, sees the end at
  // once (mg_stop alone waited up to 2 s for each connected WebSocket's worker).
  std::vector<std::shared_ptr<Client>> open;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [id, c] : clients_) open.push_back(c);
  }
  for (const auto& c : open) {
    std::lock_guard<std::mutex> write(c->write_mutex);
    if (!c->closed) Disconnect(*c);
  }
  if (ctx_ != nullptr) {
    std::atomic<bool> stopped{false};
    std::thread waker([&] {
      for (int i = 0; i < 200 && !stopped.load(); ++i) {  // until mg_stop returns (at most 2 s)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
        WakeListener(options_.address, port_);
      }
    });
    mg_stop(ctx_);  // closes every connection (OnClosed joins each sender)
    stopped = true;
    waker.join();
  }
  handler_thread_.reset();             // after mg_stop: no worker waits on it any more
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto& [id, c] : clients_) {
    c->queue.Close();
    {
      std::lock_guard<std::mutex> write(c->write_mutex);  // a sender in the middle of a batch stops
      c->closed = true;
    }
    if (c->sender.joinable()) c->sender.join();
  }
}

bool WebServer::OriginAllowed(const std::string& origin) const {
  for (const auto& o : options_.allowed_origins) {
    if (o == "*" || o == origin) return true;
    // "scheme://host:0" on a server given port 0: that host at the port it bound.
    if (options_.port == 0 && o.ends_with(":0") && origin == o.substr(0, o.size() - 1) + std::to_string(port_)) return true;
  }
  if (IsLoopback(options_.address)) {
    for (const char* local : {"http://localhost", "http://127.0.0.1", "https://localhost", "https://127.0.0.1"}) {
      const std::string l(local);
      if (origin == l || origin.rfind(l + ":", 0) == 0) return true;
    }
  }
  return false;
}

int WebServer::OnConnect(const mg_connection* conn, void* endpoint) {
  auto* self = static_cast<EndpointState*>(endpoint)->server;
  const mg_request_info* info = mg_get_request_info(conn);
  // libcivetweb 1.15 keeps the subprotocol its worker's previous WebSocket accepted and answers a
  // client that asked for none with it, which the client must refuse (civetweb#1091, fixed after
  // 1.15 by clearing it per connection, as here: this runs before the handshake is sent).
  if (mg_get_header(conn, "Sec-WebSocket-Protocol") == nullptr)
    const_cast<mg_request_info*>(info)->acceptedWebSocketSubprotocol = nullptr;
  if (const char* origin = mg_get_header(conn, "Origin"); origin != nullptr && !self->OriginAllowed(origin)) return 1;
  std::variant<Admission, Refusal> admission = self->AdmissionOf(info);
  if (const auto* refusal = std::get_if<Refusal>(&admission)) {
    // With `admit` the handshake is answered with the refusal (civetweb sends nothing when this
    // returns non-zero, and closes the connection: the answer is ours to write); with `tokens`
    // it is closed unanswered, as it always was.
    if (self->options_.admit)
      WriteResponse(const_cast<mg_connection*>(conn), refusal->status, ReasonPhrase(refusal->status), refusal->body);
    return 1;
  }
  if (!static_cast<EndpointState*>(endpoint)->roles.count(std::get<Admission>(admission).role)) return 1;
  std::lock_guard<std::mutex> lock(self->mutex_);
  if (static_cast<int>(self->admitted_.size()) >= self->options_.max_clients) return 1;
  self->admitted_[conn] = std::move(std::get<Admission>(admission));
  return 0;
}

void WebServer::OnReady(mg_connection* conn, void* endpoint) {
  auto* self = static_cast<EndpointState*>(endpoint)->server;
  ClientHandler* handler = static_cast<EndpointState*>(endpoint)->handler;
  const bool viewers = static_cast<EndpointState*>(endpoint)->viewers;
  auto c = std::make_shared<Client>(self->options_.client_buffer_bytes,
                                    viewers ? SendQueue::kDefaultFlushInterval : std::chrono::steady_clock::duration::zero());
  c->conn = conn;
  if (const mg_request_info* info = mg_get_request_info(conn)) c->remote_address = info->remote_addr;
  {
    std::lock_guard<std::mutex> lock(self->mutex_);
    c->admission = self->admitted_.at(conn);
    c->id = self->next_id_++;
    self->clients_[c->id] = c;
    self->by_conn_[conn] = {c->id, handler};
  }
  Client* raw = c.get();
  c->sender = std::thread([self, raw, viewers] {
    if (viewers) {
      // Not SCHED_IDLE: a graph thread waiting for the queue's lock held by an idle-class sender
      // that was preempted waited up to 1.4 s on a loaded machine (no priority inheritance).
      sched_param none{};
      pthread_setschedparam(pthread_self(), SCHED_BATCH, &none);  // if refused, it runs as before
    }
    std::vector<Frame> batch;
    std::string joined;  // a head and its shared tail, written as one frame
    while (raw->queue.PopAll(&batch)) {
      for (const Frame& f : batch) {
        const std::string* bytes = &f.bytes;
        if (f.tail) {
          joined.assign(f.bytes).append(*f.tail);
          bytes = &joined;
        }
        std::lock_guard<std::mutex> lock(raw->write_mutex);
        if (raw->closed) return;
        const int op = f.binary ? MG_WEBSOCKET_OPCODE_BINARY : MG_WEBSOCKET_OPCODE_TEXT;
        if (mg_websocket_write(raw->conn, op, bytes->data(), bytes->size()) <= 0) {
          // Nothing more can reach this client in order: end it, not just its sender.
          raw->queue.Close();
          self->Disconnect(*raw);
          return;
        }
      }
    }
    // Closed: by OnClosed (nothing to do), by Close() (after what was queued: the close frame,
    // then the end) or by the queue itself (its control frames overflowed).
    std::lock_guard<std::mutex> lock(raw->write_mutex);
    if (raw->closed) return;
    std::unique_lock<std::mutex> close_lock(raw->close_mutex);
    if (raw->closing) {
      WriteClose(raw->conn, raw->close_code, raw->close_reason);
      self->Disconnect(*raw);
    } else if (raw->queue.overflowed()) {
      self->Disconnect(*raw);
    }
  });
  handler->OnOpen(c->id, c->admission.role);
}

int WebServer::OnData(mg_connection* conn, int bits, char* data, size_t len, void* endpoint) {
  auto* self = static_cast<EndpointState*>(endpoint)->server;
  ClientHandler* handler = static_cast<EndpointState*>(endpoint)->handler;
  ClientId id = 0;
  {
    std::lock_guard<std::mutex> lock(self->mutex_);
    auto it = self->by_conn_.find(conn);
    if (it == self->by_conn_.end()) return 0;
    id = it->second.first;
  }
  const int opcode = bits & 0x0f;
  const bool fin = (bits & 0x80) != 0;
  if (opcode == MG_WEBSOCKET_OPCODE_CONNECTION_CLOSE) return 0;
  if (opcode == MG_WEBSOCKET_OPCODE_PING) {
    mg_websocket_write(conn, MG_WEBSOCKET_OPCODE_PONG, data, len);
    return 1;
  }
  if (opcode == MG_WEBSOCKET_OPCODE_PONG) return 1;
  if (len > self->options_.max_frame_bytes) {
    WriteClose(conn, kCloseTooBig, "frame of " + std::to_string(len) + " bytes exceeds the limit of " +
                                       std::to_string(self->options_.max_frame_bytes));
    return 0;
  }
  if (!fin || opcode == MG_WEBSOCKET_OPCODE_CONTINUATION) {
    WriteClose(conn, kCloseUnsupported, "fragmented messages are not supported");
    return 0;
  }
  Status s;
  auto handle = [&] {
    if (opcode == MG_WEBSOCKET_OPCODE_TEXT) s = handler->OnText(id, std::string_view(data, len));
    else if (opcode == MG_WEBSOCKET_OPCODE_BINARY)
      s = handler->OnBinary(id, std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(data), len));
    else s = Status::InvalidArgument("unknown opcode " + std::to_string(opcode));
  };
  if (static_cast<EndpointState*>(endpoint)->handler_only_queues) {
    handle();
  } else {
    const int64_t received_ns =
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
    self->handler_thread_->Run([&] {
      self->message_received_ns_ = received_ns;
      handle();
    });
  }
  if (!s.ok()) {
    WriteClose(conn, kClosePolicy, s.message());
    return 0;
  }
  return 1;
}

void WebServer::OnClosed(const mg_connection* conn, void* endpoint) {
  auto* self = static_cast<EndpointState*>(endpoint)->server;
  ClientHandler* handler = static_cast<EndpointState*>(endpoint)->handler;
  std::shared_ptr<Client> c;
  {
    std::lock_guard<std::mutex> lock(self->mutex_);
    self->admitted_.erase(conn);
    auto it = self->by_conn_.find(conn);
    if (it == self->by_conn_.end()) return;  // rejected before it was ready
    c = self->clients_[it->second.first];
    self->clients_.erase(it->second.first);
    self->by_conn_.erase(it);
  }
  c->queue.Close();
  {
    std::lock_guard<std::mutex> lock(c->write_mutex);  // waits for a write in progress
    c->closed = true;
  }
  if (c->sender.joinable()) c->sender.join();
  handler->OnClose(c->id);
}

std::shared_ptr<WebServer::Client> WebServer::Find(ClientId id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = clients_.find(id);
  return it == clients_.end() ? nullptr : it->second;
}

void WebServer::SendText(ClientId client, std::string json) {
  if (auto c = Find(client)) c->queue.PushControl(std::move(json));
}

void WebServer::SendData(ClientId client, uint32_t channel, std::string frame) {
  if (auto c = Find(client)) c->queue.PushData(channel, std::move(frame));
}

void WebServer::SendShared(ClientId client, uint32_t channel, std::string head, std::shared_ptr<const std::string> tail) {
  if (auto c = Find(client)) c->queue.PushData(channel, std::move(head), /*binary=*/true, std::move(tail));
}

void WebServer::SendLatest(ClientId client, uint32_t channel, std::string frame, bool binary) {
  if (auto c = Find(client)) c->queue.PushLatest(channel, std::move(frame), binary);
}

std::map<uint32_t, uint64_t> WebServer::TakeDrops(ClientId client) {
  if (auto c = Find(client)) return c->queue.TakeDrops();
  return {};
}

std::string WebServer::who(ClientId client) const {
  if (auto c = Find(client)) return c->admission.who;
  return "";
}

std::string WebServer::remote_address(ClientId client) const {
  if (auto c = Find(client)) return c->remote_address;
  return "";
}

void WebServer::Close(ClientId client, int code, std::string reason) {
  auto c = Find(client);
  if (!c) return;
  {
    std::lock_guard<std::mutex> lock(c->close_mutex);
    if (c->closing) return;
    c->closing = true;
    c->close_code = code;
    c->close_reason = std::move(reason);
  }
  c->queue.Finish();  // the sender writes what is queued, then the close frame (see OnReady)
}

std::vector<ClientId> WebServer::clients() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<ClientId> out;
  for (const auto& [id, c] : clients_) out.push_back(id);
  return out;
}

}  // namespace dyad::web
