#include "indep_vesc/scenario.hpp"

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

#include "indep_vesc/random_streams.hpp"

namespace indep::vesc {

const char* to_string(SegmentKind k) {
  switch (k) {
    case SegmentKind::off:
      return "off";
    case SegmentKind::current:
      return "current";
    case SegmentKind::coast:
      return "coast";
    case SegmentKind::brake:
      return "brake";
    case SegmentKind::flux_measurement:
      return "flux_measurement";
  }
  return "?";
}

std::vector<Segment> builtin_scenario(double duration_s, double l_current_max_A, double rated_erpm, double creep_torque_Nm,
                                      double torque_per_A_Nm, std::uint64_t seed) {
  std::mt19937_64 rng = stream_rng(seed, Stream::scenario);
  auto u = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
  const double i_max = l_current_max_A;
  std::vector<Segment> s;
  double total = 0.0;
  auto add = [&](Segment seg) {
    s.push_back(seg);
    total += seg.duration_s;
  };
  add({SegmentKind::off, u(2.0, 4.0)});
  if (duration_s >= 60.0) {
    // VESC Tool's detection: the sequence lasts ~11 s at 1800 ERPM/s; 30 s is only its upper bound.
    add({SegmentKind::flux_measurement, 30.0, u(0.25, 0.4) * i_max, 0.0, 0.0, 1800.0});
    total -= 30.0 - 12.0;
    add({SegmentKind::off, u(15.0, 25.0)});
  }
  for (int episode = 0; total < duration_s; ++episode) {
    const double sign = episode % 3 == 2 ? -1.0 : 1.0;
    if (episode % 3 != 0) {  // after a stop: a hand turns the rotor a little, unseen
      Segment creep{SegmentKind::off, u(0.8, 1.5)};
      creep.external_Nm = (u(0.0, 1.0) < 0.5 ? -1.0 : 1.0) * creep_torque_Nm;
      add(creep);
      add({SegmentKind::off, 0.5});
    }
    // From standstill or a slow roll: the sensorless open-loop start-up, then closed loop (an app's ramp or a
    // step).
    Segment start{SegmentKind::current, u(1.0, 2.0), sign * u(0.2, 0.35) * i_max, u(0.0, 0.3), u(0.15, 0.25) * rated_erpm};
    start.friction_Nm = u(0.3, 0.7) * torque_per_A_Nm * std::fabs(start.current_A);  // a load to start against
    add(start);
    // A hard acceleration: a current step, over within a read or two.
    add({SegmentKind::current, u(0.15, 0.4), sign * u(0.6, 0.9) * i_max, 0.0, u(0.35, 0.45) * rated_erpm});
    add({SegmentKind::current, u(15.0, 40.0), sign * u(0.03, 0.07) * i_max});
    switch (episode % 3) {
      case 0:
        add({SegmentKind::off, u(10.0, 25.0)});
        break;  // freewheel at speed
      case 1:
        add({SegmentKind::coast, u(45.0, 100.0)});
        break;  // a minute or more at zero current
      default:
        add({SegmentKind::brake, 4.0, u(0.15, 0.3) * i_max, 0.0, 0.03 * rated_erpm});
        add({SegmentKind::off, u(3.0, 8.0)});
        break;
    }
  }
  return s;
}

std::vector<Segment> builtin_hall_scenario(double duration_s, double l_current_max_A, double torque_per_A_Nm, int pole_pairs,
                                           std::uint64_t seed) {
  std::mt19937_64 rng = stream_rng(seed, Stream::scenario);
  auto u = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
  const double i_max = l_current_max_A;
  // The viscous load b that holds the shaft at `erpm` with the current i on the configured machine: b·ω_m = k_t·i.
  auto viscous_for = [&](double erpm, double i_A) {
    const double omega_m = erpm * 2.0 * 3.14159265358979323846 / 60.0 / pole_pairs;
    return torque_per_A_Nm * std::fabs(i_A) / omega_m;
  };
  std::vector<Segment> s;
  double total = 0.0;
  auto add = [&](Segment seg) {
    s.push_back(seg);
    total += seg.duration_s;
  };
  add({SegmentKind::off, u(1.0, 2.0)});  // standstill, the bridge off
  for (int episode = 0; total < duration_s; ++episode) {
    const double sign = episode % 3 == 2 ? -1.0 : 1.0;
    // Holding at standstill: a current against a brake (friction ten times its torque: the rotor yields by a few
    // degrees a second).
    Segment hold{SegmentKind::current, u(1.5, 2.5), sign * u(0.1, 0.2) * i_max, 0.1};
    hold.friction_Nm = 10.0 * torque_per_A_Nm * std::fabs(hold.current_A);
    add(hold);
    // Crawling, well below foc_hall_interp_erpm (500): 25–60 ERPM (a sector takes 0.17–0.4 s), then 150–280.
    Segment crawl{SegmentKind::current, u(4.0, 6.0), sign * u(0.08, 0.15) * i_max, 0.2};
    crawl.viscous_Nm_s = viscous_for(u(25.0, 60.0), crawl.current_A);
    add(crawl);
    Segment faster{SegmentKind::current, u(1.5, 2.5), sign * u(0.08, 0.15) * i_max, 0.2};
    faster.viscous_Nm_s = viscous_for(u(150.0, 280.0), faster.current_A);
    add(faster);
    // Interpolated: 900–1600 ERPM, between foc_hall_interp_erpm and foc_sl_erpm_start (2500).
    Segment interp{SegmentKind::current, u(3.0, 4.0), sign * u(0.08, 0.15) * i_max, 0.2};
    interp.viscous_Nm_s = viscous_for(u(900.0, 1600.0), interp.current_A);
    add(interp);
    // Above foc_sl_erpm (3500): 6000–10 000 ERPM, through the blend on the way.
    Segment fast{SegmentKind::current, u(3.0, 4.0), sign * u(0.1, 0.2) * i_max, 0.2};
    fast.viscous_Nm_s = viscous_for(u(6000.0, 10000.0), fast.current_A);
    add(fast);
    // Zero current: the bridge modulating at 0 A while bearings and drag run the shaft down through the blend, the
    // interpolated range and crawling; then the bridge off.
    add({SegmentKind::coast, u(3.0, 5.0)});
    add({SegmentKind::off, u(1.0, 2.0)});
  }
  return s;
}

namespace {

[[noreturn]] void fail(const std::string& path, int line, const std::string& why) {
  throw ScenarioError(path + ":" + std::to_string(line) + ": " + why);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) {
    const auto a = cell.find_first_not_of(" \t\r");
    const auto b = cell.find_last_not_of(" \t\r");
    cells.push_back(a == std::string::npos ? std::string() : cell.substr(a, b - a + 1));
  }
  return cells;
}

}  // namespace

