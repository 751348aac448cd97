/// WebServer — the embedded HTTP + WebSocket server of one `web` component (civetweb, Debian's
/// libcivetweb). It serves fixed pages (embedded in the plugin: no files to install, no CDN) and
/// WebSocket endpoints, each with its own handler and accepted subprotocols.
///
/// Every client gets a SendQueue and a sender thread of its own: producers (the bridge, called
/// from the graph's delivering threads) only queue, so a slow, stuck or malicious client never
/// blocks the experiment; it loses samples instead (SendQueue's policy). Received frames larger
/// than `max_frame_bytes` close the client (1009); a client the handler rejects is closed with
/// the handler's code and reason. A client whose write fails (a peer that stopped reading for
/// the write timeout, a dead link) or whose control frames outgrow its buffer is disconnected
/// at once: its socket is shut down, so the worker ends it and the handler's OnClose runs.
///
/// Admission, for pages and WebSocket clients alike: every request carries `?token=<token>`,
/// and the token says its role (`tokens`, one per role, compared in constant time); each page
/// and endpoint names the roles it admits (401 without a known token, 403 for a role it does
/// not admit). Or, with `admit` (Options::admit), a callback decides every page request and
/// WebSocket handshake from the token and the peer's address: it admits with a role and a `who`
/// (the participant, say), or refuses with an HTTP status and a plain-text body, which a page
/// request and a WebSocket handshake both get as their answer.
/// At most `max_clients` WebSocket clients. A request carrying an Origin header must
/// name an allowed origin (`allowed_origins`, entries "scheme://host[:port]" or "*"; on a server
/// given port 0, an entry "scheme://host:0" stands for that host at the port it bound; localhost
/// origins are always allowed when the server binds a loopback address). Pages are sent with
/// `Referrer-Policy: no-referrer` (their URL holds the token), `Cache-Control: no-store` and
/// `X-Frame-Options: DENY` (no page of another site can frame the steering page).
///
/// TLS: with `tls_certificate` (a PEM file: private key, then certificate chain) the server
/// speaks HTTPS and WSS only. Debian's civetweb 1.15 loads libssl by name and asks it for
/// SSL_get_peer_certificate, which OpenSSL 3 no longer exports (a null call on the first
/// connection); the server first loads dyad's libdyad_civetweb_ssl.so (civetweb_ssl_shim.c), a
/// library named "libssl.so" that supplies it, so civetweb finds that one.
///
/// Stacks: civetweb's worker threads (pages, handshakes, OnOpen/OnClose) have 100 KB stacks
/// (Debian's build sets USE_STACK_SIZE 102400), and an OpenSSL 3 SSL_write takes most of that.
/// Every thread's static TLS comes out of its stack: a program that runs this server must keep
/// its thread_local data small (a 5 KB std::mt19937 in the dyad command overflowed a page's
/// SSL_write, web.tls_browser; 4.6 KB more crashes civetweb's own WebSocket handshake, whose
/// mg_printf formats into an 8 KB stack buffer: the `static_tls` test holds each file of the build
/// to 1 KB). Pages are written without mg_printf for the same reason. Deep work belongs on the
/// handler thread or a thread of one's own.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <thread>
#include <variant>
#include <vector>

#include <dyad/status.hpp>

#include "send_queue.hpp"

struct mg_context;
struct mg_connection;
struct mg_websocket_subprotocols;
struct mg_request_info;

