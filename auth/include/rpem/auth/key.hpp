#pragma once
// A key as libsodium intends it (docs/rpemd.md, "Keys"): its bytes in memory of their own from
// sodium_malloc — locked into RAM (never swapped out, left out of core dumps), between guard pages —
// read-only once written, and wiped with sodium_memzero before they are freed. A key cannot be copied:
// each exists once, and moving it moves the owner, not the bytes. libsodium is initialised once per
// process (initialise(): rpemd's and rpem's start-up, and before the first key in any case).

#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>

namespace rpem::auth {

inline constexpr std::size_t kKeyBytes = 32;

/// A key that cannot be made or used: names the file (or what) and why.
class KeyError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// libsodium's sodium_init(), run once per process whoever calls first (thread-safe); later calls
/// return at once. Throws KeyError if libsodium cannot be used.
void initialise();

class Key {
 public:
  using Bytes = std::span<const std::uint8_t, kKeyBytes>;

  /// No key: no bytes, id 0 (as a key moved from).
  Key() noexcept = default;
  /// Key `id` with a copy of `bytes` in locked memory (wiping the caller's copy is the caller's).
  /// Throws KeyError if locked memory cannot be had.
  Key(std::int32_t id, Bytes bytes);
  /// Key `id` whose bytes `fill(std::span<std::uint8_t, kKeyBytes>)` writes in place, so they never exist
  /// anywhere else (a key file's hex decoded, random bytes). If `fill` throws, the bytes are wiped.
  template <class Fill>
  [[nodiscard]] static Key filled(std::int32_t id, Fill&& fill) {
    Key key = allocate(id);
    fill(std::span<std::uint8_t, kKeyBytes>(key.bytes_, kKeyBytes));
    key.seal();
    return key;
  }

  Key(Key&& other) noexcept;
  Key& operator=(Key&& other) noexcept;
  Key(const Key&) = delete;             // one copy of each key
  Key& operator=(const Key&) = delete;  // one copy of each key
  /// Wipes the bytes (sodium_memzero), then frees them (sodium_free).
  ~Key();

  [[nodiscard]] std::int32_t id() const noexcept { return id_; }
  [[nodiscard]] bool empty() const noexcept { return bytes_ == nullptr; }
  /// The key's bytes (read-only memory); not for an empty key.
  [[nodiscard]] Bytes bytes() const noexcept;

 private:
  [[nodiscard]] static Key allocate(std::int32_t id);
  void seal() noexcept;
  void release() noexcept;

  std::int32_t id_ = 0;
  std::uint8_t* bytes_ = nullptr;  ///< kKeyBytes from sodium_malloc
};

}  // namespace rpem::auth
