#include "rpem/auth/mac.hpp"

#include <sodium.h>

#include <utility>

#include "rpem/core/assert.hpp"

namespace rpem::auth {

bool Keyring::add(Key&& key) noexcept {
  if (n_ >= kMaxKeys || key.id() <= 0 || key.empty() || find(key.id()) != nullptr) return false;
  keys_[static_cast<std::size_t>(n_++)] = std::move(key);
  return true;
}

const Key* Keyring::find(std::int32_t id) const noexcept {
  for (int k = 0; k < n_; ++k) {
    if (keys_[static_cast<std::size_t>(k)].id() == id) return &keys_[static_cast<std::size_t>(k)];
  }
  return nullptr;
}

Tag compute_tag(const Key& key, std::string_view channel, std::span<const std::uint8_t> covered) noexcept {
  RPEM_ASSERT(!key.empty(), "a tag is computed with a key, not an empty or moved-from one");
  static constexpr unsigned char kZero = 0;
  crypto_auth_hmacsha256_state state;
  crypto_auth_hmacsha256_init(&state, key.bytes().data(), key.bytes().size());
  crypto_auth_hmacsha256_update(&state, reinterpret_cast<const unsigned char*>(kDomain.data()), kDomain.size());
  crypto_auth_hmacsha256_update(&state, &kZero, 1);
  crypto_auth_hmacsha256_update(&state, reinterpret_cast<const unsigned char*>(channel.data()), channel.size());
  crypto_auth_hmacsha256_update(&state, &kZero, 1);
  crypto_auth_hmacsha256_update(&state, covered.data(), covered.size());
  Tag tag{};
  crypto_auth_hmacsha256_final(&state, tag.data());
  sodium_memzero(&state, sizeof state);
  return tag;
}

std::int32_t key_id_of(std::span<const std::uint8_t> encoded) noexcept {
  if (encoded.size() < kTrailerBytes) return 0;
  const std::uint8_t* p = encoded.data() + encoded.size() - kTrailerBytes;
  const std::uint32_t u = (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3];
  return static_cast<std::int32_t>(u);
}

bool sign(const Key& key, std::string_view channel, std::span<std::uint8_t> encoded) noexcept {
  if (encoded.size() < kTrailerBytes || key_id_of(encoded) != key.id()) return false;
  const std::size_t covered = encoded.size() - kMacBytes;
  const Tag tag = compute_tag(key, channel, encoded.first(covered));
  std::copy(tag.begin(), tag.end(), encoded.begin() + static_cast<std::ptrdiff_t>(covered));
  return true;
}

const char* to_string(Verdict v) noexcept {
  switch (v) {
    case Verdict::kVerified:
      return "verified";
    case Verdict::kUnsigned:
      return "unsigned";
    case Verdict::kUnknownKey:
      return "unknown key";
    case Verdict::kBadMac:
      return "bad MAC";
    case Verdict::kMalformed:
      return "malformed";
  }
  return "?";
}

Verdict verify(const Keyring& keys, std::string_view channel, std::span<const std::uint8_t> encoded) noexcept {
  if (encoded.size() < kTrailerBytes) return Verdict::kMalformed;
  const std::int32_t id = key_id_of(encoded);
  if (id == 0) return Verdict::kUnsigned;
  const Key* key = keys.find(id);
  if (key == nullptr) return Verdict::kUnknownKey;
  const std::size_t covered = encoded.size() - kMacBytes;
  const Tag tag = compute_tag(*key, channel, encoded.first(covered));
  return crypto_verify_32(tag.data(), encoded.data() + covered) == 0 ? Verdict::kVerified : Verdict::kBadMac;
}

}  // namespace rpem::auth
