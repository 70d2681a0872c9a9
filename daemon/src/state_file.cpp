#include "rpem/daemon/state_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "rpem/core/errno_text.hpp"

namespace rpem::daemon {
namespace fs = std::filesystem;

namespace {

/// A temporary file in the same directory, fsync, rename, fsync of the directory: a crash leaves the
/// old or the new file, never a torn one. Returns an empty string or the reason it failed.
std::string write_atomically(const std::string& path, const std::string& text) {
  const fs::path target(path);
  std::error_code ec;
  if (target.has_parent_path()) fs::create_directories(target.parent_path(), ec);
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd < 0) return "open " + tmp + ": " + core::errno_text(errno);
  const char* p = text.data();
  std::size_t left = text.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      const std::string why = core::errno_text(errno);
      ::close(fd);
      return std::string("write ").append(tmp).append(": ").append(why);
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) return "fsync " + tmp + ": " + core::errno_text(errno);
  if (::rename(tmp.c_str(), path.c_str()) != 0) return "rename to " + path + ": " + core::errno_text(errno);
  const std::string dir = target.has_parent_path() ? target.parent_path().string() : ".";
  if (const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC); dfd >= 0) {
    (void)::fsync(dfd);
    ::close(dfd);
  }
  return "";
}

nlohmann::json thermal_to_json(const core::ThermalSnapshot& s) {
  const int n = s.nodes;
  nlohmann::json t = nlohmann::json::array(), p = nlohmann::json::array();
  for (int i = 0; i < n; ++i) {
    t.push_back(s.t_C[i]);
    nlohmann::json row = nlohmann::json::array();
    for (int j = 0; j < n; ++j) row.push_back(s.p_K2(i, j));
    p.push_back(row);
  }
  const core::ThermalLoad& l = s.load;
  return {{"nodes", n},
          {"winding", s.winding},
          {"magnet", s.magnet},
          {"t_C", t},
          {"p_K2", p},
          {"load",
           {{"current_sq_A2", l.current_sq_A2},
            {"basis", l.basis},
            {"convection_basis", l.convection_basis},
            {"coolant_C", l.coolant_C}}}};
}

/// Throws (the file is corrupt) where a value is missing or of another shape than thermal_to_json writes.
core::ThermalSnapshot thermal_from_json(const nlohmann::json& j) {
  core::ThermalSnapshot s;
  s.nodes = j.at("nodes").get<int>();
  if (s.nodes < 2 || s.nodes > core::kMaxThermalNodes)
    throw std::runtime_error("thermal.nodes " + std::to_string(s.nodes) + " outside 2.." +
                             std::to_string(core::kMaxThermalNodes));
  s.winding = j.at("winding").get<int>();
  s.magnet = j.at("magnet").get<int>();
  const nlohmann::json& t = j.at("t_C");
  const nlohmann::json& p = j.at("p_K2");
  const auto n = static_cast<std::size_t>(s.nodes);
  if (t.size() != n || p.size() != n) throw std::runtime_error("thermal.t_C and thermal.p_K2 need one entry a node");
  for (int i = 0; i < s.nodes; ++i) {
    s.t_C[i] = t.at(static_cast<std::size_t>(i)).get<double>();
    const nlohmann::json& row = p.at(static_cast<std::size_t>(i));
    if (row.size() != n) throw std::runtime_error("thermal.p_K2 is not square");
    for (int k = 0; k < s.nodes; ++k) s.p_K2(i, k) = row.at(static_cast<std::size_t>(k)).get<double>();
  }
  const nlohmann::json& l = j.at("load");
  s.load.current_sq_A2 = l.at("current_sq_A2").get<double>();
  s.load.basis = l.at("basis").get<std::array<double, core::kLossForms>>();
  s.load.convection_basis = l.at("convection_basis").get<double>();
  s.load.coolant_C = l.at("coolant_C").get<double>();
  return s;
}

