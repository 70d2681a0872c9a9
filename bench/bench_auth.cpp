// The cost of authenticating rpemd's LCM messages (docs/benchmarks.md, "Message authentication"):
// HMAC-SHA256 (libsodium) over each message type's canonical string, as the publisher signs
// RPEM_ESTIMATE and RPEM_DIAGNOSTICS and the control thread verifies RPEM_COMMAND; and LCM's encoding of
// the same message beside it, for scale. Counters: bytes per message (the encoding, with its 36-byte
// key id and MAC trailer).
#include <benchmark/benchmark.h>

#include <array>
#include <vector>

#include "rpem/auth/mac.hpp"
#include "rpem/command_t.hpp"
#include "rpem/diagnostics_t.hpp"
#include "rpem/estimate_t.hpp"

namespace {

rpem::auth::Key key() {
  std::array<std::uint8_t, rpem::auth::kKeyBytes> bytes{};
  bytes.fill(0x5A);
  return {1, bytes};
}

template <class Message>
Message message() {
  Message m{};
  m.key_id = 1;
  if constexpr (requires { m.algorithm; }) m.algorithm = "sga";
  if constexpr (requires { m.source; }) {
    m.source = "can";
    m.source_name = "can0";
  }
  return m;
}

template <class Message>
void BM_Sign(benchmark::State& state, const char* channel) {
  Message m = message<Message>();
  std::vector<std::uint8_t> buffer(static_cast<std::size_t>(m.getEncodedSize()));
  const rpem::auth::Key k = key();
  for (auto _ : state) {
    const int n = m.encode(buffer.data(), 0, static_cast<int>(buffer.size()));
    benchmark::DoNotOptimize(rpem::auth::sign(k, channel, std::span(buffer.data(), static_cast<std::size_t>(n))));
    benchmark::ClobberMemory();
  }
  state.counters["bytes"] = static_cast<double>(buffer.size());
}

template <class Message>
void BM_EncodeOnly(benchmark::State& state) {
  Message m = message<Message>();
  std::vector<std::uint8_t> buffer(static_cast<std::size_t>(m.getEncodedSize()));
  for (auto _ : state) {
    benchmark::DoNotOptimize(m.encode(buffer.data(), 0, static_cast<int>(buffer.size())));
    benchmark::ClobberMemory();
  }
  state.counters["bytes"] = static_cast<double>(buffer.size());
}

void BM_VerifyCommand(benchmark::State& state) {
  rpem::command_t m = message<rpem::command_t>();
  std::vector<std::uint8_t> buffer(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(buffer.data(), 0, static_cast<int>(buffer.size()));
  rpem::auth::sign(key(), "RPEM_COMMAND", buffer);
  rpem::auth::Keyring keys;
  keys.add(key());
  for (auto _ : state) benchmark::DoNotOptimize(rpem::auth::verify(keys, "RPEM_COMMAND", buffer));
  state.counters["bytes"] = static_cast<double>(buffer.size());
}

void BM_EncodeSignEstimate(benchmark::State& s) { BM_Sign<rpem::estimate_t>(s, "RPEM_ESTIMATE"); }
void BM_EncodeSignDiagnostics(benchmark::State& s) { BM_Sign<rpem::diagnostics_t>(s, "RPEM_DIAGNOSTICS"); }
void BM_EncodeSignCommand(benchmark::State& s) { BM_Sign<rpem::command_t>(s, "RPEM_COMMAND"); }
void BM_EncodeEstimate(benchmark::State& s) { BM_EncodeOnly<rpem::estimate_t>(s); }
void BM_EncodeDiagnostics(benchmark::State& s) { BM_EncodeOnly<rpem::diagnostics_t>(s); }
BENCHMARK(BM_EncodeEstimate);
BENCHMARK(BM_EncodeSignEstimate);
BENCHMARK(BM_EncodeDiagnostics);
BENCHMARK(BM_EncodeSignDiagnostics);
BENCHMARK(BM_EncodeSignCommand);
BENCHMARK(BM_VerifyCommand);

}  // namespace

BENCHMARK_MAIN();
