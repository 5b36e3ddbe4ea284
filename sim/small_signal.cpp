#include "sim/small_signal.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hsa::sim {
namespace {

// Bisection for an increasing or decreasing f on [lo, hi] that changes sign there.
template <typename F>
double bisect(F f, double lo, double hi) {
  double f_lo = f(lo);
  for (int i = 0; i < 200 && hi - lo > 1e-12 * std::max(1.0, std::abs(hi)); ++i) {
    const double mid = 0.5 * (lo + hi);
    const double f_mid = f(mid);
    if ((f_mid < 0.0) == (f_lo < 0.0)) {
      lo = mid;
      f_lo = f_mid;
    } else {
      hi = mid;
    }
  }
  return 0.5 * (lo + hi);
}

}  // namespace

SmallSignalPlant linearize(const Cylinder& cylinder, double position_m, double load_kg) {
  const LocalParameters local = cylinder.local_parameters(position_m, load_kg);
  const double ps = cylinder.supply().supply_pressure_pa;
  const double area = cylinder.parameters().geometry.piston_area();
  const double alpha = cylinder.parameters().geometry.area_ratio();
  const double weight = local.mass_kg * cylinder.parameters().gravity_m_per_s2;

  // For an opening x, the chamber pressures at which no oil flows, and the net force they leave.
  auto settle = [&](double x) {
    CylinderState s{position_m, 0.0, 0.0, 0.0};
    s.pressure_a_pa = bisect(
        [&](double pa) {
          s.pressure_a_pa = pa;
          return cylinder.port_flows(s, local, x, true).into_a_m3_per_s;
        },
        0.0, ps);
    s.pressure_b_pa = bisect(
        [&](double pb) {
          s.pressure_b_pa = pb;
          return cylinder.port_flows(s, local, x, true).into_b_m3_per_s;
        },
        0.0, ps);
    return s;
  };
  const double x0 = bisect(
      [&](double x) {
        const CylinderState s = settle(x);
        return area * (s.pressure_a_pa - alpha * s.pressure_b_pa) - weight;
      },
      -1.0, 1.0);
  const CylinderState eq = settle(x0);

  auto f = [&](const Eigen::Vector3d& z, double x) {
    const CylinderState s{position_m, z(0), z(1), z(2)};
    const CylinderState d = cylinder.derivative(s, local, x, true, /*dry_friction=*/false);
    return Eigen::Vector3d(d.velocity_m_per_s, d.pressure_a_pa, d.pressure_b_pa);
  };
  const Eigen::Vector3d z0(0.0, eq.pressure_a_pa, eq.pressure_b_pa);
  const Eigen::Vector3d h(1e-6, 10.0, 10.0);  // m/s, Pa, Pa: far above rounding, far below curvature
  Eigen::Matrix3d a;
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d dz = Eigen::Vector3d::Zero();
    dz(k) = h(k);
    a.col(k) = (f(z0 + dz, x0) - f(z0 - dz, x0)) / (2.0 * h(k));
  }
  const double hx = 1e-6;
  const Eigen::Vector3d b = (f(z0, x0 + hx) - f(z0, x0)) / hx;

  SmallSignalPlant plant;
  plant.hold_opening = x0;
  plant.equilibrium = eq;
  // Modal form: V/X(s) = Σ r_k/(s − p_k). The paper kept the dominant pole pair of its identified
  // models and dropped the rest (section 3.4, Fig. 9b); here the rest is the null-leakage mode,
  // seconds slow, whose weight is set by leakage paths the identification could not see. So k01 is
  // the DC gain of the dominant pair's part alone.
  const Eigen::EigenSolver<Eigen::Matrix3d> eigen(a);
  const Eigen::Matrix3cd modes = eigen.eigenvectors();
  const Eigen::Vector3cd input = modes.inverse() * b.cast<std::complex<double>>();
  int complex_index = -1;
  for (int k = 0; k < 3; ++k) {
    plant.poles[static_cast<std::size_t>(k)] = eigen.eigenvalues()(k);
    if (eigen.eigenvalues()(k).imag() > 0.0) complex_index = k;
  }
  if (complex_index < 0) throw std::runtime_error("linearize: the plant has no oscillatory pole pair");
  const std::complex<double> p = eigen.eigenvalues()(complex_index);
  const std::complex<double> residue = modes(0, complex_index) * input(complex_index);
  plant.b0 = std::norm(p);
  plant.b1 = -2.0 * p.real();
  // The pair's residues are conjugate: DC gain −(r/p + r̄/p̄) = −2·Re(r/p).
  plant.k01_mm_per_s = -2.0 * (residue / p).real() * 1e3;
  return plant;
}

}  // namespace hsa::sim
