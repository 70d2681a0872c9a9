#pragma once
// Authenticated LCM messages (docs/rpemd.md, "Authentication"). An authenticated message type ends with
// two fields, in this order:
//     int32_t key_id;    // 0: unsigned
//     byte    mac[32];
// so its LCM encoding E (n bytes: the 8-byte type fingerprint, then every field in declaration order,
// big-endian) ends with the 4-byte key id and the 32-byte tag. The tag is
//     mac = HMAC-SHA256(key, "rpem-auth-1" ‖ 0x00 ‖ channel ‖ 0x00 ‖ E[0, n−32))
// — every field including the key id, the type (its fingerprint) and the full channel name (with its
// prefix), so a valid estimate can never pass as a command, nor a command for one rpemd as one for
// another. HMAC-SHA256 from libsodium (crypto_auth_hmacsha256_*), compared in constant time
// (crypto_verify_32). Nothing here allocates or throws: the publisher and control threads call it per
// message. Keys: key.hpp.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "rpem/auth/key.hpp"

namespace rpem::auth {

inline constexpr std::size_t kMacBytes = 32;
inline constexpr std::size_t kTrailerBytes = 4 + kMacBytes;  ///< key_id and mac at the end of E
inline constexpr std::string_view kDomain{"rpem-auth-1"};
inline constexpr int kMaxKeys = 2;  ///< accepted at once: the current key and, during a rotation, the next

using Tag = std::array<std::uint8_t, kMacBytes>;

/// The accepted keys (at most kMaxKeys, distinct ids), held here and nowhere else.
class Keyring {
 public:
  /// Takes the key; false (and the key left with the caller) if full, the id is not positive or
  /// already present.
  bool add(Key&& key) noexcept;
  [[nodiscard]] const Key* find(std::int32_t id) const noexcept;
  [[nodiscard]] int size() const noexcept { return n_; }
  [[nodiscard]] bool empty() const noexcept { return n_ == 0; }
  [[nodiscard]] const Key& operator[](int k) const noexcept { return keys_[static_cast<std::size_t>(k)]; }

 private:
  std::array<Key, kMaxKeys> keys_{};
  int n_ = 0;
};

/// HMAC-SHA256 of the canonical string above; `covered` is E[0, n−32).
[[nodiscard]] Tag compute_tag(const Key& key, std::string_view channel, std::span<const std::uint8_t> covered) noexcept;

/// The key id of an encoded authenticated message (E[n−36, n−32), big-endian); 0 if too short.
[[nodiscard]] std::int32_t key_id_of(std::span<const std::uint8_t> encoded) noexcept;

/// Signs an encoding in place: `encoded` was produced with key_id = key.id; its last 32 bytes become
/// the tag. False if it is too short to hold the trailer or the key id in it is not key.id.
bool sign(const Key& key, std::string_view channel, std::span<std::uint8_t> encoded) noexcept;

enum class Verdict : std::int8_t {
  kVerified,    ///< the tag is right under the key its key id names
  kUnsigned,    ///< key id 0
  kUnknownKey,  ///< a key id the keyring does not hold
  kBadMac,      ///< the key is known, the tag wrong: altered or forged
  kMalformed,   ///< shorter than the trailer
};
[[nodiscard]] const char* to_string(Verdict v) noexcept;

/// Checks an encoded authenticated message that has decoded exactly as its type.
[[nodiscard]] Verdict verify(const Keyring& keys, std::string_view channel, std::span<const std::uint8_t> encoded) noexcept;

}  // namespace rpem::auth