/// Empty, or why a well-formed thermal state cannot be a machine's: nodes out of range, a temperature below
/// absolute zero, a covariance that is not one (asymmetric, a negative variance or eigenvalue), a load that is not
/// one.
std::string thermal_implausibility(const core::ThermalSnapshot& s) {
  constexpr double kAbsoluteZero_C = -273.15;
  const int n = s.nodes;
  if (s.winding < 0 || s.winding >= n || s.magnet < 0 || s.magnet >= n || s.winding == s.magnet)
    return "its winding and magnet are not two of its nodes";
  const auto t = s.t_C.head(n);
  const auto p = s.p_K2.topLeftCorner(n, n);
  if (!t.allFinite() || (t.array() <= kAbsoluteZero_C).any()) return "a temperature is not finite or below absolute zero";
  if (!p.allFinite() || (p.diagonal().array() < 0.0).any()) return "a variance is not finite or negative";
  if (!p.isApprox(p.transpose(), 1e-9)) return "its covariance is not symmetric";
  // A covariance has no negative eigenvalue (rounding aside: the filter's own are ≥ −1e-9 of its largest variance).
  const Eigen::VectorXd eig = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(p, Eigen::EigenvaluesOnly).eigenvalues();
  if (eig.minCoeff() < -1e-9 * p.diagonal().maxCoeff()) return "its covariance has a negative eigenvalue";
  const core::ThermalLoad& l = s.load;
  const bool basis_ok = std::all_of(l.basis.begin(), l.basis.end(), [](double b) { return std::isfinite(b) && b >= 0.0; });
  if (!(l.current_sq_A2 >= 0.0) || !std::isfinite(l.current_sq_A2) || !basis_ok || !(l.convection_basis >= 0.0) ||
      !std::isfinite(l.convection_basis) || !std::isfinite(l.coolant_C) || l.coolant_C <= kAbsoluteZero_C)
    return "its load is not finite and non-negative";
  return "";
}

}  // namespace

std::string write_state_file(const std::string& path, const PersistedEstimates& e) {
  nlohmann::json j;
  j["format"] = "rpemd-estimates-1";
  j["written_unix_s"] = e.written_unix_s;
  j["psi_m_Wb"] = e.psi_m_Wb ? nlohmann::json(*e.psi_m_Wb) : nlohmann::json(nullptr);
  j["r_s_Ohm"] = e.r_s_Ohm ? nlohmann::json(*e.r_s_Ohm) : nlohmann::json(nullptr);
  if (e.psi_m_Wb) j["psi_m_adapted_unix_s"] = e.psi_m_adapted_unix_s;
  if (e.r_s_Ohm) j["r_s_adapted_unix_s"] = e.r_s_adapted_unix_s;
  if (e.thermal.state.nodes > 0) {
    j["thermal"] = thermal_to_json(e.thermal.state);
    j["thermal"]["at_unix_s"] = e.thermal.at_unix_s;
  }
  return write_atomically(path, j.dump(2) + "\n");
}

std::string command_sequence_file(const std::string& state_file) {
  const fs::path p(state_file);
  return (p.has_parent_path() ? p.parent_path() / "commands.json" : fs::path("commands.json")).string();
}

std::string write_command_sequence(const std::string& path, std::int64_t last_accepted_seq) {
  return write_atomically(
      path, "{\"format\": \"rpemd-commands-1\", \"last_accepted_seq\": " + std::to_string(last_accepted_seq) + "}\n");
}

std::int64_t load_command_sequence(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    if (!fs::exists(path)) return 0;
    throw std::runtime_error(path + ": cannot read the last accepted command sequence number");
  }
  std::stringstream text;
  text << in.rdbuf();
  try {
    const nlohmann::json j = nlohmann::json::parse(text.str());
    if (!j.is_object() || j.value("format", "") != "rpemd-commands-1")
      throw std::runtime_error("not an rpemd commands file");
    return j.at("last_accepted_seq").get<std::int64_t>();
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": corrupt (" + e.what() +
                             "); it holds the last accepted command's sequence number, "
                             "which replay protection needs: restore it, or remove it to start again from 0");
  }
}

