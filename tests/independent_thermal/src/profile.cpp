#include "indep_thermal/profile.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>

#include "indep_thermal/errors.hpp"
#include "indep_thermal/random.hpp"

namespace indep_thermal {

Demand Profile::at(double t_s, bool left_limit) const {
  Demand d;
  d.i_d_given = gives_i_d;
  if (points.empty()) return d;
  // `after`: the first point later than t (from the left: the first at or after t), so that the segment
  // [after − 1, after] holds t (at a step: the segment after it, or before it for the left limit).
  const auto later = [](double t, const ProfilePoint& p) { return t < p.t_s; };
  const auto earlier = [](const ProfilePoint& p, double t) { return p.t_s < t; };
  const auto after = left_limit ? std::lower_bound(points.begin(), points.end(), t_s, earlier)
                                : std::upper_bound(points.begin(), points.end(), t_s, later);
  const ProfilePoint* a = after == points.begin() ? &points.front() : &*(after - 1);
  const ProfilePoint* b = after == points.end() ? a : &*after;
  double w = 0.0;
  if (b->t_s > a->t_s && t_s > a->t_s) w = (t_s - a->t_s) / (b->t_s - a->t_s);
  if (after == points.begin()) w = 0.0;
  d.speed_rpm = a->speed_rpm + w * (b->speed_rpm - a->speed_rpm);
  d.i_q_A = a->i_q_A + w * (b->i_q_A - a->i_q_A);
  d.i_d_A = a->i_d_A + w * (b->i_d_A - a->i_d_A);
  return d;
}

std::vector<double> Profile::knots() const {
  std::vector<double> k;
  for (const ProfilePoint& p : points) {
    if (k.empty() || p.t_s > k.back()) k.push_back(p.t_s);
  }
  return k;
}

namespace {

[[noreturn]] void data_error(const std::string& path, std::size_t line, std::size_t column, const std::string& why) {
  throw DataError(path + ":" + std::to_string(line) + (column > 0 ? ":" + std::to_string(column) : "") + ": " + why);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  for (char c : line) {
    if (c == ',') {
      cells.push_back(cell);
      cell.clear();
    } else if (c != '\r') {
      cell.push_back(c);
    }
  }
  cells.push_back(cell);
  for (std::string& s : cells) {
    const auto first = s.find_first_not_of(" \t");
    const auto last = s.find_last_not_of(" \t");
    s = first == std::string::npos ? std::string() : s.substr(first, last - first + 1);
  }
  return cells;
}

}  // namespace

Profile read_profile_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw DataError(path + ": cannot be read");
  Profile profile;
  profile.name = path;
  std::string line;
  std::size_t line_no = 0;
  std::vector<std::string> header;
  int col_t = -1, col_speed = -1, col_iq = -1, col_id = -1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[line.find_first_not_of(" \t")] == '#') continue;
    std::vector<std::string> cells = split(line);
    if (header.empty()) {
      header = cells;
      for (std::size_t c = 0; c < header.size(); ++c) {
        int* slot = header[c] == "t_s"         ? &col_t
                    : header[c] == "speed_rpm" ? &col_speed
                    : header[c] == "i_q_A"     ? &col_iq
                    : header[c] == "i_d_A"     ? &col_id
                                               : nullptr;
        if (slot == nullptr) {
          data_error(path, line_no, c + 1, "unknown column '" + header[c] + "' (t_s, speed_rpm, i_q_A, i_d_A)");
        }
        if (*slot >= 0) data_error(path, line_no, c + 1, "duplicate column '" + header[c] + "'");
        *slot = static_cast<int>(c);
      }
      if (col_t < 0 || col_speed < 0 || col_iq < 0) {
        data_error(path, line_no, 0, "the header needs t_s, speed_rpm and i_q_A");
      }
      profile.gives_i_d = col_id >= 0;
      continue;
    }
    if (cells.size() != header.size()) {
      data_error(path, line_no, 0, std::to_string(cells.size()) + " cells, the header has " + std::to_string(header.size()));
    }
    auto number = [&](int col, double limit) {
      const std::string& s = cells[static_cast<std::size_t>(col)];
      double v = 0.0;
      const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
      if (ec != std::errc() || ptr != s.data() + s.size() || s.empty()) {
        data_error(path, line_no, static_cast<std::size_t>(col) + 1,
                   "column " + header[static_cast<std::size_t>(col)] + ": '" + s + "' is not a number");
      }
      if (!std::isfinite(v) || std::abs(v) > limit) {
        data_error(path, line_no, static_cast<std::size_t>(col) + 1,
                   "column " + header[static_cast<std::size_t>(col)] + ": " + s + " is beyond ±" + std::to_string(limit));
      }
      return v;
    };
    ProfilePoint p;
    p.t_s = number(col_t, 1e9);
    p.speed_rpm = number(col_speed, 1e6);
    p.i_q_A = number(col_iq, 1e5);
    if (col_id >= 0) p.i_d_A = number(col_id, 1e5);
    if (p.t_s < 0.0) data_error(path, line_no, static_cast<std::size_t>(col_t) + 1, "column t_s: negative time");
    const std::size_t n = profile.points.size();
    if (n > 0 && p.t_s < profile.points[n - 1].t_s) {
      data_error(path, line_no, static_cast<std::size_t>(col_t) + 1, "column t_s: time goes back");
    }
    if (n > 1 && p.t_s == profile.points[n - 1].t_s && p.t_s == profile.points[n - 2].t_s) {
      data_error(path, line_no, static_cast<std::size_t>(col_t) + 1, "column t_s: a third point at one time");
    }
    profile.points.push_back(p);
  }
  if (header.empty()) throw DataError(path + ":1: empty profile (no header)");
  if (profile.points.empty()) data_error(path, line_no, 0, "no points: the header is followed by no rows");
  return profile;
}