namespace dyad::web {

using ClientId = uint64_t;

// Whether a listen address reaches only this machine (127.x, localhost, ::1): then pages from
// localhost origins are accepted, and TLS is not needed.
bool IsLoopback(const std::string& address);

// What a client may do, said by its token. The server only admits by role; what each role may
// do on an endpoint is the handler's to enforce.
enum class Role { kViewer, kSubject, kExperimenter };
const char* RoleName(Role role);

// Options::admit's answers. A request admitted: its role (what it may open, as with `tokens`) and
// who it is (e.g. the participant's pseudonym; WebServer::who() gives it back for a client).
struct Admission {
  Role role = Role::kViewer;
  std::string who;
};
// A request refused: answered with `status` (an HTTP error status, 400-599: 404, 409, 429, 503
// ...) and `body` (plain text, UTF-8), a page request and a WebSocket handshake alike.
struct Refusal {
  int status = 404;
  std::string body;
};
// Decides one page request or WebSocket handshake from its `token` (the query's `token`, "" when
// it has none) and `remote_address` (the peer's IP, e.g. "127.0.0.1"). Runs on civetweb's worker
// threads, several at once: it must be thread-safe and quick (it holds a worker).
using Admit = std::function<std::variant<Admission, Refusal>(std::string_view token, std::string_view remote_address)>;

// Whether a client's token is the expected one, in time that does not depend on where they
// differ (OpenSSL's CRYPTO_memcmp; only the length can be learnt). An empty `expected` matches
// nothing.
bool TokenMatches(std::string_view given, std::string_view expected);

// A new token: 32 hex digits from std::random_device.
std::string RandomToken();

// The URLs' host for a server bound to `address`: itself, or for a wildcard (0.0.0.0, ::) this
// machine's IPv4 addresses other than loopback (loopback when it has none).
std::vector<std::string> UrlHosts(const std::string& address);

// What the application does with WebSocket clients. Threads:
//   - OnOpen and OnClose run on the civetweb worker thread that serves the client's connection
//     (for a client still open when the server stops, while ~WebServer waits for it).
//   - OnText and OnBinary run on the server's one handler thread (a normal stack: civetweb's are
//     small), one message at a time across all clients, while the client's worker waits; or,
//     for an endpoint whose handler only queues (Endpoint::handler_only_queues), on the client's
//     worker itself, two clients' messages then at the same time.
// So one client's calls never overlap and come in order (OnOpen, messages, OnClose), and two
// clients' messages never overlap either (unless the handler only queues); but one client's
// OnOpen or OnClose may run while another client's OnText or OnBinary does. Producers calling
// Send* run on their own threads.
class ClientHandler {
 public:
  virtual ~ClientHandler() = default;
  virtual void OnOpen(ClientId client, Role role) = 0;
  // Return a non-OK Status to close the client with its message as the close reason.
  virtual Status OnText(ClientId client, std::string_view text) = 0;
  virtual Status OnBinary(ClientId client, std::span<const uint8_t> bytes) = 0;
  virtual void OnClose(ClientId client) = 0;
};

class WebServer {
 public:
  struct Page {
    std::string mime;  // e.g. "text/html; charset=utf-8"
    std::string body;
    std::set<Role> roles;  // who may load it
    std::string uri;       // filled by Start()
  };
  struct Endpoint {
    std::string uri;                        // e.g. "/"
    std::vector<std::string> subprotocols;  // empty: any
    ClientHandler* handler = nullptr;
    std::set<Role> roles;  // who may connect
    // Its clients are viewers (Foxglove, the experimenter's page): their frames are batched per
    // display frame (SendQueue::kDefaultFlushInterval) and their sender threads are SCHED_BATCH,
    // which never preempt a running thread when they wake (a graph thread finishes its step
    // first) yet get a fair share of the CPU. False: every sample at once, normal scheduling
    // (the subject's page, whose robot state is what the subject steers by).
    bool viewers = true;
    // The handler's OnText/OnBinary only queue the frame for a thread of its own, or do as little
    // (a shallow stack, bounded in time: a socket write with a short timeout, say; the study
    // server's front relays a trial's frame within 100 ms): they are then called on civetweb's
    // worker (that client's only: a slow call delays no other client), with no hand-over to
    // the server's handler thread (a wake-up of that thread and one of the worker per frame; the
    // study server relays dozens of pages' pointer streams). message_received_ns() is not set for
    // them. False: on the handler thread (see the Stacks paragraph above).
    bool handler_only_queues = false;
  };
  struct Options {
    std::string address = "127.0.0.1";
    int port = 8765;  // 0: any free port (see port())
    std::map<std::string, Page> pages;  // by exact URI
    std::vector<Endpoint> endpoints;
    std::vector<std::string> allowed_origins;
    std::map<Role, std::string> tokens;  // at least one unless `admit`; each distinct and non-empty
    // When set, decides every page request and WebSocket handshake instead of `tokens` (which may
    // then be empty and is not consulted). The Origin check, the pages' and endpoints' roles and
    // max_clients still apply to what it admits.
    Admit admit;
    std::string tls_certificate;         // PEM: key and certificate chain; empty: plain HTTP
    int max_clients = 8;
    int write_timeout_ms = 5000;  // a write blocked this long disconnects the client
    size_t max_frame_bytes = 1 << 20;
    size_t client_buffer_bytes = 4 << 20;
  };

