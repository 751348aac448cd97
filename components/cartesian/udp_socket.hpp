/// UdpSocket: an owned, non-blocking IPv4 UDP socket (RAII; move-only). No allocation after Open.
#pragma once

#include <netinet/in.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include <dyad/status.hpp>

namespace dyad::cartesian {

class UdpSocket {
 public:
  // Binds 0.0.0.0:`local_port` (0: an ephemeral port).
  static StatusOr<UdpSocket> Open(uint16_t local_port);
  // "host" as a dotted quad or a name (resolved once, here).
  static StatusOr<sockaddr_in> Resolve(const std::string& host, uint16_t port);

  UdpSocket(UdpSocket&& other) noexcept : fd_(other.fd_) { other.fd_ = -1; }
  UdpSocket& operator=(UdpSocket&& other) noexcept;
  UdpSocket(const UdpSocket&) = delete;
  UdpSocket& operator=(const UdpSocket&) = delete;
  ~UdpSocket();

  Status SendTo(const void* data, size_t size, const sockaddr_in& to);
  // Size of the next datagram (its full size, even when longer than `capacity`; only `capacity`
  // bytes are stored; 0 for an empty one); *from gets the sender. kNothing when none is
  // waiting; another negative value is a socket error (-errno), e.g. -ECONNREFUSED after an
  // ICMP port-unreachable.
  static constexpr long kNothing = -11;  // -EAGAIN
  long Receive(uint8_t* buffer, size_t capacity, sockaddr_in* from);
  // Waits up to `timeout_ms` for a datagram; true when one is waiting.
  bool WaitReadable(int timeout_ms);
  uint16_t local_port() const;

 private:
  explicit UdpSocket(int fd) : fd_(fd) {}
  int fd_ = -1;
};

std::string ToString(const sockaddr_in& address);  // "127.0.0.1:47000"

}  // namespace dyad::cartesian
