#pragma once
// RPEM_ESTIMATE messages as rpemd sends them: encoded by lcm-gen's class and signed by auth/ (the code
// rpemd's publisher signs with), under a test key. For the supervisor's tests.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "rpem/auth/mac.hpp"
#include "rpem/estimate_t.hpp"

namespace rpem::test {

/// A utime in 2026 [µs]: the instant the supervisor's and the gate's tests send their estimates at.
inline constexpr std::int64_t kT0 = 1'790'000'000'000'000;

/// A test key: bytes 0x40 + `salt`, 0x41 + `salt`, … under `id`.
inline auth::Key test_key(std::int32_t id, std::uint8_t salt = 0) {
  std::array<std::uint8_t, auth::kKeyBytes> bytes{};
  for (std::size_t k = 0; k < bytes.size(); ++k) bytes[k] = static_cast<std::uint8_t>(0x40 + salt + k);
  return auth::Key(id, bytes);
}

/// A running rpemd's estimate at `utime_us` (sample time utime − 1 s): both temperatures raw and valid,
/// adapting; no thermal model.
inline rpem::estimate_t raw_estimate(std::int64_t utime_us, double t_magnet_C, double t_winding_C) {
  rpem::estimate_t m{};
  m.utime = utime_us;
  m.sample_time_us = utime_us - 1'000'000;
  m.samples = 1000;
  m.t_magnet_C = t_magnet_C;
  m.t_winding_C = t_winding_C;
  m.psi_m_valid = m.r_s_valid = true;
  m.psi_m_converged = m.r_s_converged = true;
  m.psi_m_age_s = m.r_s_age_s = 0.0;
  m.state = 1;
  m.algorithm = "sga";
  m.t_magnet_observed_age_s = m.t_winding_observed_age_s = -1.0;
  return m;
}

/// `m` encoded, with key id `key`'s, signed for `channel` (unsigned: key id 0, tag zero, if `key` is null).
inline std::vector<std::uint8_t> encode_signed(rpem::estimate_t m, const auth::Key* key,
                                               const std::string& channel = "RPEM_ESTIMATE") {
  m.key_id = key ? key->id() : 0;
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  if (key) auth::sign(*key, channel, bytes);
  return bytes;
}

}  // namespace rpem::test