  // Starts listening; fails (IOError) when the address/port cannot be bound or the certificate
  // cannot be used, InvalidArgument when the tokens are missing (and no `admit`), empty or not
  // distinct.
  static StatusOr<std::unique_ptr<WebServer>> Start(const Options& options);
  ~WebServer();  // closes every client, stops the server, joins every thread
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  int port() const { return port_; }
  // Queue frames for a client (dropped silently if it is gone).
  void SendText(ClientId client, std::string json);
  void SendData(ClientId client, uint32_t channel, std::string frame);
  // A binary data frame `head` + `*tail`: one copy of a sample shared by every client's frame.
  void SendShared(ClientId client, uint32_t channel, std::string head, std::shared_ptr<const std::string> tail);
  // Newest only (see SendQueue::PushLatest); a text frame unless `binary`.
  void SendLatest(ClientId client, uint32_t channel, std::string frame, bool binary);
  // Per-channel drops of a client since the last call.
  std::map<uint32_t, uint64_t> TakeDrops(ClientId client);
  std::vector<ClientId> clients() const;
  // A connected client's Admission::who ("" with `tokens`, or once the client is gone).
  std::string who(ClientId client) const;
  // A connected client's IP address ("" once it is gone).
  std::string remote_address(ClientId client) const;
  // Ends a client from any thread (a handler's OnText included): the frames queued before this
  // call are sent, then a close frame with `code` (e.g. 1000, 1008, 1012) and `reason` (cut to
  // 120 bytes), then the connection is shut down and the handler's OnClose runs on the client's
  // worker thread (after Close returns, not within it: frames already received may still reach
  // OnText meanwhile). Frames queued after the call are dropped. Nothing for a client that is
  // gone or closing already. A peer that has stopped reading gets its close frame after the
  // write timeout's wait, at worst (the sender's, never the caller's).
  void Close(ClientId client, int code, std::string reason);
  // Inside OnText/OnBinary only (the handler thread): the wall-clock time (ns since the epoch)
  // civetweb's worker received the message; the handler's own start minus this is the wait for
  // the handler thread (bench/web prints it).
  int64_t message_received_ns() const { return message_received_ns_; }

 private:
  struct Client;
  struct EndpointState;
  class HandlerThread;
  WebServer() = default;
  static int OnPage(mg_connection* conn, void* page);
  static int OnConnect(const mg_connection* conn, void* self);
  static void OnReady(mg_connection* conn, void* self);
  static int OnData(mg_connection* conn, int bits, char* data, size_t len, void* self);
  static void OnClosed(const mg_connection* conn, void* self);
  bool OriginAllowed(const std::string& origin) const;
  // The role whose token the request's query carries (every token compared: constant time).
  std::optional<Role> RoleOf(const char* query_string) const;
  // The request's admission: by `admit` when set, else by `tokens` (a Refusal of 401 when no
  // token matches).
  std::variant<Admission, Refusal> AdmissionOf(const mg_request_info* info) const;
  // Ends `c`'s connection from any thread (its socket shut down). REQUIRES: c->write_mutex held
  // and c->closed false, so the connection is still open.
  void Disconnect(Client& c);
  std::shared_ptr<Client> Find(ClientId id) const;

  Options options_;
  Page not_found_{"", "", {}, "\n"};  // "/" when no page is: its URI matches no request (404)
  std::unique_ptr<HandlerThread> handler_thread_;  // runs OnText/OnBinary (see web_server.cpp)
  int64_t message_received_ns_ = 0;                 // written and read on the handler thread only
  mg_context* ctx_ = nullptr;
  int port_ = 0;
  std::vector<std::unique_ptr<EndpointState>> endpoints_;  // civetweb keeps pointers into these
  mutable std::mutex mutex_;
  std::map<ClientId, std::shared_ptr<Client>> clients_;
  std::map<const mg_connection*, std::pair<ClientId, ClientHandler*>> by_conn_;
  ClientId next_id_ = 1;
  std::map<const mg_connection*, Admission> admitted_;  // past OnConnect, not yet closed
};

}  // namespace dyad::web
