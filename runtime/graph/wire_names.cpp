// Opaque names of a secured graph's participants and certificates (dyad/wire_names.hpp):
// HMAC-SHA256 and AES-256-CTR from OpenSSL's libcrypto.
#include <dyad/wire_names.hpp>

#include <array>
#include <fstream>
#include <memory>
#include <sstream>

#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <openssl/rand.h>

namespace dyad {
namespace {

constexpr size_t kKeyBytes = 32, kTagBytes = 16, kBlock = 48, kMaxPadded = 96;
constexpr const char* kPrefix = "dyad~";

std::string Hex(const unsigned char* p, size_t n) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (size_t i = 0; i < n; ++i) out += {digits[p[i] >> 4], digits[p[i] & 15]};
  return out;
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

std::array<unsigned char, 32> Hmac(const std::string& key, const std::string& text) {
  std::array<unsigned char, 32> mac{};
  unsigned int n = 0;
  HMAC(EVP_sha256(), key.data(), static_cast<int>(key.size()), reinterpret_cast<const unsigned char*>(text.data()), text.size(),
       mac.data(), &n);
  return mac;
}

// One of the two keys derived from the names key: "mac" or "enc".
std::string Derived(const std::string& key, const char* label) {
  const auto d = Hmac(key, std::string("dyad wire names: ") + label);
  return std::string(reinterpret_cast<const char*>(d.data()), d.size());
}

std::array<unsigned char, kTagBytes> Tag(const std::string& key, const std::string& name) {
  const auto mac = Hmac(Derived(key, "mac"), name);
  std::array<unsigned char, kTagBytes> tag{};
  std::copy(mac.begin(), mac.begin() + kTagBytes, tag.begin());
  return tag;
}

// AES-256-CTR of `text` with IV `tag` (encrypting and decrypting are the same).
std::string Ctr(const std::string& key, const std::array<unsigned char, kTagBytes>& tag, const std::string& text) {
  const std::string k = Derived(key, "enc");
  std::unique_ptr<EVP_CIPHER_CTX, void (*)(EVP_CIPHER_CTX*)> ctx(EVP_CIPHER_CTX_new(), &EVP_CIPHER_CTX_free);
  const auto* k_bytes = reinterpret_cast<const unsigned char*>(k.data());
  std::string out(text.size(), '\0');
  int n = 0;
  if (!ctx || EVP_EncryptInit_ex(ctx.get(), EVP_aes_256_ctr(), nullptr, k_bytes, tag.data()) != 1 ||
      EVP_EncryptUpdate(ctx.get(), reinterpret_cast<unsigned char*>(out.data()), &n,
                        reinterpret_cast<const unsigned char*>(text.data()), static_cast<int>(text.size())) != 1)
    return "";
  return out;
}

}  // namespace

StatusOr<std::string> ReadNamesKey(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound(path + ": the keystore's names key is missing (run `dyad security init` on the keystore)");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str(), key;
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
  const auto tag = Tag(key, name);
  return kPrefix + Hex(tag.data(), tag.size());
}

std::string WireName(const std::string& key, const std::string& name) {
  const std::string subject = WireSubject(key, name);
  if (name.size() >= kMaxPadded) return subject;
  std::string padded = name;
  padded.resize(name.size() < kBlock ? kBlock : kMaxPadded, '\0');
  const std::string sealed = Ctr(key, Tag(key, name), padded);
  return subject + "." + Hex(reinterpret_cast<const unsigned char*>(sealed.data()), sealed.size());
}

std::string ReadableName(const std::string& key, const std::string& wire) {
  const size_t dot = wire.find('.');
  const std::string prefix = kPrefix;
  if (wire.rfind(prefix, 0) != 0 || dot != prefix.size() + 2 * kTagBytes) return "";
  std::string tag_bytes, sealed;
  if (!Unhex(wire.substr(prefix.size(), 2 * kTagBytes), &tag_bytes) || !Unhex(wire.substr(dot + 1), &sealed)) return "";
  if (sealed.size() != kBlock && sealed.size() != kMaxPadded) return "";
  std::array<unsigned char, kTagBytes> tag{};
  std::copy(tag_bytes.begin(), tag_bytes.end(), tag.begin());
  std::string name = Ctr(key, tag, sealed);
  name.erase(name.find_last_not_of('\0') + 1);
  // The tag authenticates the name: a forgery, or another key's, decrypts to something else.
  if (name.empty() || name.find('\0') != std::string::npos || Tag(key, name) != tag) return "";
  return name;
}

}  // namespace dyad
