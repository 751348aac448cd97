/// WsClient — a WebSocket client for text frames over plain TCP (ws://), made for relaying a
/// page's frames to a graph's web component on loopback (`dyad study serve`).
///
/// Contract:
///   - Connect() resolves `host`, connects, sends the upgrade request for `path_and_query` (e.g.
///     "/subject/ws?token=T") and checks the server's 101 answer, all within `timeout`. Errors
///     name host:port and the path without its query (the query holds a token):
///       NotFound  nothing listens there (connection refused, or no TCP connection within the
///                 timeout): the case to retry while a graph starts;
///       IOError   the server answered the handshake with another status than 101 (the status
///                 and the first line of its body in the message), closed it unanswered (a
///                 WebServer with `tokens` refusing), gave no whole answer within the timeout,
///                 or the host cannot be resolved.
///   - After the handshake, one thread of the client's own reads: `on_text` runs on it for each
///     text frame, in order, possibly before Connect has returned (a server's first frame): a
///     callback that uses the returned WsClient must wait for it (a mutex held around Connect and
///     storing its result, say). Binary frames are ignored; pings are answered. `on_close` runs on it
///     once when the link ends without Close(): the peer's close frame (answered), the peer
///     closing the socket, a read error, a frame larger than kMaxFrameBytes or fragmented (then
///     the client sends 1009/1003 first).
///   - SendText: thread-safe (one frame at a time, whole); an error (FailedPrecondition) once
///     closed, by either side; IOError when the write fails (the link then ends: on_close).
///     A write blocks while the peer's receive window is full, at most `timeout` (kWriteTimeout
///     by default; a relay on a shared thread gives a short one, and a peer that stops reading
///     then ends the link rather than holding the thread).
///   - Close(): idempotent, from any thread (a callback included). Sends a close frame (1000),
///     shuts the socket down, and when called from another thread waits for the reading thread:
///     no callback runs after it returns. From a callback of its own
///     the reading thread ends after that callback returns, and runs none after it. Do not hold,
///     while calling Close() or ~WsClient from another thread, a lock the callbacks take.
///   - ~WsClient(): Close(). A WsClient may be destroyed inside its own callback.
///
/// Why not civetweb's mg_connect_websocket_client (libcivetweb 1.15): it has no timeout for the
/// connection or the handshake, mg_close_connection waits for its reading thread's poll quantum
/// (SOCKET_TIMEOUT_QUANTUM, 2 s, per close), and it cannot be closed from its own callback (it would join itself,
/// then free the connection its thread still uses). The protocol a client needs (RFC 6455: the
/// upgrade, masked frames out, unmasked frames in) is small; this is it.
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include <dyad/status.hpp>

namespace dyad::web {

class WsClient {
 public:
  struct Callbacks {
    std::function<void(std::string_view text)> on_text;  // on the client's own thread; may be empty
    std::function<void()> on_close;  // once, when the peer closes or the link fails (not after Close()); may be empty
  };
  // Received frames larger than this end the link (the client closes it with 1009).
  static constexpr size_t kMaxFrameBytes = 16u << 20;
  static constexpr std::chrono::milliseconds kWriteTimeout{5000};

  // Connects to ws://host:port/path_and_query (see the contract above). `path_and_query` starts
  // with '/'.
  static StatusOr<std::unique_ptr<WsClient>> Connect(const std::string& host, int port, const std::string& path_and_query,
                                                     Callbacks callbacks, std::chrono::milliseconds timeout);
  Status SendText(std::string_view text, std::chrono::milliseconds timeout = kWriteTimeout);
  void Close();
  ~WsClient();
  WsClient(const WsClient&) = delete;
  WsClient& operator=(const WsClient&) = delete;

 private:
  struct State;
  explicit WsClient(std::shared_ptr<State> state) : state_(std::move(state)) {}
  std::shared_ptr<State> state_;  // shared with the reading thread, which may outlive this
};

}  // namespace dyad::web
