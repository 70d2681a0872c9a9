#include "rpem/auth/key.hpp"

#include <sodium.h>

#include <algorithm>
#include <utility>

#include "rpem/core/assert.hpp"

namespace rpem::auth {

void initialise() {
  static const bool usable = sodium_init() >= 0;  // once per process, on the first call
  if (!usable) throw KeyError("libsodium cannot be initialised");
}

Key Key::allocate(std::int32_t id) {
  initialise();
  Key key;
  key.bytes_ = static_cast<std::uint8_t*>(sodium_malloc(kKeyBytes));
  if (key.bytes_ == nullptr) throw KeyError("no locked memory for a key (sodium_malloc)");
  key.id_ = id;
  return key;
}

Key::Key(std::int32_t id, Bytes bytes)
    : Key(filled(id, [&](std::span<std::uint8_t, kKeyBytes> out) { std::copy(bytes.begin(), bytes.end(), out.begin()); })) {}

void Key::seal() noexcept { (void)sodium_mprotect_readonly(bytes_); }

void Key::release() noexcept {
  if (bytes_ == nullptr) return;
  (void)sodium_mprotect_readwrite(bytes_);
  sodium_memzero(bytes_, kKeyBytes);
  sodium_free(bytes_);
  bytes_ = nullptr;
  id_ = 0;
}

Key::Key(Key&& other) noexcept : id_(std::exchange(other.id_, 0)), bytes_(std::exchange(other.bytes_, nullptr)) {}

Key& Key::operator=(Key&& other) noexcept {
  if (this != &other) {
    release();
    id_ = std::exchange(other.id_, 0);
    bytes_ = std::exchange(other.bytes_, nullptr);
  }
  return *this;
}

Key::~Key() { release(); }

Key::Bytes Key::bytes() const noexcept {
  RPEM_ASSERT(!empty(), "the bytes of a key, not of an empty or moved-from one");
  return Bytes(bytes_, kKeyBytes);
}

}  // namespace rpem::auth
