#include "ws_client.hpp"

#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <openssl/evp.h>
#include <openssl/rand.h>
#include <openssl/sha.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <random>
#include <thread>

namespace dyad::web {

namespace {

using Clock = std::chrono::steady_clock;

constexpr int kOpContinuation = 0x0, kOpText = 0x1, kOpClose = 0x8, kOpPing = 0x9, kOpPong = 0xA;
constexpr size_t kMaxHeadBytes = 16 << 10, kMaxRefusalBodyBytes = 1 << 10;

std::string Base64(const unsigned char* data, size_t n) {
  std::string out(4 * ((n + 2) / 3) + 1, '\0');
  const int len = EVP_EncodeBlock(reinterpret_cast<unsigned char*>(out.data()), data, static_cast<int>(n));
  out.resize(static_cast<size_t>(len));
  return out;
}

// The Sec-WebSocket-Accept a server must answer to `key` (RFC 6455 4.2.2).
std::string AcceptFor(const std::string& key) {
  const std::string text = key + "258EAFA5-E914-47DA-95CA-C5AB0DC85B11";
  unsigned char digest[SHA_DIGEST_LENGTH];
  SHA1(reinterpret_cast<const unsigned char*>(text.data()), text.size(), digest);
  return Base64(digest, sizeof(digest));
}

// A frame's masking key, unpredictable as RFC 6455 10.3 asks (OpenSSL's CSPRNG). Not a
// thread_local engine: a std::mt19937 there is 5 KB of static TLS in every thread of a program
// that links this (the dyad command), taken from each thread's stack, and civetweb's workers
// have small stacks: SSL_write on one overflowed it (web.tls_browser crashed in EVP_CipherInit_ex).
uint32_t RandomWord() {
  uint32_t word = 0;
  if (RAND_bytes(reinterpret_cast<unsigned char*>(&word), sizeof word) != 1) word = static_cast<uint32_t>(std::random_device{}());
  return word;
}

// One frame as a client sends it: final, masked (RFC 6455 5.3).
std::string EncodeFrame(int opcode, std::string_view payload) {
  std::string f;
  f.reserve(payload.size() + 14);
  f.push_back(static_cast<char>(0x80 | opcode));
  const uint64_t n = payload.size();
  if (n < 126) {
    f.push_back(static_cast<char>(0x80 | n));
  } else if (n < 65536) {
    f.push_back(static_cast<char>(0x80 | 126));
    for (int shift = 8; shift >= 0; shift -= 8) f.push_back(static_cast<char>((n >> shift) & 0xff));
  } else {
    f.push_back(static_cast<char>(0x80 | 127));
    for (int shift = 56; shift >= 0; shift -= 8) f.push_back(static_cast<char>((n >> shift) & 0xff));
  }
  const uint32_t key = RandomWord();
  char mask[4];
  for (int i = 0; i < 4; ++i) mask[i] = static_cast<char>((key >> (8 * i)) & 0xff);
  f.append(mask, 4);
  const size_t start = f.size();
  f.append(payload);
  for (size_t i = 0; i < n; ++i) f[start + i] = static_cast<char>(f[start + i] ^ mask[i % 4]);
  return f;
}

std::string CloseFrame(int code) {
  const char payload[2] = {static_cast<char>((code >> 8) & 0xff), static_cast<char>(code & 0xff)};
  return EncodeFrame(kOpClose, std::string_view(payload, 2));
}

int RemainingMs(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return static_cast<int>(std::clamp<int64_t>(left, 0, 1 << 30));
}

// Waits for `events` on `fd` until the deadline: true when they came.
bool WaitFor(int fd, short events, Clock::time_point deadline) {
  for (;;) {
    pollfd p{fd, events, 0};
    const int n = poll(&p, 1, RemainingMs(deadline));
    if (n > 0) return true;
    if (n == 0 || errno != EINTR) return false;
  }
}

// One address tried until the deadline: the connected socket (blocking), or -1 with errno's text.
int ConnectOne(const addrinfo* a, Clock::time_point deadline, std::string* why) {
  const int fd = socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, a->ai_protocol);
  if (fd < 0) {
    *why = std::strerror(errno);
    return -1;
  }
  int error = 0;
  if (connect(fd, a->ai_addr, a->ai_addrlen) != 0) {
    error = errno;
    if (error == EINPROGRESS) {
      socklen_t len = sizeof(error);
      if (!WaitFor(fd, POLLOUT, deadline)) error = ETIMEDOUT;
      else if (getsockopt(fd, SOL_SOCKET, SO_ERROR, &error, &len) != 0) error = errno;
    }
  }
  if (error != 0) {
    *why = std::strerror(error);
    close(fd);
    return -1;
  }
  fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) & ~O_NONBLOCK);  // the reading thread blocks; sends use MSG_DONTWAIT
  const int flags = 1;
  setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &flags, sizeof(flags));  // small frames at once
  return fd;
}

