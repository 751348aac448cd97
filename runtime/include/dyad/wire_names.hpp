// dyad/wire_names.hpp — what a secured graph's participants are called where anyone can read it.
//
// DDS sends a participant's name, and the subject of its certificate, in clear: in every
// discovery announcement and every authentication handshake, to anyone who can reach the graph,
// a stranger with a certificate of another CA included. In a graph with `security:` neither
// names the graph, a process or a host: they are made with the keystore's names key
// (`names.key` beside `identity_ca.cert.pem`, 32 random bytes as 64 hex digits, mode 0600,
// written once by `dyad security init`). Every identity of the graph holds it; a stranger does
// not, so to a stranger the names are random-looking and only equal to themselves.
//
//   WireSubject(key, name)  "dyad~" + 32 hex digits: HMAC-SHA256(key, name) cut to 128 bits.
//                           A certificate's subject (CN=...): nothing needs to read it back.
//   WireName(key, name)     WireSubject(key, name) + "." + the name encrypted (AES-256-CTR, the
//                           HMAC as its IV: a synthetic IV, so the same name gives the same
//                           text), padded with zero bytes to 48 or 144 bytes so that its length
//                           says little, in base64url (64 or 192 characters: at most 230 in all,
//                           under Fast DDS's 255). A participant's name: the graph's participants
//                           read it back (ReadableName) to report and match their peers by name.
//                           A name has at most kMaxReadableName bytes (143, so that the padding
//                           ends it): every dyad/<graph>/<process> and dyad/launcher/<host> fits
//                           (names of 64 characters each; graph.cpp asserts it), and WireName
//                           returns "" for a longer one: its participant is refused, never left
//                           unreadable. (Fast DDS keeps a participant's name in a string_255 and
//                           cuts a longer one silently: the largest bucket under it would be 162
//                           bytes, 38 + 216 characters; nothing the graph names needs it.)
//   ReadableName(key, wire) the name, when `wire` is a WireName made with this key; "" for
//                           anything else (another graph's, a forgery, a plain name).
// WireSubject and WireName return "" when libcrypto fails (callers refuse to go on).
//
// Both are the same for every run of the graph (docs/security.md, "Names on the wire", says
// why). The key is derived into two (one for the HMAC, one for AES) by HMAC with fixed labels.
#pragma once

#include <cstddef>
#include <string>

#include <dyad/status.hpp>

namespace dyad {

inline constexpr const char* kNamesKeyFile = "names.key";
// The longest participant name a WireName holds (and its peers read back), in bytes.
inline constexpr size_t kMaxReadableName = 143;

// The key in the file at `path` (64 hex digits, then an optional newline): 32 raw bytes. An
// error names the file and says to run `dyad security init` when it is missing. The file must be
// a regular file (a symbolic link or a special file is refused) that only its owner can read.
StatusOr<std::string> ReadNamesKey(const std::string& path);
// A new key file's text: 64 hex digits from the system's random source, and a newline.
StatusOr<std::string> NewNamesKeyText();

std::string WireSubject(const std::string& key, const std::string& name);
std::string WireName(const std::string& key, const std::string& name);
std::string ReadableName(const std::string& key, const std::string& wire);

}  // namespace dyad
