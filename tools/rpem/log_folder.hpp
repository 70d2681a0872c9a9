#pragma once
// A folder of logs as VESC Tool leaves them (one CSV per logging session, named by the session's start:
// 2026-11-26_10-15-02.csv): `rpem estimate --log FOLDER --out DIR` runs the estimator over each log on its own
// and writes DIR/<log's stem>.estimate.csv per log and DIR/summary.csv, one row per log (docs/drive-log.md,
// "A folder of logs").

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

namespace rpem::tools {

/// The logs in `folder`: its regular files (not hidden) whose names end in ".csv" in any case, in name order —
/// VESC Tool names a log by its session's start, so name order is time order. Subfolders are not entered.
/// io::InputError naming the folder where it cannot be read or holds no such file.
[[nodiscard]] std::vector<std::filesystem::path> logs_in_folder(const std::string& folder);

/// The session's start as VESC Tool names its log (vedderb/vesc_tool vescinterface.cpp, openRtLogFile: the local
/// date and time at opening, yyyy-MM-dd_hh-mm-ss.csv; hh:mm:ss in older versions), as ISO 8601 local time
/// ("2026-11-30T09:05:10"); "" where the name is not of that form.
[[nodiscard]] std::string session_start(const std::filesystem::path& log);

/// Where the estimate of `log` goes: `out_dir`/<its stem>.estimate.csv. Distinct logs get distinct names, and none
/// is summary.csv.
[[nodiscard]] std::string estimate_path(const std::string& out_dir, const std::filesystem::path& log);

/// A temperature's peak over a session, and the peak of T + 2σ (what a derating on T + 2σ acts on) [°C]; unset
/// where it was never estimated.
struct TemperaturePeak {
  std::optional<double> t_C, t_2sd_C;
  void add(double t, double sd_K) {
    if (!std::isfinite(t) || !std::isfinite(sd_K)) return;
    t_C = t_C ? std::max(*t_C, t) : t;
    t_2sd_C = t_2sd_C ? std::max(*t_2sd_C, t + 2.0 * sd_K) : t + 2.0 * sd_K;
  }
};

/// What one log's run ended with: its figures, or why it was skipped.
struct LogOutcome {
  std::string log;      ///< the file's name in the folder
  std::string error;    ///< empty: estimated; else the error that skipped it (file:line: why)
  std::string kind;     ///< "averaged" or "instantaneous"
  std::string started;  ///< session_start of its name
  std::uint64_t samples = 0, resyncs = 0, outliers = 0, excluded = 0;
  std::array<std::uint64_t, 2> adapted{};  ///< samples in which ψm, R_s adapted
  std::optional<double> t_first_s, t_last_s, psi_m_Wb, r_s_Ohm;
  /// Whether the log determines ψm, R_s (the averaged path's check; unset where none was made).
  std::array<std::optional<bool>, 2> identifiable;
  TemperaturePeak magnet, winding;  ///< the fused temperatures' peaks (--thermal)
};

/// DIR/summary.csv: its header at construction, a row per log as each ends (flushed, so a run stopped part-way
/// leaves the logs it finished).
class FolderSummary {
 public:
  explicit FolderSummary(const std::string& path);
  void add(const LogOutcome& outcome);

 private:
  std::string path_;
  std::ofstream out_;
};

}  // namespace rpem::tools
