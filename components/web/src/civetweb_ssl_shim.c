/* libdyad_civetweb_ssl.so: OpenSSL 3 as Debian's civetweb 1.15 expects to find it.
 *
 * civetweb loads "libssl.so" with dlopen and looks up each function it uses; one of them,
 * SSL_get_peer_certificate, is a macro in OpenSSL 3 (for SSL_get1_peer_certificate, the same
 * contract: a new reference the caller frees), so the lookup fails and civetweb calls a null
 * pointer on the first TLS connection. This library's SONAME is "libssl.so": once loaded (by
 * web_server.cpp, before civetweb initialises TLS), civetweb's dlopen("libssl.so") returns it, and
 * lookups through it reach the real libssl.so.3 it links. Nothing else is defined here. */
#include <openssl/ssl.h>

#undef SSL_get_peer_certificate
X509* SSL_get_peer_certificate(const SSL* ssl);
__attribute__((visibility("default"))) X509* SSL_get_peer_certificate(const SSL* ssl) {
  return SSL_get1_peer_certificate(ssl);
}