// A socket connected to host:port by the deadline; NotFound when nothing answers there.
StatusOr<int> ConnectSocket(const std::string& host, int port, Clock::time_point deadline, const std::string& where) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* list = nullptr;
  const std::string service = std::to_string(port);
  if (const int e = getaddrinfo(host.c_str(), service.c_str(), &hints, &list); e != 0)
    return Status::IOError(where, std::string("cannot resolve the host: ") + gai_strerror(e));
  std::string why = "no address";
  int fd = -1;
  for (const addrinfo* a = list; a != nullptr && fd < 0; a = a->ai_next) fd = ConnectOne(a, deadline, &why);
  freeaddrinfo(list);
  if (fd < 0) return Status::NotFound(where + ": nothing listens there (" + why + ")");
  return fd;
}

// Sends all of `bytes` by the deadline (the socket is non-blocking or has a send timeout).
bool SendAll(int fd, std::string_view bytes, Clock::time_point deadline) {
  while (!bytes.empty()) {
    const ssize_t n = send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) {
      bytes.remove_prefix(static_cast<size_t>(n));
    } else if (n < 0 && errno == EINTR) {
      continue;
    } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      if (!WaitFor(fd, POLLOUT, deadline)) return false;
    } else {
      return false;
    }
  }
  return true;
}

// Receives until `buffer` holds "\r\n\r\n" (the head's end: its offset + 4, or 0 on failure).
size_t ReceiveHead(int fd, std::string* buffer, Clock::time_point deadline, size_t limit) {
  for (;;) {
    if (const size_t end = buffer->find("\r\n\r\n"); end != std::string::npos) return end + 4;
    if (buffer->size() > limit || !WaitFor(fd, POLLIN, deadline)) return 0;
    char chunk[4096];
    const ssize_t n = recv(fd, chunk, sizeof(chunk), 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return 0;
    buffer->append(chunk, static_cast<size_t>(n));
  }
}

// A header's value in an HTTP head ("" when absent); names compared without case.
std::string HeaderValue(const std::string& head, const std::string& name) {
  size_t pos = head.find("\r\n");
  while (pos != std::string::npos && pos + 2 < head.size()) {
    const size_t start = pos + 2, end = head.find("\r\n", start);
    const std::string line = head.substr(start, end == std::string::npos ? std::string::npos : end - start);
    const size_t colon = line.find(':');
    if (colon == name.size() && strncasecmp(line.c_str(), name.c_str(), name.size()) == 0) {
      const size_t value = line.find_first_not_of(" \t", colon + 1);
      return value == std::string::npos ? "" : line.substr(value, line.find_last_not_of(" \t\r") + 1 - value);
    }
    pos = end;
  }
  return "";
}

// A refused handshake's error: its status line and the first line of its body.
Status Refused(int fd, const std::string& head, std::string body, Clock::time_point deadline, const std::string& where) {
  const std::string status_line = head.substr(0, head.find("\r\n"));
  const std::string length = HeaderValue(head, "Content-Length");
  const size_t want =
      std::min<size_t>(kMaxRefusalBodyBytes, length.empty() ? kMaxRefusalBodyBytes : std::strtoul(length.c_str(), nullptr, 10));
  while (body.size() < want && WaitFor(fd, POLLIN, deadline)) {
    char chunk[1024];
    const ssize_t n = recv(fd, chunk, sizeof(chunk), 0);
    if (n <= 0) break;
    body.append(chunk, static_cast<size_t>(n));
  }
  body = body.substr(0, std::min(want, body.find('\n')));
  const size_t space = status_line.find(' ');
  std::string message = "the server refused the WebSocket handshake: " +
                        (space == std::string::npos ? status_line : "HTTP " + status_line.substr(space + 1));
  if (!body.empty()) message += ": " + body;
  return Status::IOError(where, message);
}

// Sends the upgrade request and checks the answer; `rest` gets the bytes after the answer's head.
Status Handshake(int fd, const std::string& host, int port, const std::string& path, Clock::time_point deadline,
                 const std::string& where, std::string* rest) {
  unsigned char nonce[16];
  for (int i = 0; i < 16; i += 4) {
    const uint32_t w = RandomWord();
    std::memcpy(nonce + i, &w, 4);
  }
  const std::string key = Base64(nonce, sizeof(nonce));
  const std::string host_header = (host.find(':') != std::string::npos ? "[" + host + "]" : host) + ":" + std::to_string(port);
  const std::string request = "GET " + path + " HTTP/1.1\r\nHost: " + host_header +
                              "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: " + key +
                              "\r\nSec-WebSocket-Version: 13\r\n\r\n";
  if (!SendAll(fd, request, deadline)) return Status::IOError(where, "cannot send the WebSocket handshake");
  std::string buffer;
  const size_t head_end = ReceiveHead(fd, &buffer, deadline, kMaxHeadBytes);
  if (head_end == 0)
    return Status::IOError(where, buffer.empty() ? "the server closed the connection without answering the WebSocket handshake"
                                                 : "no whole answer to the WebSocket handshake in time");
  const std::string head = buffer.substr(0, head_end);
  *rest = buffer.substr(head_end);
  if (head.rfind("HTTP/1.1 101 ", 0) != 0 && head.rfind("HTTP/1.1 101\r", 0) != 0)
    return Refused(fd, head, *rest, deadline, where);
  if (HeaderValue(head, "Sec-WebSocket-Accept") != AcceptFor(key))
    return Status::IOError(where, "the server's WebSocket handshake has a wrong Sec-WebSocket-Accept");
  return Status::OK();
}

// A frame's head at `data` (n bytes): false when more bytes are needed.
struct FrameHead {
  bool fin = false;
  int opcode = 0;
  bool masked = false;
  unsigned char mask[4] = {0, 0, 0, 0};
  uint64_t length = 0;
  size_t size = 0;  // of the head
};

bool ParseHead(const unsigned char* data, size_t n, FrameHead* h) {
  if (n < 2) return false;
  h->fin = (data[0] & 0x80) != 0;
  h->opcode = data[0] & 0x0f;
  h->masked = (data[1] & 0x80) != 0;
  h->length = data[1] & 0x7f;
  size_t pos = 2;
  const int extra = h->length == 126 ? 2 : h->length == 127 ? 8 : 0;
  if (n < pos + static_cast<size_t>(extra) + (h->masked ? 4 : 0)) return false;
  if (extra > 0) {
    h->length = 0;
    for (int i = 0; i < extra; ++i) h->length = (h->length << 8) | data[pos++];
  }
  if (h->masked) {
    std::memcpy(h->mask, data + pos, 4);
    pos += 4;
  }
  h->size = pos;
  return true;
}

// The client whose reading thread this is (nullptr on every other thread).
thread_local const void* reading_for = nullptr;

}  // namespace

