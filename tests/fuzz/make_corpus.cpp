// Writes the seed corpus for the decoder fuzzer: valid FD and classic streams (with and without
// defects, each with a temperature frame) in the fuzzer's input format. Run once; the files are
// committed under can/fuzz/corpus.
#include <algorithm>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "rpem/can/encoder.hpp"

using namespace rpem;

void write(const std::string& path, const std::vector<can::CanFrame>& frames) {
  std::ofstream out(path, std::ios::binary);
  for (const auto& f : frames) {
    const char head[4] = {static_cast<char>(f.id & 0xFF), static_cast<char>(f.id >> 8),
                          static_cast<char>((f.fd ? 1 : 0) | 4), static_cast<char>(f.len)};
    out.write(head, 4);
    out.write(reinterpret_cast<const char*>(f.data.data()), f.len);
  }
}

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : ".";
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int mode = 0; mode < 2; ++mode) {
    can::TelemetryEncoder enc(mode == 0 ? can::BusMode::kFd : can::BusMode::kClassic, 3);
    std::vector<can::CanFrame> frames;
    std::array<can::CanFrame, can::TelemetryEncoder::kMaxFramesPerAdd> buf;
    for (int k = 0; k < 12; ++k) {
      core::DriveSample s;
      s.t_ns = 1'000'000 + k * 125'000LL;
      s.theta_el_rad = 3.0 * u(rng);
      s.omega_el_rad_s = 300.0 * u(rng);
      s.u_dc_V = 220.0;
      s.u_V = {100 * u(rng), 100 * u(rng), 100 * u(rng)};
      s.i_A = {5 * u(rng), 5 * u(rng), 5 * u(rng)};
      if (k == 7) s.i_A[1] = 50.0;     // a saturated value
      s.t_winding_C = 60.0 + 0.1 * k;  // the first sample sends a temperature frame (ID 0x118)
      s.t_coolant_C = 40.0;
      const std::size_t n = enc.add(s, 1, buf);
      frames.insert(frames.end(), buf.begin(), buf.begin() + static_cast<long>(n));
    }
    write(dir + (mode == 0 ? "/fd_stream" : "/classic_stream"), frames);
    std::vector<can::CanFrame> shuffled = frames;
    std::shuffle(shuffled.begin(), shuffled.end(), rng);
    write(dir + (mode == 0 ? "/fd_shuffled" : "/classic_shuffled"), shuffled);
  }
  return 0;
}