LoadedState load_state_file(const std::string& path, double max_age_s, double psi_min, double psi_max, double rs_min,
                            double rs_max) {
  LoadedState s;
  std::ifstream in(path);
  if (!in) {
    s.message = "no state file at " + path;
    return s;
  }
  std::stringstream text;
  text << in.rdbuf();
  try {
    const nlohmann::json j = nlohmann::json::parse(text.str());
    if (!j.is_object() || j.value("format", "") != "rpemd-estimates-1") throw std::runtime_error("not an rpemd state file");
    s.estimates.written_unix_s = j.at("written_unix_s").get<std::int64_t>();
    if (!j.at("psi_m_Wb").is_null()) s.estimates.psi_m_Wb = j.at("psi_m_Wb").get<double>();
    if (!j.at("r_s_Ohm").is_null()) s.estimates.r_s_Ohm = j.at("r_s_Ohm").get<double>();
    s.estimates.psi_m_adapted_unix_s = j.value("psi_m_adapted_unix_s", s.estimates.written_unix_s);
    s.estimates.r_s_adapted_unix_s = j.value("r_s_adapted_unix_s", s.estimates.written_unix_s);
    if (j.contains("thermal")) {
      s.estimates.thermal.state = thermal_from_json(j.at("thermal"));
      s.estimates.thermal.at_unix_s = j.at("thermal").at("at_unix_s").get<std::int64_t>();
    }
  } catch (const std::exception& e) {
    s.status = StateFileStatus::kCorrupt;
    s.message = path + ": corrupt state file ignored (" + e.what() + ")";
    return s;
  }
  const std::int64_t now_s = std::time(nullptr);
  const double age = static_cast<double>(now_s - s.estimates.written_unix_s);
  const std::string limit = " s old (limit " + std::to_string(static_cast<long>(max_age_s)) + " s)";
  if (age < -60.0 || age > max_age_s) {
    s.status = StateFileStatus::kTooOld;
    s.message = path + ": state file is " + std::to_string(static_cast<long>(age)) + limit + ", ignored";
    return s;
  }
  std::string note;  // what is left out of a file that is loaded
  if (PersistedThermal& t = s.estimates.thermal; t.state.nodes > 0) {
    const double thermal_age = static_cast<double>(now_s - t.at_unix_s);
    if (thermal_age < -60.0 || thermal_age > max_age_s) {
      note = "; its thermal state is " + std::to_string(static_cast<long>(thermal_age)) + limit + ", left out";
      t = PersistedThermal{};
      if (!s.estimates.psi_m_Wb && !s.estimates.r_s_Ohm) {
        s.status = StateFileStatus::kTooOld;
        s.message = path + ": state file holds nothing else" + note;
        return s;
      }
    }
  }
  const bool has_thermal = s.estimates.thermal.state.nodes > 0;
  auto plausible = [](const std::optional<double>& v, double lo, double hi) {
    return !v || (std::isfinite(*v) && *v >= lo && *v <= hi);
  };
  if (!plausible(s.estimates.psi_m_Wb, psi_min, psi_max) || !plausible(s.estimates.r_s_Ohm, rs_min, rs_max) ||
      (!s.estimates.psi_m_Wb && !s.estimates.r_s_Ohm && !has_thermal)) {
    s.status = StateFileStatus::kImplausible;
    s.message = path + ": state file values outside the configured bounds, ignored";
    return s;
  }
  if (const std::string why = has_thermal ? thermal_implausibility(s.estimates.thermal.state) : ""; !why.empty()) {
    s.status = StateFileStatus::kImplausible;
    s.message = path + ": state file's thermal state is not a machine's (" + why + "), ignored";
    return s;
  }
  s.status = StateFileStatus::kLoaded;
  const char* what = s.estimates.psi_m_Wb || s.estimates.r_s_Ohm ? "estimates " : "a thermal state ";
  s.message = path + ": resuming from " + what + std::to_string(static_cast<long>(age)) + " s old" + note;
  return s;
}

}  // namespace rpem::daemon