std::vector<Segment> read_scenario_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ScenarioError(path + ": cannot be read");
  std::string line;
  int n = 0;
  std::vector<std::string> header;
  std::vector<Segment> segments;
  const std::vector<std::string> known = {"kind",       "duration_s",  "current_A",   "ramp_s",      "until_erpm",
                                          "erpm_per_s", "external_Nm", "friction_Nm", "viscous_Nm_s"};
  while (std::getline(in, line)) {
    ++n;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::vector<std::string> cells = split(line);
    if (header.empty()) {
      header = cells;
      if (header.size() < 3 || header[0] != "kind" || header[1] != "duration_s" || header[2] != "current_A") {
        fail(path, n, "header must start with kind,duration_s,current_A");
      }
      for (std::size_t c = 0; c < header.size(); ++c) {
        if (c >= known.size() || header[c] != known[c]) {
          fail(path, n,
               "column " + std::to_string(c + 1) + " '" + header[c] + "': expected '" +
                   (c < known.size() ? known[c] : std::string("nothing")) + "'");
        }
      }
      continue;
    }
    if (cells.size() != header.size()) {
      fail(path, n, std::to_string(cells.size()) + " cells, the header has " + std::to_string(header.size()));
    }
    Segment seg;
    const std::string& kind = cells[0];
    if (kind == "off")
      seg.kind = SegmentKind::off;
    else if (kind == "current")
      seg.kind = SegmentKind::current;
    else if (kind == "coast")
      seg.kind = SegmentKind::coast;
    else if (kind == "brake")
      seg.kind = SegmentKind::brake;
    else if (kind == "flux_measurement")
      seg.kind = SegmentKind::flux_measurement;
    else
      fail(path, n, "kind '" + kind + "' (known: off, current, coast, brake, flux_measurement)");
    double* fields[] = {&seg.duration_s, &seg.current_A,   &seg.ramp_s,      &seg.until_erpm,
                        &seg.erpm_per_s, &seg.external_Nm, &seg.friction_Nm, &seg.viscous_Nm_s};
    for (std::size_t c = 1; c < cells.size(); ++c) {
      double v = 0.0;
      try {
        std::size_t used = 0;
        v = std::stod(cells[c], &used);
        if (used != cells[c].size()) throw std::invalid_argument(cells[c]);
      } catch (const std::exception&) {
        fail(path, n, "column " + header[c] + ": '" + cells[c] + "' is not a number");
      }
      if (!std::isfinite(v)) fail(path, n, "column " + header[c] + ": not finite");
      *fields[c - 1] = v;
    }
    if (seg.duration_s <= 0.0) fail(path, n, "duration_s must be positive");
    if (seg.ramp_s < 0.0 || seg.until_erpm < 0.0 || seg.erpm_per_s <= 0.0 || seg.friction_Nm < 0.0 ||
        seg.viscous_Nm_s < 0.0) {
      fail(path, n, "ramp_s, until_erpm, friction_Nm and viscous_Nm_s must be >= 0, erpm_per_s > 0");
    }
    segments.push_back(seg);
  }
  if (segments.empty()) fail(path, n, "no segments");
  return segments;
}

}  // namespace indep::vesc
