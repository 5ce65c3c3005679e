#pragma once
/// SHA-1 (FIPS 180-4) and base64 (RFC 4648), just what the WebSocket opening handshake (RFC 6455 §4.2.2) needs.
/// SHA-1 is used here only to prove the server read the client's key, never for security. Pure functions.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

namespace palpate {

/// The 20-byte SHA-1 digest of `data`.
std::array<uint8_t, 20> sha1(std::string_view data);

/// `data` in base64 with padding (RFC 4648 §4).
std::string base64(std::string_view data);

/// Sec-WebSocket-Accept for a client's Sec-WebSocket-Key: base64(SHA-1(key + the RFC 6455 GUID)).
std::string websocket_accept(std::string_view key);

}  // namespace palpate
