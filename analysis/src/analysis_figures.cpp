#include "rpem/analysis/analysis_figures.hpp"

#include <cmath>
#include <complex>
#include <functional>

#include "rpem/analysis/gnuplot.hpp"
#include "rpem/core/machine.hpp"
#include "rpem/core/predictor.hpp"

namespace rpem::analysis {
namespace {

/// The four-quadrant plane: speed n ∈ [−1, 1] pu, torque τ ∈ [−1, 1] pu, MTPA currents.
struct Plane {
  static constexpr int kN = 81;
  [[nodiscard]] static double coordinate(int k) { return -1.0 + 2.0 * k / (kN - 1); }
};

/// A heat map block: x = n, y = τ, z = f(n, τ).
DataBlock map_block(const std::string& name, const std::function<double(double, double)>& f) {
  DataBlock b;
  b.name = name;
  b.columns.resize(3);
  for (int i = 0; i < Plane::kN; ++i) {
    for (int j = 0; j < Plane::kN; ++j) {
      const double n = Plane::coordinate(i), tau = Plane::coordinate(j);
      b.columns[0].push_back(n);
      b.columns[1].push_back(tau);
      b.columns[2].push_back(f(n, tau));
    }
  }
  return b;
}

void heat_panel(GnuplotFigure& fig, const std::string& block, const std::string& title, const std::string& cb,
                bool log = false) {
  fig.add_line("set title " + gp_quote(title) + " noenhanced");
  fig.add_line("set cblabel " + gp_quote(cb));
  fig.add_line(log ? "set logscale cb; set format cb '10^{%L}'" : "unset logscale cb; set format cb '%g'");
  fig.add_line("plot $" + block + " u 1:2:3 w image notitle");
}

void plane_setup(GnuplotFigure& fig, int rows, int cols, const std::string& title) {
  fig.add_line("set multiplot layout " + std::to_string(rows) + "," + std::to_string(cols) + " title " + gp_quote(title) +
               " noenhanced");
  fig.add_line("set xlabel 'n [pu]'; set ylabel 'τ [pu]'; set xrange [-1:1]; set yrange [-1:1]");
  fig.add_line("set palette defined (0 '#313695', 1 '#74add1', 2 '#ffffbf', 3 '#f46d43', 4 '#a50026'); set size ratio 1");
}

/// Fig_EigenTraj: the predictor's eigenvalues, continuous and one-step, over 0 ≤ n ≤ 2 pu.
std::string write_eigen_trajectories(const std::string& dir, const core::MachinePu& m, double wn, double sample_period_s) {
  GnuplotFigure fig(dir + "/Fig_EigenTraj.png", 1200, 480);
  DataBlock cont{"cont", std::vector<std::vector<double>>(4)};
  DataBlock disc{"disc", std::vector<std::vector<double>>(3)};
  for (double n = 0.0; n <= 2.0 + 1e-12; n += 0.01) {
    const auto [l1, l2] = core::continuous_eigenvalues(m, wn, n);
    cont.columns[0].push_back(n);
    cont.columns[1].push_back(l1.real());
    cont.columns[2].push_back(l1.imag());
    cont.columns[3].push_back(l2.imag());
    auto radius = [&](core::Discretization d) {
      const core::Mat2 phi = core::transition_matrix(m, wn, d, sample_period_s, n);
      const double tr = phi.trace(), det = core::det2(phi);
      const std::complex<double> root = std::sqrt(std::complex<double>(tr * tr / 4.0 - det, 0.0));
      return std::max(std::abs(tr / 2.0 + root), std::abs(tr / 2.0 - root));
    };
    disc.columns[0].push_back(n);
    disc.columns[1].push_back(radius(core::Discretization::kTrapezoidal));
    disc.columns[2].push_back(radius(core::Discretization::kExplicitEuler));
  }
  fig.add_data(std::move(cont));
  fig.add_data(std::move(disc));
  fig.add_line("set multiplot layout 1,2 title 'Fig_EigenTraj: predictor eigenvalues, 0 ≤ n ≤ 2 pu' noenhanced");
  fig.add_line(
      "set grid; set title '(a) continuous: λ_{1,2} (colour: n [pu])'; set xlabel 'Re λ [1/s]'; set ylabel 'Im λ [rad/s]'");
  fig.add_line("set palette defined (0 '#313695', 1 '#f46d43'); set cblabel 'n [pu]'");
  fig.add_line("plot $cont u 2:3:1 w l lw 3 lc palette notitle, '' u 2:4:1 w l lw 3 lc palette notitle");
  fig.add_line("set title " + gp_quote("(b) discrete, T_{samp} = " + std::to_string(sample_period_s * 1e6).substr(0, 5) +
                                       " µs: spectral radius of the one-step map"));
  fig.add_line("set xlabel 'n [pu]'; set ylabel 'max |z|'; set key top left; unset colorbox");
  fig.add_line(
      "plot $disc u 1:2 w l lw 2 t 'trapezoidal', '' u 1:3 w l lw 2 t 'explicit Euler', 1 w l dt 2 lc 'black' t '|z| = 1'");
  fig.add_line("unset multiplot");
  fig.render();
  return dir + "/Fig_EigenTraj.png";
}

/// Fig_sensitivity: exact steady-state ε for a −10 % estimate error.
std::string write_sensitivity(const std::string& dir, const core::MachinePu& m) {
  GnuplotFigure fig(dir + "/Fig_sensitivity.png", 1100, 1000);
  auto eps = [&](int param, int component) {
    return [&, param, component](double n, double tau) {
      const core::Vec2 i = core::mtpa_reference(m, tau);
      core::MachinePu model = m;
      (param == 0 ? model.psi_m_pu : model.r_s_pu) *= 0.9;
      const core::Vec2 u = core::steady_state_voltage(m, n, i);
      return core::steady_state_prediction_error(m, model, n, u)[component];
    };
  };
  fig.add_data(map_block("epsi_d", eps(0, 0)));
  fig.add_data(map_block("epsi_q", eps(0, 1)));
  fig.add_data(map_block("ers_d", eps(1, 0)));
  fig.add_data(map_block("ers_q", eps(1, 1)));
  plane_setup(fig, 2, 2, "Fig_sensitivity: steady-state prediction error [pu] for estimates 10 % low");
  heat_panel(fig, "epsi_d", "(a) ε_d, ψ̂m −10 %", "ε_d [pu]");
  heat_panel(fig, "epsi_q", "(a) ε_q, ψ̂m −10 %", "ε_q [pu]");
  heat_panel(fig, "ers_d", "(b) ε_d, r̂s −10 %", "ε_d [pu]");
  heat_panel(fig, "ers_q", "(b) ε_q, r̂s −10 %", "ε_q [pu]");
  fig.add_line("unset multiplot");
  fig.render();
  return dir + "/Fig_sensitivity.png";
}

/// fig_PEG_analytical: the steady-state prediction gradients.
std::string write_prediction_gradients(const std::string& dir, const core::MachinePu& m) {
  GnuplotFigure fig(dir + "/fig_PEG_analytical.png", 1100, 1000);
  auto grad = [&](int row, int col) {
    return [&, row, col](double n, double tau) {
      return core::steady_state_gradients(m, n, core::mtpa_reference(m, tau))(row, col);
    };
  };
  fig.add_data(map_block("gpd", grad(0, core::kPsiM)));
  fig.add_data(map_block("gpq", grad(1, core::kPsiM)));
  fig.add_data(map_block("grd", grad(0, core::kRs)));
  fig.add_data(map_block("grq", grad(1, core::kRs)));
  plane_setup(fig, 2, 2, "fig_PEG_analytical: steady-state prediction gradients (denominator r̂s² + n²x_dx_q, erratum E2)");
  heat_panel(fig, "gpd", "(a) dî_d/dψ̂m", "[pu/pu]");
  heat_panel(fig, "gpq", "(a) dî_q/dψ̂m", "[pu/pu]");
  heat_panel(fig, "grd", "(b) dî_d/dr̂s", "[pu/pu]");
  heat_panel(fig, "grq", "(b) dî_q/dr̂s", "[pu/pu]");
  fig.add_line("unset multiplot");
  fig.render();
  return dir + "/fig_PEG_analytical.png";
}

/// fig_hesscompstatic: scalar Hessian and matrix-Hessian determinant in steady state.
std::string write_hessians(const std::string& dir, const core::MachinePu& m) {
  GnuplotFigure fig(dir + "/fig_hesscompstatic.png", 1100, 520);
  auto hess = [&](bool det) {
    return [&, det](double n, double tau) {
      const core::Mat2 g = core::steady_state_gradients(m, n, core::mtpa_reference(m, tau));
      const core::Mat2 r = g.transpose() * g;
      return std::max(det ? core::det2(r) : r.trace(), 1e-8);
    };
  };
  fig.add_data(map_block("r", hess(false)));
  fig.add_data(map_block("detR", hess(true)));
  plane_setup(fig, 1, 2, "fig_hesscompstatic: scalar Hessian r and matrix-Hessian determinant |R| (steady state)");
  heat_panel(fig, "r", "r = tr{ΨΨ^T}", "r [pu]", true);
  heat_panel(fig, "detR", "|R| = (n·î_d/D)^2", "|R| [pu]", true);
  fig.add_line("unset multiplot");
  fig.render();
  return dir + "/fig_hesscompstatic.png";
}

}  // namespace

std::vector<std::string> write_analysis_figures(const std::string& dir, const core::MachineSi& machine,
                                                double sample_period_s) {
  const core::PerUnitBase base = core::PerUnitBase::from_rated(machine.rated);
  const core::MachinePu m = core::to_pu(base, machine);
  return {write_eigen_trajectories(dir, m, base.omega_el_rad_s, sample_period_s), write_sensitivity(dir, m),
          write_prediction_gradients(dir, m), write_hessians(dir, m)};
}

}  // namespace rpem::analysis
