// libFuzzer target for every log the tools read (docs/drive-log.md): a log given as its header makes it (our drive
// log, our averaged log, VESC Tool's realtime log) or through a user's column map (`--log-map`), read the way
// `rpem estimate` reads it. The input is a file's bytes, or a column map's YAML, a line "%%csv", then the file.
// The reading may fail only with a DriveLogError, or a ConfigError where a map is given; every sample it delivers
// is finite where required, within DriveLogLimits (the absolute ones: the seeds come from machines larger than the
// paper's), later than the one before, in the frames the header promises and, averaged, a window that ends no
// earlier than it starts; a log without samples throws; and the estimator (the built-in paper machine) keeps its
// estimates finite inside D_M.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "estimate_in_bounds.hpp"
#include "rpem/core/averaged_estimator.hpp"
#include "rpem/core/drive_estimator.hpp"
#include "rpem/io/averaged_log.hpp"
#include "rpem/io/errors.hpp"
#include "rpem/io/log_source.hpp"
#include "rpem/io/machine_config.hpp"
#include "rpem/io/rotor_frame_rebuild.hpp"

namespace {

constexpr std::string_view kCsvMark = "%%csv\n";
// The tools read paths: the input is written where libFuzzer runs (run_fuzz.sh: the target's own directory).
constexpr const char* kLogPath = "fuzz-log.csv";
constexpr const char* kMapPath = "fuzz-map.yaml";

void check(bool ok) {
  if (!ok) std::abort();
}

bool within(double v, const rpem::io::Bound& b) { return std::isfinite(v) && std::abs(v) <= b.max_abs; }
/// An optional quantity: not reported (NaN) or within its bound.
bool absent_or_within(double v, const rpem::io::Bound& b) { return std::isnan(v) || within(v, b); }
/// An optional temperature: not reported (NaN) or within the limits' range.
bool absent_or_plausible_C(double t, const rpem::io::DriveLogLimits& limits) {
  return std::isnan(t) || (t >= limits.temperature_min_C && t <= limits.temperature_max_C);
}

void write_file(const char* path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  check(static_cast<bool>(out));
}

/// As `rpem estimate` runs an averaged log (tools/rpem/estimate_command.cpp, run_averaged).
void run_averaged(const rpem::io::LogSource& source, const rpem::io::MachineConfig& config,
                  const rpem::io::DriveLogLimits& limits) {
  using namespace rpem;
  io::AveragedLogRead read;
  std::vector<core::AveragedSample> samples = io::read_averaged_log(source.path, source.map, limits, &read);
  check(!samples.empty());  // a log without samples must have thrown
  std::int64_t last_t_ns = INT64_MIN;
  for (const core::AveragedSample& x : samples) {
    check(x.t_start_ns <= x.t_ns && x.t_ns > last_t_ns);
    last_t_ns = x.t_ns;
    check(absent_or_within(x.u_dc_V, limits.voltage_V));
    for (double t : {x.t_winding_C, x.t_magnet_C, x.t_coolant_C}) check(absent_or_plausible_C(t, limits));
  }
  (void)io::describe(source, read);
  const io::RotorFrameRebuild rebuilt =
      io::complete_rotor_frame(samples, read, config.machine, io::command_hold_s(config.estimator), source.path);
  for (const core::AveragedSample& x : samples) {
    check(within(x.omega_el_rad_s, limits.speed_rad_s));
    for (int k = 0; k < 2; ++k) check(within(x.u_dq_V[k], limits.voltage_V) && within(x.i_dq_A[k], limits.current_A));
  }
  io::check_averaged_supports(config, "builtin", read.layout.u_dc, source.path);
  const core::EstimatorSettings settings = io::estimator_settings(config, rebuilt);
  core::AveragedDriveEstimator estimator(config.machine, settings);
  for (const core::AveragedSample& x : samples) check(fuzz::estimate_in_bounds(estimator.step(x), settings));
}

/// As `rpem estimate` runs a log of instantaneous samples (run_instantaneous).
void run_instantaneous(const rpem::io::LogSource& source, const rpem::io::MachineConfig& config,
                       const rpem::io::DriveLogLimits& limits) {
  using namespace rpem;
  io::DriveLogReader reader(source.path, source.map, limits);
  const io::DriveLogLayout& layout = reader.layout();
  static core::DriveEstimator estimator(config.machine, config.estimator);
  estimator.reset();
  io::DriveLogRow row;
  std::int64_t last_t_ns = INT64_MIN;
  std::size_t rows = 0;
  while (reader.next(row)) {
    ++rows;
    const core::DriveSample& x = row.sample;
    check(x.t_ns > last_t_ns);
    last_t_ns = x.t_ns;
    check(within(x.theta_el_rad, limits.angle_rad) && within(x.omega_el_rad_s, limits.speed_rad_s) &&
          within(x.u_dc_V, limits.voltage_V));
    check(x.voltage_frame == (layout.voltage_abc ? core::Frame::kAbc : core::Frame::kDq));
    check(x.current_frame == (layout.current_abc ? core::Frame::kAbc : core::Frame::kDq));
    for (int k = 0; k < 3; ++k) check(within(x.u_V[k], limits.voltage_V) && within(x.i_A[k], limits.current_A));
    for (double t : {row.t_magnet_C.value_or(std::nan("")), x.t_winding_C, x.t_coolant_C})
      check(absent_or_plausible_C(t, limits));
    check(fuzz::estimate_in_bounds(estimator.step(x), config.estimator));
  }
  check(rows > 0);  // a log without samples must have thrown
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace rpem;
  static const io::MachineConfig config = io::builtin_paper_config();
  static const io::DriveLogLimits limits;
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const std::size_t mark = input.find(kCsvMark);
  const bool mapped = mark != std::string_view::npos;
  if (mapped) write_file(kMapPath, input.substr(0, mark));
  write_file(kLogPath, mapped ? input.substr(mark + kCsvMark.size()) : input);
  try {
    const io::LogSource source = io::log_source(kLogPath, mapped ? kMapPath : "");
    check(!source.format.empty());
    if (source.averaged()) {
      run_averaged(source, config, limits);
    } else {
      run_instantaneous(source, config, limits);
    }
  } catch (const io::DriveLogError&) {
  } catch (const io::ConfigError&) {
    check(mapped);  // only a column map is configuration
  }
  return 0;
}