struct WsClient::State {
  int fd = -1;
  std::string where;  // "ws://host:port/path", for errors (no query: it holds a token)
  Callbacks callbacks;
  std::mutex write_mutex;  // one frame at a time on the socket (a plain mutex: TSan 14 cannot see timed locks)
  std::mutex close_mutex;  // held by a Close() from outside the reading thread, for all of it
  std::mutex mutex;        // guards the three below
  std::condition_variable done_cv;
  bool closed = false;  // Close() was called: no callback from now on
  bool ended = false;   // the link is over (either side): nothing more is sent
  bool done = false;    // the reading thread ran its last callback
  ~State() {
    if (fd >= 0) close(fd);
  }
  // Writes one frame: false if it could not be written whole within kWriteTimeout (after the
  // frame before it, which has as long).
  bool Write(const std::string& frame, std::chrono::milliseconds timeout = kWriteTimeout) {
    std::lock_guard<std::mutex> lock(write_mutex);
    return SendAll(fd, frame, Clock::now() + timeout);
  }
  // Whether the reading thread may run a callback now.
  bool Open() {
    std::lock_guard<std::mutex> lock(mutex);
    return !closed;
  }
  void Read(std::string buffer);
  bool Dispatch(const FrameHead& h, std::string_view payload);
  void End();
};

// Returns false when the link ends with this frame.
bool WsClient::State::Dispatch(const FrameHead& h, std::string_view payload) {
  if (!h.fin || h.opcode == kOpContinuation) {
    (void)Write(CloseFrame(1003));  // best effort: the link ends either way
    return false;
  }
  switch (h.opcode) {
    case kOpText:
      if (!Open()) return false;
      if (callbacks.on_text) callbacks.on_text(payload);
      return true;
    case kOpClose:
      // Answered with the peer's own code (RFC 6455 5.5.1); the link ends.
      (void)Write(EncodeFrame(kOpClose, payload.substr(0, std::min<size_t>(payload.size(), 2))));
      return false;
    case kOpPing:
      return Write(EncodeFrame(kOpPong, payload));
    default:  // binary and pong: not for this client
      return true;
  }
}

