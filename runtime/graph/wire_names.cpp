// Opaque names of a secured graph's participants and certificates (dyad/wire_names.hpp):
// HMAC-SHA256 and AES-256-CTR from OpenSSL's libcrypto.
#include <dyad/wire_names.hpp>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <openssl/rand.h>

namespace dyad {
namespace {

constexpr size_t kKeyBytes = 32, kTagBytes = 16, kBlock = 48, kMaxPadded = 144;
constexpr const char* kPrefix = "dyad~";

std::string Hex(const unsigned char* p, size_t n) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (size_t i = 0; i < n; ++i) out += {digits[p[i] >> 4], digits[p[i] & 15]};
  return out;
}

const char* const kBase64Url = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_";

// base64url of `bytes`, whose size is a multiple of 3 (no padding needed): 4 characters per 3
// bytes where hex takes 6, so that a sealed name of 144 bytes fits a participant's name.
std::string Base64Url(const std::string& bytes) {
  std::string out;
  for (size_t i = 0; i + 2 < bytes.size(); i += 3) {
    const auto at = [&bytes](size_t k) { return static_cast<unsigned>(static_cast<unsigned char>(bytes[k])); };
    const unsigned v = at(i) << 16 | at(i + 1) << 8 | at(i + 2);
    for (int shift = 18; shift >= 0; shift -= 6) out += kBase64Url[(v >> shift) & 63];
  }
  return out;
}

// The bytes of `text` (base64url, a multiple of 4 characters, no padding); false on anything else.
bool UnBase64Url(const std::string& text, std::string* out) {
  if (text.size() % 4 != 0) return false;
  out->clear();
  for (size_t i = 0; i < text.size(); i += 4) {
    unsigned v = 0;
    for (size_t k = i; k < i + 4; ++k) {
      const char* at = std::strchr(kBase64Url, text[k]);
      if (text[k] == '\0' || at == nullptr) return false;
      v = v << 6 | static_cast<unsigned>(at - kBase64Url);
    }
    for (int shift = 16; shift >= 0; shift -= 8) out->push_back(static_cast<char>((v >> shift) & 255));
  }
  return true;
}

// The bytes of `hex` (even length, lowercase or uppercase digits); false on anything else.
bool Unhex(const std::string& hex, std::string* out) {
  if (hex.size() % 2 != 0) return false;
  auto digit = [](char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  out->clear();
  for (size_t i = 0; i < hex.size(); i += 2) {
    const int hi = digit(hex[i]), lo = digit(hex[i + 1]);
    if (hi < 0 || lo < 0) return false;
    out->push_back(static_cast<char>(hi * 16 + lo));
  }
  return true;
}

// False when libcrypto fails: `mac` is then not a MAC (all zeros would reuse one keystream).
bool Hmac(const std::string& key, const std::string& text, std::array<unsigned char, 32>* mac) {
  unsigned int n = 0;
  return HMAC(EVP_sha256(), key.data(), static_cast<int>(key.size()), reinterpret_cast<const unsigned char*>(text.data()),
              text.size(), mac->data(), &n) != nullptr &&
         n == mac->size();
}

// One of the two keys derived from the names key: "mac" or "enc"; "" when libcrypto fails.
std::string Derived(const std::string& key, const char* label) {
  std::array<unsigned char, 32> d{};
  if (!Hmac(key, std::string("dyad wire names: ") + label, &d)) return "";
  return std::string(reinterpret_cast<const char*>(d.data()), d.size());
}

// False when libcrypto fails.
bool Tag(const std::string& key, const std::string& name, std::array<unsigned char, kTagBytes>* tag) {
  const std::string mac_key = Derived(key, "mac");
  std::array<unsigned char, 32> mac{};
  if (mac_key.empty() || !Hmac(mac_key, name, &mac)) return false;
  std::copy(mac.begin(), mac.begin() + kTagBytes, tag->begin());
  return true;
}

// AES-256-CTR of `text` with IV `tag` (encrypting and decrypting are the same).
std::string Ctr(const std::string& key, const std::array<unsigned char, kTagBytes>& tag, const std::string& text) {
  const std::string k = Derived(key, "enc");
  if (k.empty()) return "";
  std::unique_ptr<EVP_CIPHER_CTX, void (*)(EVP_CIPHER_CTX*)> ctx(EVP_CIPHER_CTX_new(), &EVP_CIPHER_CTX_free);
  const auto* k_bytes = reinterpret_cast<const unsigned char*>(k.data());
  std::string out(text.size(), '\0');
  int n = 0;
  if (!ctx || EVP_EncryptInit_ex(ctx.get(), EVP_aes_256_ctr(), nullptr, k_bytes, tag.data()) != 1 ||
      EVP_EncryptUpdate(ctx.get(), reinterpret_cast<unsigned char*>(out.data()), &n,
                        reinterpret_cast<const unsigned char*>(text.data()), static_cast<int>(text.size())) != 1 ||
      static_cast<size_t>(n) != text.size())
    return "";
  return out;
}

}  // namespace

StatusOr<std::string> ReadNamesKey(const std::string& path) {
  // Never through a link, never a special file (a FIFO or /dev/zero would hang or never end).
  const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0 && errno == ENOENT)
    return Status::NotFound(path + ": the keystore's names key is missing (run `dyad security init` on the keystore)");
  if (fd < 0 && errno == ELOOP)
    return Status::FailedPrecondition(path, "a symbolic link (refused: the names key is read only from a regular file)");
  if (fd < 0) return Status::IOError(path, std::string("open: ") + std::strerror(errno));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0) return Status::IOError(path, std::string("stat: ") + std::strerror(errno));
  if (!S_ISREG(st.st_mode))
    return Status::FailedPrecondition(path, "not a regular file (the names key is a file of 64 hex digits)");
  if ((st.st_mode & 077) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
    return Status::FailedPrecondition(path, std::string("the names key readable by others (mode ") + mode + "; chmod 600 it)");
  }
  char buf[2 * kKeyBytes + 2];
  ssize_t got = 0, r = 0;
  while (got < static_cast<ssize_t>(sizeof buf) && (r = ::read(fd, buf + got, sizeof buf - got)) > 0) got += r;
  if (r < 0) return Status::IOError(path, std::string("read: ") + std::strerror(errno));
  std::string text(buf, static_cast<size_t>(got)), key;
  if (!text.empty() && text.back() == '\n') text.pop_back();
  if (text.size() != 2 * kKeyBytes || !Unhex(text, &key))
    return Status::InvalidArgument(path + ": not a names key (expected 64 hex digits, as `dyad security init` writes)");
  return key;
}