Profile heat_cool_profile(const Machine& m, double duration_s) {
  const double n = 0.917 * m.speed_rpm;
  const double i = m.peak_current_A();
  const double t_start = std::min(60.0, 0.01 * duration_s);
  const double t_ramp = t_start + std::min(12.0, 0.01 * duration_s);
  const double t_step = 0.586 * duration_s;
  Profile p;
  p.name = "heat-cool";
  p.gives_i_d = true;
  p.points = {{0.0, 0.0, 0.0, 0.0},
              {t_start, 0.0, 0.0, 0.0},
              {t_ramp, n, 0.29 * i, -0.885 * i},
              {t_step, n, 0.29 * i, -0.885 * i},
              {t_step, n, 0.0, -0.47 * i},
              {duration_s, n, 0.0, -0.47 * i}};
  return p;
}

namespace {

struct Segment {
  double speed_rel;  // of N_n
  double i_q_rel;    // of Î_n
  double duration_s;
};

enum class Kind { cruise, high_speed, hard, regen, standstill_hold, idle, light };

Segment draw_segment(Kind kind, Rng& rng) {
  switch (kind) {
    case Kind::cruise:
      return {rng.uniform(0.3, 0.9), rng.uniform(0.3, 0.8), rng.uniform(120, 600)};
    case Kind::high_speed:
      return {rng.uniform(0.8, 1.3), rng.uniform(0.1, 0.4), rng.uniform(120, 600)};
    case Kind::hard:
      return {rng.uniform(0.3, 0.8), rng.uniform(0.8, 1.3), rng.uniform(30, 180)};
    case Kind::regen:
      return {rng.uniform(0.3, 1.0), -rng.uniform(0.2, 0.6), rng.uniform(20, 120)};
    case Kind::standstill_hold: {
      const double sign = rng.uniform() < 0.5 ? -1.0 : 1.0;
      return {0.0, sign * rng.uniform(0.4, 1.0), rng.uniform(60, 300)};
    }
    case Kind::idle:
      return {0.0, 0.0, rng.uniform(120, 600)};
    case Kind::light:
      return {rng.uniform(0.1, 0.4), rng.uniform(0.0, 0.15), rng.uniform(120, 600)};
  }
  return {0.0, 0.0, 60.0};
}

Kind pick(Rng& rng, const std::vector<std::pair<Kind, double>>& weights) {
  double total = 0.0;
  for (const auto& w : weights) total += w.second;
  double u = rng.uniform() * total;
  for (const auto& w : weights) {
    if (u < w.second) return w.first;
    u -= w.second;
  }
  return weights.back().first;
}

}  // namespace

Profile drive_cycle_profile(const Machine& m, double duration_s, std::uint64_t seed, double load_scale) {
  Rng rng(seed, Stream::profile);
  Profile p;
  p.name = "drive-cycle";
  p.gives_i_d = false;
  const double n_n = m.speed_rpm;
  const double i_n = load_scale * m.peak_current_A();
  double t = 0.0;
  double speed = 0.0;
  double i_q = 0.0;
  p.points.push_back({0.0, 0.0, 0.0, 0.0});
  // One segment: ramp from the present state to the segment's over `ramp`, then hold; clipped at the end.
  auto add = [&](const Segment& s, double ramp) {
    if (t >= duration_s) return;
    const bool cut = t + ramp > duration_s;  // the ramp cut short by the end
    const double t_ramped = cut ? duration_s : t + ramp;
    const double w = cut ? (t_ramped - t) / ramp : 1.0;
    speed = cut ? speed + w * (s.speed_rel * n_n - speed) : s.speed_rel * n_n;
    i_q = cut ? i_q + w * (s.i_q_rel * i_n - i_q) : s.i_q_rel * i_n;
    p.points.push_back({t_ramped, speed, i_q, 0.0});
    t = std::min(t_ramped + s.duration_s, duration_s);
    p.points.push_back({t, speed, i_q, 0.0});
  };
  // The machine is at the coolant's temperature at first: an idle, then a short standstill with current
  // (where R_s can be commissioned at a known temperature), then blocks of load and rest.
  add({0.0, 0.0, std::min(30.0, duration_s)}, 1.0);
  add({0.0, 0.4, 30.0}, 2.0);
  add({0.0, 0.0, 20.0}, 2.0);
  const std::vector<std::pair<Kind, double>> load = {
      {Kind::cruise, 0.35}, {Kind::high_speed, 0.2}, {Kind::hard, 0.15}, {Kind::regen, 0.1}, {Kind::standstill_hold, 0.2}};
  const std::vector<std::pair<Kind, double>> rest = {{Kind::idle, 0.5}, {Kind::standstill_hold, 0.2}, {Kind::light, 0.3}};
  while (t < duration_s) {
    const double load_end = t + rng.uniform(900.0, 2400.0);
    while (t < std::min(load_end, duration_s)) add(draw_segment(pick(rng, load), rng), rng.uniform(5.0, 20.0));
    // Each rest block stops the machine: an idle, then a standstill with current (a hold on a slope),
    // then what the draw gives.
    const double rest_end = t + rng.uniform(300.0, 900.0);
    add(draw_segment(Kind::idle, rng), rng.uniform(5.0, 20.0));
    add(draw_segment(Kind::standstill_hold, rng), rng.uniform(2.0, 5.0));
    while (t < std::min(rest_end, duration_s)) add(draw_segment(pick(rng, rest), rng), rng.uniform(5.0, 20.0));
  }
  return p;
}

}  // namespace indep_thermal
