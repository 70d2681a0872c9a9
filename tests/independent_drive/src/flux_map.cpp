#include "indep_drive/flux_map.hpp"
#include "indep_drive/ipow.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace indep {

namespace {

int column(const std::vector<std::string>& header, std::initializer_list<const char*> names, const std::string& path) {
  for (const char* n : names) {
    const auto it = std::find(header.begin(), header.end(), n);
    if (it != header.end()) return static_cast<int>(it - header.begin());
  }
  throw std::runtime_error(path + ":1: no column " + *names.begin());
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) {
    while (!cell.empty() && (cell.back() == '\r' || cell.back() == ' ')) cell.pop_back();
    cells.push_back(cell);
  }
  return cells;
}

}  // namespace

FluxMapData read_flux_map(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot be read");
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(path + ":1: empty");
  const std::vector<std::string> header = split(line);
  const int cd = column(header, {"i_d_A", "i_d_grid_k"}, path);
  const int cq = column(header, {"i_q_A", "i_q_grid_k"}, path);
  const int pd = column(header, {"psi_d_Vs", "Psi_d_map"}, path);
  const int pq = column(header, {"psi_q_Vs", "Psi_q_map"}, path);
  FluxMapData map{path, {}};
  int line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line == "\r") continue;
    const std::vector<std::string> cells = split(line);
    if (cells.size() != header.size()) {
      throw std::runtime_error(path + ":" + std::to_string(line_no) + ": " + std::to_string(cells.size()) +
                               " cells, header has " + std::to_string(header.size()));
    }
    FluxMapPoint p;
    double* dest[4] = {&p.i_d_A, &p.i_q_A, &p.psi_d_Wb, &p.psi_q_Wb};
    const int cols[4] = {cd, cq, pd, pq};
    bool finite = true;
    for (int k = 0; k < 4; ++k) {
      const std::string& s = cells[static_cast<std::size_t>(cols[k])];
      try {
        std::size_t used = 0;
        *dest[k] = std::stod(s, &used);
        if (used != s.size()) throw std::invalid_argument(s);
      } catch (const std::exception&) {
        throw std::runtime_error(path + ":" + std::to_string(line_no) + ": column " +
                                 header[static_cast<std::size_t>(cols[k])] + ": '" + s + "' is not a number");
      }
      finite = finite && std::isfinite(*dest[k]);
    }
    if (finite) map.points.push_back(p);
  }
  if (map.points.size() < 10) throw std::runtime_error(path + ": fewer than 10 finite points");
  return map;
}

double FluxMapFit::l_d0_H() const {
  for (const PolyTerm& t : terms)
    if (t.m == 2 && t.n == 0) return 2.0 * t.b_Wb / current_scale_A;
  return 0.0;
}

double FluxMapFit::l_q0_H() const {
  for (const PolyTerm& t : terms)
    if (t.m == 0 && t.n == 2) return 2.0 * t.b_Wb / current_scale_A;
  return 0.0;
}