void WsClient::State::Read(std::string buffer) {
  size_t offset = 0;  // the first byte not yet parsed
  for (;;) {
    FrameHead h;
    const auto* data = reinterpret_cast<const unsigned char*>(buffer.data()) + offset;
    const size_t available = buffer.size() - offset;
    if (ParseHead(data, available, &h)) {
      if (h.length > kMaxFrameBytes) {
        (void)Write(CloseFrame(1009));  // best effort: the link ends either way
        return;
      }
      if (available >= h.size + h.length) {
        char* payload = buffer.data() + offset + h.size;
        if (h.masked)
          for (uint64_t i = 0; i < h.length; ++i) payload[i] = static_cast<char>(payload[i] ^ h.mask[i % 4]);
        offset += h.size + h.length;
        if (!Dispatch(h, std::string_view(payload, h.length))) return;
        continue;
      }
    }
    if (offset > 0) {  // keep only what is not parsed yet
      buffer.erase(0, offset);
      offset = 0;
    }
    char chunk[64 << 10];
    const ssize_t n = recv(fd, chunk, sizeof(chunk), 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;  // the peer closed, the link failed, or Close() shut the socket down
    buffer.append(chunk, static_cast<size_t>(n));
  }
}

// After Read: on_close unless Close() came first, then `done` for a Close() waiting.
void WsClient::State::End() {
  bool call = false;
  {
    std::lock_guard<std::mutex> lock(mutex);
    ended = true;
    call = !closed;
  }
  shutdown(fd, SHUT_RDWR);  // a writer blocked on a full window stops now
  if (call && callbacks.on_close) callbacks.on_close();
  {
    std::lock_guard<std::mutex> lock(mutex);
    done = true;
  }
  done_cv.notify_all();
}

StatusOr<std::unique_ptr<WsClient>> WsClient::Connect(const std::string& host, int port, const std::string& path_and_query,
                                                      Callbacks callbacks, std::chrono::milliseconds timeout) {
  const std::string path = path_and_query.substr(0, path_and_query.find('?'));
  const std::string where =
      "ws://" + (host.find(':') != std::string::npos ? "[" + host + "]" : host) + ":" + std::to_string(port) + path;
  if (path_and_query.empty() || path_and_query[0] != '/') return Status::InvalidArgument(where, "the path must start with '/'");
  const Clock::time_point deadline = Clock::now() + timeout;
  StatusOr<int> fd = ConnectSocket(host, port, deadline, where);
  if (!fd.ok()) return fd.status();
  auto state = std::make_shared<State>();
  state->fd = *fd;
  state->where = where;
  state->callbacks = std::move(callbacks);
  std::string rest;
  if (Status s = Handshake(state->fd, host, port, path_and_query, deadline, where, &rest); !s.ok()) return s;
  std::thread reader([state, rest = std::move(rest)]() mutable {
    reading_for = state.get();
    state->Read(std::move(rest));
    state->End();
  });
  // Detached: the thread holds the state it needs, and Close() waits for `done`, not for the
  // thread, so a WsClient can be closed and destroyed from its own callbacks.
  reader.detach();
  return std::unique_ptr<WsClient>(new WsClient(std::move(state)));
}

Status WsClient::SendText(std::string_view text, std::chrono::milliseconds timeout) {
  State& s = *state_;
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    if (s.ended || s.closed) return Status::FailedPrecondition(s.where, "the WebSocket is closed");
  }
  if (s.Write(EncodeFrame(kOpText, text), timeout)) return Status::OK();
  shutdown(s.fd, SHUT_RDWR);  // a frame half written: nothing after it can be read right; the link ends
  return Status::IOError(s.where, "cannot send a frame (the peer does not read, or the link failed)");
}

void WsClient::Close() {
  State& s = *state_;
  const bool own_thread = reading_for == &s;
  std::unique_lock<std::mutex> closing(s.close_mutex, std::defer_lock);
  if (!own_thread) closing.lock();  // a second Close() from outside waits for the first
  bool was_ended = false;
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    was_ended = s.ended;
    s.closed = s.ended = true;
  }
  if (!was_ended) {
    // Best effort, not waiting on a peer that does not read: the socket is shut down next.
    std::unique_lock<std::mutex> write(s.write_mutex, std::try_to_lock);
    for (int i = 0; i < 100 && !write.owns_lock(); ++i) {  // a frame being written: 100 ms for it
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      write.try_lock();
    }
    if (write.owns_lock()) (void)SendAll(s.fd, CloseFrame(1000), Clock::now());
  }
  shutdown(s.fd, SHUT_RDWR);  // the reading thread's recv returns
  if (own_thread) return;     // it ends after the callback that called this returns
  std::unique_lock<std::mutex> lock(s.mutex);
  s.done_cv.wait(lock, [&] { return s.done; });
}

WsClient::~WsClient() { Close(); }

}  // namespace dyad::web
