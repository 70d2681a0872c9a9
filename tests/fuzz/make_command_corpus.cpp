// Writes the seed corpus for the RPEM_COMMAND fuzzer (daemon/fuzz/fuzz_command.cpp) in its input
// format: every command kind, valid and at D_M's edges, old and new sequence numbers, commands on and
// off, a narrow D_M, junk and a truncated message; authentication off, and required with messages
// signed by the harness under each held key, an unknown key, for another channel, or left unsigned. Run once; the files are committed under
// daemon/fuzz/corpus.
#include <cmath>
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "rpem/command_t.hpp"

namespace {

std::vector<std::uint8_t> encode(std::int64_t seq, std::int8_t command, double psi_m_Wb, double r_s_Ohm) {
  rpem::command_t m{};
  m.utime = 1'700'000'000'000'000 + seq;
  m.seq = seq;
  m.command = command;
  m.psi_m_Wb = psi_m_Wb;
  m.r_s_Ohm = r_s_Ohm;
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

void write(const std::string& path, std::uint8_t flags, std::int64_t last,
           const std::vector<std::vector<std::uint8_t>>& messages, std::uint8_t auth = 0) {
  std::ofstream out(path, std::ios::binary);
  out.put(static_cast<char>(flags));
  out.put(static_cast<char>(auth));
  for (int k = 0; k < 8; ++k) out.put(static_cast<char>((static_cast<std::uint64_t>(last) >> (8 * k)) & 0xFF));
  for (const auto& m : messages) {
    out.put(static_cast<char>(m.size()));
    out.write(reinterpret_cast<const char*>(m.data()), static_cast<std::streamsize>(m.size()));
  }
}

}  // namespace

int main(int argc, char** argv) {
  using rpem::command_t;
  const std::string dir = argc > 1 ? argv[1] : ".";
  const auto reset = encode(1, command_t::RESET, 0, 0), freeze = encode(2, command_t::FREEZE, 0, 0),
             unfreeze = encode(3, command_t::UNFREEZE, 0, 0), set = encode(4, command_t::SET_VALUES, 1.1, 2.4),
             edge = encode(5, command_t::SET_VALUES, 0.5, 4.5), outside = encode(6, command_t::SET_VALUES, 1.8, 2.4),
             nan = encode(7, command_t::SET_VALUES, std::nan(""), 2.4), unknown = encode(8, 9, 0, 0),
             old = encode(2, command_t::RESET, 0, 0);
  std::vector<std::uint8_t> truncated(set.begin(), set.end() - 3);
  const std::string text = "this is not an rpem command_t";
  const std::vector<std::uint8_t> junk(text.begin(), text.end());
  write(dir + "/every_kind", 0xFD, 0, {reset, freeze, unfreeze, set, edge, outside, nan, unknown, old});
  write(dir + "/disabled", 0x00, 0, {reset, set});
  write(dir + "/old_sequence", 0x55, 4, {reset, freeze, set, edge});
  write(dir + "/narrow_bounds", 0x07, 0, {set, encode(9, command_t::SET_VALUES, 1.1, 2.2)});
  write(dir + "/malformed", 0xFF, 0, {junk, truncated, set});
  write(dir + "/busy", 0x01, 0, {reset, freeze, unfreeze, set, edge, encode(10, command_t::RESET, 0, 0)});
  // auth byte: bit 0 required; bits 1-2 signed with key 1, key 2, key 9 (unknown); bit 3 for another channel.
  write(dir + "/auth_key1", 0xFD, 0, {reset, freeze, unfreeze, set, edge, outside, old}, 0x03);
  write(dir + "/auth_key2", 0x55, 1, {reset, freeze, set, edge}, 0x05);
  write(dir + "/auth_unknown_key", 0x01, 0, {reset, set}, 0x07);
  write(dir + "/auth_other_channel", 0x01, 0, {reset, set}, 0x0B);
  write(dir + "/auth_unsigned", 0xFF, 0, {reset, junk, truncated, set}, 0x01);
  return 0;
}
