#include "web_server.hpp"

#include <civetweb.h>

#include <atomic>
#include <cstring>

namespace dyad::web {
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

std::string QueryValue(const char* query, const std::string& key) {
  if (query == nullptr) return "";
  char buf[512];
  const int n = mg_get_var(query, std::strlen(query), key.c_str(), buf, sizeof(buf));
  return n >= 0 ? std::string(buf, static_cast<size_t>(n)) : "";
}

bool IsLoopback(const std::string& address) {
  return address.rfind("127.", 0) == 0 || address == "localhost" || address == "::1";
}

}  // namespace

struct WebServer::Client {
  ClientId id = 0;
  mg_connection* conn = nullptr;
  SendQueue queue;
  std::mutex write_mutex;  // held while writing; closing takes it, so no write outlives the connection
  bool closed = false;
  std::thread sender;
  explicit Client(size_t limit) : queue(limit) {}
};

StatusOr<std::unique_ptr<WebServer>> WebServer::Start(const Options& options, ClientHandler* handler) {
  mg_init_library(MG_FEATURES_WEBSOCKET | MG_FEATURES_FILES);
  std::unique_ptr<WebServer> s(new WebServer());
  s->options_ = options;
  s->handler_ = handler;
  const std::string ports = (options.address.find(':') != std::string::npos ? "[" + options.address + "]" : options.address) +
                            ":" + std::to_string(options.port);
  const std::string threads = std::to_string(options.max_clients + 4);
  std::vector<const char*> opts = {"listening_ports", ports.c_str(), "num_threads", threads.c_str(),
                                   "request_timeout_ms", "5000", "websocket_timeout_ms", "3600000",
                                   "enable_directory_listing", "no"};
  if (!options.document_root.empty()) opts.insert(opts.end(), {"document_root", options.document_root.c_str()});
  opts.push_back(nullptr);
  mg_callbacks callbacks{};
  callbacks.log_message = [](const mg_connection*, const char*) { return 1; };  // no stderr noise per client
  s->ctx_ = mg_start(&callbacks, s.get(), opts.data());
  if (s->ctx_ == nullptr)
    return Status::IOError("web server: cannot listen on " + ports + " (in use, or not an address of this machine)");
  mg_server_port sp[4];
  const int n = mg_get_server_ports(s->ctx_, 4, sp);
  s->port_ = n > 0 ? sp[0].port : options.port;
  for (const auto& p : s->options_.subprotocols) s->subprotocol_ptrs_.push_back(p.c_str());
  // civetweb keeps the pointer: the struct lives as long as the server.
  s->subprotocols_ = std::make_unique<mg_websocket_subprotocols>();
  s->subprotocols_->nb_subprotocols = static_cast<int>(s->subprotocol_ptrs_.size());
  s->subprotocols_->subprotocols = s->subprotocol_ptrs_.data();
  mg_set_websocket_handler_with_subprotocols(s->ctx_, "/", s->subprotocols_.get(), &WebServer::OnConnect, &WebServer::OnReady,
                                             &WebServer::OnData, &WebServer::OnClosed, s.get());
  return s;
}

WebServer::~WebServer() {
  if (ctx_ != nullptr) mg_stop(ctx_);  // closes every connection (OnClosed joins each sender)
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto& [id, c] : clients_) {
    c->queue.Close();
    if (c->sender.joinable()) c->sender.join();
  }
}

bool WebServer::OriginAllowed(const std::string& origin) const {
  for (const auto& o : options_.allowed_origins)
    if (o == "*" || o == origin) return true;
  if (IsLoopback(options_.address)) {
    for (const char* local : {"http://localhost", "http://127.0.0.1", "https://localhost", "https://127.0.0.1"}) {
      const std::string l(local);
      if (origin == l || origin.rfind(l + ":", 0) == 0) return true;
    }
  }
  return false;
}

int WebServer::OnConnect(const mg_connection* conn, void* self_ptr) {
  auto* self = static_cast<WebServer*>(self_ptr);
  const mg_request_info* info = mg_get_request_info(conn);
  if (const char* origin = mg_get_header(conn, "Origin"); origin != nullptr && !self->OriginAllowed(origin)) return 1;
  if (!self->options_.token.empty() && QueryValue(info->query_string, "token") != self->options_.token) return 1;
  std::lock_guard<std::mutex> lock(self->mutex_);
  if (static_cast<int>(self->admitted_.size()) >= self->options_.max_clients) return 1;
  self->admitted_.insert(conn);
  return 0;
}

void WebServer::OnReady(mg_connection* conn, void* self_ptr) {
  auto* self = static_cast<WebServer*>(self_ptr);
  auto c = std::make_shared<Client>(self->options_.client_buffer_bytes);
  c->conn = conn;
  {
    std::lock_guard<std::mutex> lock(self->mutex_);
    c->id = self->next_id_++;
    self->clients_[c->id] = c;
    self->by_conn_[conn] = c->id;
  }
  Client* raw = c.get();
  c->sender = std::thread([raw] {
    Frame f;
    while (raw->queue.Pop(&f)) {
      std::lock_guard<std::mutex> lock(raw->write_mutex);
      if (raw->closed) break;
      const int op = f.binary ? MG_WEBSOCKET_OPCODE_BINARY : MG_WEBSOCKET_OPCODE_TEXT;
      if (mg_websocket_write(raw->conn, op, f.bytes.data(), f.bytes.size()) <= 0) break;
    }
  });
  self->handler_->OnOpen(c->id);
}

int WebServer::OnData(mg_connection* conn, int bits, char* data, size_t len, void* self_ptr) {
  auto* self = static_cast<WebServer*>(self_ptr);
  ClientId id = 0;
  {
    std::lock_guard<std::mutex> lock(self->mutex_);
    auto it = self->by_conn_.find(conn);
    if (it == self->by_conn_.end()) return 0;
    id = it->second;
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
  if (opcode == MG_WEBSOCKET_OPCODE_TEXT) s = self->handler_->OnText(id, std::string_view(data, len));
  else if (opcode == MG_WEBSOCKET_OPCODE_BINARY)
    s = self->handler_->OnBinary(id, std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(data), len));
  else s = Status::InvalidArgument("unknown opcode " + std::to_string(opcode));
  if (!s.ok()) {
    WriteClose(conn, kClosePolicy, s.message());
    return 0;
  }
  return 1;
}

void WebServer::OnClosed(const mg_connection* conn, void* self_ptr) {
  auto* self = static_cast<WebServer*>(self_ptr);
  std::shared_ptr<Client> c;
  {
    std::lock_guard<std::mutex> lock(self->mutex_);
    self->admitted_.erase(conn);
    auto it = self->by_conn_.find(conn);
    if (it == self->by_conn_.end()) return;  // rejected before it was ready
    c = self->clients_[it->second];
    self->clients_.erase(it->second);
    self->by_conn_.erase(it);
  }
  c->queue.Close();
  {
    std::lock_guard<std::mutex> lock(c->write_mutex);  // waits for a write in progress
    c->closed = true;
  }
  if (c->sender.joinable()) c->sender.join();
  self->handler_->OnClose(c->id);
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

std::map<uint32_t, uint64_t> WebServer::TakeDrops(ClientId client) {
  if (auto c = Find(client)) return c->queue.TakeDrops();
  return {};
}

std::vector<ClientId> WebServer::clients() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<ClientId> out;
  for (const auto& [id, c] : clients_) out.push_back(id);
  return out;
}

}  // namespace dyad::web