StatusOr<std::string> NewNamesKeyText() {
  std::array<unsigned char, kKeyBytes> key{};
  if (RAND_bytes(key.data(), static_cast<int>(key.size())) != 1) return Status::Internal("cannot draw a names key (RAND_bytes)");
  return Hex(key.data(), key.size()) + "\n";
}

std::string WireSubject(const std::string& key, const std::string& name) {
  std::array<unsigned char, kTagBytes> tag{};
  if (!Tag(key, name, &tag)) return "";
  return kPrefix + Hex(tag.data(), tag.size());
}

std::string WireName(const std::string& key, const std::string& name) {
  std::array<unsigned char, kTagBytes> tag{};
  if (!Tag(key, name, &tag)) return "";
  static_assert(kMaxReadableName < kMaxPadded, "a zero byte of padding ends the longest name");
  if (name.size() > kMaxReadableName) return "";
  const std::string subject = kPrefix + Hex(tag.data(), tag.size());
  std::string padded = name;
  padded.resize(name.size() < kBlock ? kBlock : kMaxPadded, '\0');
  const std::string sealed = Ctr(key, tag, padded);
  if (sealed.empty()) return "";
  return subject + "." + Base64Url(sealed);
}

std::string ReadableName(const std::string& key, const std::string& wire) {
  const size_t dot = wire.find('.');
  const std::string prefix = kPrefix;
  if (wire.rfind(prefix, 0) != 0 || dot != prefix.size() + 2 * kTagBytes) return "";
  std::string tag_bytes, sealed;
  if (!Unhex(wire.substr(prefix.size(), 2 * kTagBytes), &tag_bytes) || !UnBase64Url(wire.substr(dot + 1), &sealed)) return "";
  if (sealed.size() != kBlock && sealed.size() != kMaxPadded) return "";
  std::array<unsigned char, kTagBytes> tag{}, check{};
  std::copy(tag_bytes.begin(), tag_bytes.end(), tag.begin());
  std::string name = Ctr(key, tag, sealed);
  name.erase(name.find_last_not_of('\0') + 1);
  // The tag authenticates the name: a forgery, or another key's, decrypts to something else.
  if (name.empty() || name.find('\0') != std::string::npos || !Tag(key, name, &check)) return "";
  if (CRYPTO_memcmp(check.data(), tag.data(), kTagBytes) != 0) return "";
  return name;
}

}  // namespace dyad