FluxMapFit fit_flux_map(const FluxMapData& raw, int degree) {
  FluxMapFit fit;
  // The magnet axis: the flux at the smallest current of the map; a map whose ψ_q is not zero there
  // (a rotor-position offset of the test bench) is turned by δ so that it is.
  const FluxMapPoint* origin = &raw.points.front();
  for (const FluxMapPoint& p : raw.points) {
    if (std::hypot(p.i_d_A, p.i_q_A) < std::hypot(origin->i_d_A, origin->i_q_A)) origin = &p;
  }
  fit.axis_rotation_rad = std::atan2(origin->psi_q_Wb, origin->psi_d_Wb);
  FluxMapData map{raw.path, {}};
  for (const FluxMapPoint& p : raw.points) {
    const Vec2 i = rotate({p.i_d_A, p.i_q_A}, -fit.axis_rotation_rad);
    const Vec2 psi = rotate({p.psi_d_Wb, p.psi_q_Wb}, -fit.axis_rotation_rad);
    map.points.push_back({i.x, i.y, psi.x, psi.y});
  }
  for (const FluxMapPoint& p : map.points) fit.current_scale_A = std::max(fit.current_scale_A, std::abs(p.i_q_A));
  if (!(fit.current_scale_A > 0.0)) throw std::runtime_error(map.path + ": the map has no q-axis current");
  for (int total = 2; total <= degree; ++total) {
    for (int n = 0; n <= total; n += 2) fit.terms.push_back({total - n, n, 0.0});
  }
  const auto rows = static_cast<Eigen::Index>(2 * map.points.size());
  const auto cols = static_cast<Eigen::Index>(fit.terms.size() + 1);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(rows, cols);
  Eigen::VectorXd y(rows);
  for (std::size_t k = 0; k < map.points.size(); ++k) {
    const FluxMapPoint& p = map.points[k];
    const double xd = p.i_d_A / fit.current_scale_A, xq = p.i_q_A / fit.current_scale_A;
    fit.max_abs_x_d = std::max(fit.max_abs_x_d, std::abs(xd));
    fit.max_abs_x_q = std::max(fit.max_abs_x_q, std::abs(xq));
    const auto rd = static_cast<Eigen::Index>(2 * k), rq = rd + 1;
    a(rd, 0) = 1.0;  // ψ0
    for (std::size_t j = 0; j < fit.terms.size(); ++j) {
      const PolyTerm& t = fit.terms[j];
      const auto c = static_cast<Eigen::Index>(j + 1);
      if (t.m > 0) a(rd, c) = t.m * ipow(xd, t.m - 1) * ipow(xq, t.n);
      if (t.n > 0) a(rq, c) = t.n * ipow(xd, t.m) * ipow(xq, t.n - 1);
    }
    y(rd) = p.psi_d_Wb;
    y(rq) = p.psi_q_Wb;
  }
  const Eigen::VectorXd coef = a.colPivHouseholderQr().solve(y);
  fit.psi0_Wb = coef(0);
  for (std::size_t j = 0; j < fit.terms.size(); ++j) fit.terms[j].b_Wb = coef(static_cast<Eigen::Index>(j + 1));
  const Eigen::VectorXd r = a * coef - y;
  fit.rms_residual_Wb = std::sqrt(r.squaredNorm() / static_cast<double>(rows));
  fit.max_residual_Wb = r.cwiseAbs().maxCoeff();
  return fit;
}

FluxModel scale_flux_map(const FluxMapFit& fit, const MachineParams& machine, double full_scale_current_A,
                         SaturationParts parts) {
  const double a20 = 0.5 * fit.l_d0_H() * fit.current_scale_A;
  const double a02 = 0.5 * fit.l_q0_H() * fit.current_scale_A;
  if (!(a20 > 0.0) || !(a02 > 0.0)) throw std::runtime_error("flux map: non-positive small-signal inductance");
  const double k_d = machine.l_d_H * full_scale_current_A / (2.0 * a20);
  const double k_q = machine.l_q_H * full_scale_current_A / (2.0 * a02);
  const double k_x = std::sqrt(k_d * k_q);
  std::vector<PolyTerm> terms;
  for (const PolyTerm& t : fit.terms) {
    if (t.m + t.n <= 2) continue;  // the quadratic part is the machine's own L_d, L_q
    if (t.n == 0 && parts.ld) terms.push_back({t.m, t.n, parts.depth * k_d * t.b_Wb});
    if (t.m == 0 && parts.lq) terms.push_back({t.m, t.n, parts.depth * k_q * t.b_Wb});
    if (t.m > 0 && t.n > 0 && parts.cross) terms.push_back({t.m, t.n, parts.depth * k_x * t.b_Wb});
  }
  return FluxModel(machine.l_d_H, machine.l_q_H, full_scale_current_A, std::move(terms));
}

}  // namespace indep
