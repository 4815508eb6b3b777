// Volumetric anti-locking (Mast 2013 ch. 4; src/stabilize, docs/antilocking.md).
//  1. Cantilever in the incompressible limit (seed §6.2.1, nu = 0.49): plain MPM locks (period and
//     amplitude off Euler-Bernoulli by more than 3 %), node-based volumetric anti-locking keeps
//     both within 3 %; in one scene, a beam that overrides its material's setting moves as a
//     beam of that setting (anti-locking per body).
//  2. Water at rest in a tank: the RMS deviation of the particle pressure from rho g depth is
//     below 5 % of the base pressure with node-based averaging, and clearly worse without.
//  3. The full-tensor approaches (AS2, AS3CV, hybrid) and Anura3D's strain smoothing on the same
//     two cases.
//     The stress approximation (Table 4.1 steps 6-7) with each approach; the viscoplastic fluids
//     in the tank.
//  4. The seed's dam break with barrier (§6.1.2) after the impact: pressure within 5 % of
//     hydrostatic with averaging, plain MPM more than 10x worse.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "support/obstacle_checks.h"
#include "support/run_scene.h"

namespace surge {
namespace {

// First cantilever mode shape (spec seed-validation-cases.md §3.4), as in cantilever_test.cpp.
Real ModeShape(Real x, Real L) {
  const Real b = 1.875104 / L, s = 0.734096;
  return std::cosh(b * x) - std::cos(b * x) - s * (std::sinh(b * x) - std::sin(b * x));
}

// Beam discretisation (coarser than cantilever_test.cpp: K/G = 50 makes dt 3.3x smaller).
const char* kCellSize = "0.25";

struct BeamResult {
  Real period_ratio = 0;     // MPM period / Euler-Bernoulli period
  Real amplitude_ratio = 0;  // MPM tip amplitude / (tip speed / omega_EB)
};

// scenes/cantilever_2d.yaml at nu = 0.49 (E of the scene's aluminium kept), started in the first
// mode with no gravity, run for 1.3 Euler-Bernoulli periods.
// `antilocking` is the content of the material's antilocking map, e.g. "method: node, strain:
// increment".
// `extra`: further overrides. One result per body (each body's own tip).
std::vector<BeamResult> CantileverBodies(const std::string& antilocking,
                                         const std::vector<std::string>& extra = {}) {
  const Real E = 9 * 70.28e9 * 26.23e9 / (3 * 70.28e9 + 26.23e9), nu = 0.49;
  const Real K = E / (3 * (1 - 2 * nu)), G = E / (2 * (1 + nu));
  std::vector<std::string> overrides = {
      "gravity=[0, 0]", "grid.shape_function=linear", "grid.cell_size=" + std::string(kCellSize),
      "bodies.0.particles_per_cell=2", "materials.aluminium.bulk_modulus=" + std::to_string(K),
      "materials.aluminium.shear_modulus=" + std::to_string(G),
      "materials.aluminium.antilocking={" + antilocking + "}"};
  for (const std::string& o : extra) overrides.push_back(o);
  LoadedScene scene = LoadScene(testing::ScenePath("cantilever_2d.yaml"), overrides);
  const Real rho = scene.model.materials[0].density, L = 10.0, d = 1.0;
  const Real E_plane = E / (1 - nu * nu), I = d * d * d / 12, A = d;
  const Real omega = 1.875104 * 1.875104 * std::sqrt(E_plane * I / (rho * A * std::pow(L, 4)));
  const Real period_eb = 2 * M_PI / omega, v_tip = omega * d / 200;
  const size_t bodies = scene.model.bodies.size();
  Particles& P = scene.state.particles;
  std::map<int64_t, Real> y0;  // tip particles by id: initial height
  std::vector<Real> v0(bodies), m0(bodies);
  for (size_t p = 0; p < P.size(); ++p) {
    P.v[p] = Vec3(0, v_tip * ModeShape(P.x[p].x(), L) / ModeShape(L, L), 0);
    if (P.x[p].x() > L - 0.5) {
      y0[P.id[p]] = P.x[p].y();
      v0[size_t(P.body[p])] += P.mass[p] * P.v[p].y();
      m0[size_t(P.body[p])] += P.mass[p];
    }
  }
  std::vector<Real> t, amplitude(bodies);
  std::vector<std::vector<Real>> tip(bodies);
  testing::RunUntil(scene, 1.3 * period_eb, [&](const State& s, const StepReport&) {
    std::vector<Real> v(bodies), u(bodies), m(bodies);
    for (size_t p = 0; p < s.particles.size(); ++p) {
      const auto it = y0.find(s.particles.id[p]);
      if (it == y0.end()) continue;
      const size_t b = size_t(s.particles.body[p]);
      v[b] += s.particles.mass[p] * s.particles.v[p].y();
      u[b] += s.particles.mass[p] * (s.particles.x[p].y() - it->second);
      m[b] += s.particles.mass[p];
    }
    t.push_back(s.time);
    for (size_t b = 0; b < bodies; ++b) {
      tip[b].push_back(v[b] / m[b]);
      amplitude[b] = std::max(amplitude[b], std::abs(u[b] / m[b]));
    }
  });
  std::vector<BeamResult> out(bodies);
  for (size_t b = 0; b < bodies; ++b) {
    const auto crossings = testing::ZeroCrossings(t, tip[b]);
    EXPECT_GE(crossings.size(), 2u);
    // Euler-Bernoulli tip amplitude: the initial mean tip speed / omega.
    out[b].period_ratio = testing::PeriodFromCrossings(crossings) / period_eb;
    out[b].amplitude_ratio = amplitude[b] / (v0[b] / m0[b] / omega);
    std::printf("cantilever nu = 0.49, antilocking {%s}, body '%s': period / EB %.4f, amplitude / "
                "EB %.4f\n",
                antilocking.c_str(), scene.model.bodies[b].name.c_str(), out[b].period_ratio,
                out[b].amplitude_ratio);
  }
  return out;
}

BeamResult Cantilever(const std::string& antilocking) { return CantileverBodies(antilocking)[0]; }

TEST(AntilockingTest, NodeBasedUnlocksTheIncompressibleCantilever) {
  const BeamResult plain = Cantilever("method: none");
  const BeamResult node = Cantilever("method: node, strain: increment");
  // The problem is present without anti-locking: the beam is too stiff.
  EXPECT_GT(std::abs(plain.period_ratio - 1), 0.03);
  EXPECT_GT(std::abs(plain.amplitude_ratio - 1), 0.03);
  // The fix works (seed §6.2.1 gate of issue #4: 3 %).
  EXPECT_NEAR(node.period_ratio, 1.0, 0.03);
  EXPECT_NEAR(node.amplitude_ratio, 1.0, 0.03);

  // Anti-locking per body (docs/antilocking.md, "Per body"): the scene's beam and a second beam of
  // the same material 3 cells above it (clamped to the same wall, no contact), the material
  // node-based and the upper beam overriding it with none. Each beam moves as the single beam
  // with that setting (the shared run's time steps differ slightly, hence not bitwise).
  const std::string beam =
      "{name: beam, material: aluminium, region: {box: {min: [0, 0], max: [10, 1]}}, "
      "particles_per_cell: 2}";
  const std::string upper =
      "{name: upper, material: aluminium, region: {box: {min: [0, 1.75], max: [10, 2.75]}}, "
      "particles_per_cell: 2, antilocking: {method: none}}";
  const std::vector<BeamResult> shared =
      CantileverBodies("method: node, strain: increment", {"bodies=[" + beam + ", " + upper + "]"});
  ASSERT_EQ(shared.size(), 2u);
  EXPECT_NEAR(shared[0].period_ratio, node.period_ratio, 1e-3);
  EXPECT_NEAR(shared[0].amplitude_ratio, node.amplitude_ratio, 1e-3);
  EXPECT_NEAR(shared[1].period_ratio, plain.period_ratio, 1e-3);
  EXPECT_NEAR(shared[1].amplitude_ratio, plain.amplitude_ratio, 1e-3);
}

// Particle pressures -tr(sigma)/3 summed by id over the sampled steps, and each particle's last
// height, for the RMS of the time-averaged pressure about rho g (h - y).
struct PressureSamples {
  std::map<int64_t, std::pair<Real, int>> pressure;  // by id: sum of samples, count
  std::map<int64_t, Real> height;                    // by id: last y [m]
  void Add(const Particles& P) {
    for (size_t p = 0; p < P.size(); ++p) {
      auto& [sum, n] = pressure[P.id[p]];
      sum += -P.stress[p].trace() / 3;
      ++n;
      height[P.id[p]] = P.x[p].y();
    }
  }
  // RMS over particles of p - rho g (h - y), relative to rho g h.
  Real RmsAboutHydrostatic(Real rho, Real g, Real h) const {
    Real sq = 0;
    for (const auto& [id, acc] : pressure) {
      const Real dev = acc.first / acc.second - rho * g * (h - height.at(id));
      sq += dev * dev;
    }
    return std::sqrt(sq / Real(pressure.size())) / (rho * g * h);
  }
  // Mean and RMS of (p - rho g (h - y)) / (rho g h) in height bands [edges[k], edges[k+1]).
  void PrintBands(Real rho, Real g, Real h, const std::vector<Real>& edges) const {
    for (size_t k = 0; k + 1 < edges.size(); ++k) {
      Real sum = 0, sq = 0;
      int n = 0;
      for (const auto& [id, acc] : pressure) {
        const Real y = height.at(id);
        if (y < edges[k] || y >= edges[k + 1]) continue;
        const Real dev = (acc.first / acc.second - rho * g * (h - y)) / (rho * g * h);
        sum += dev;
        sq += dev * dev;
        ++n;
      }
      if (n > 0)
        std::printf("  band %.2f-%.2f m: %d particles, mean %+.4f, RMS %.4f\n", edges[k],
                    edges[k + 1], n, sum / n, std::sqrt(sq / n));
    }
  }
};

// Water at rest in a tank: scenes/dam_break_2d.yaml with the column filling a 0.114 m wide box to
// h = 0.057 m (0.0095 m cells, 2 particles per cell per direction), gravity ramped over 0.2 s
// (seed App. B.2.3) and the state observed after settling. Returns the RMS over particles (their
// pressure time-averaged over the last 0.25 s) of p - rho g depth, relative to the base pressure
// rho g h; h = m / (rho0 W) is the incompressible surface height.
// `ghosts`: domain.ghost_nodes, empty for the default (mirror).
// `material`: a YAML map replacing the scene's water (density 997.5 kept by the caller), or empty.
Real TankPressureRms(const std::string& method, const std::string& ghosts = "",
                     const std::string& material = "") {
  constexpr Real kW = 0.114, kRho = 997.5, kG = 9.81, kEnd = 1.0, kAvgFrom = 0.75;
  std::vector<std::string> overrides = {
      "domain.max=[0.114, 0.228]", "grid.cell_size=0.0095", "bodies.0.particles_per_cell=2",
      "bodies.0.region.box.max=[0.114, 0.057]", "gravity_ramp=0.2"};
  if (!material.empty()) overrides.push_back("materials.water=" + material);
  overrides.push_back("materials.water.antilocking={method: " + method + "}");  // [, stress: true]
  if (!ghosts.empty()) overrides.push_back("domain.ghost_nodes=" + ghosts);
  LoadedScene scene = LoadScene(testing::ScenePath("dam_break_2d.yaml"), overrides);
  Real mass = 0;
  for (Real m : scene.state.particles.mass) mass += m;
  const Real h = mass / (kRho * kW);
  PressureSamples samples;
  std::vector<Real> floor;  // floor reaction per step [N/m]
  testing::RunUntil(scene, kEnd, [&](const State& s, const StepReport& r) {
    if (s.time < kAvgFrom) return;
    floor.push_back(-r.walls.force[int(Face::kYMin)].y());
    samples.Add(s.particles);
  });
  const Real rms = samples.RmsAboutHydrostatic(kRho, kG, h);
  // Wall-force noise: RMS fluctuation of the floor reaction about the weight m g, per weight.
  Real noise = 0;
  for (Real f : floor) noise += (f - mass * kG) * (f - mass * kG);
  noise = std::sqrt(noise / Real(floor.size())) / (mass * kG);
  std::printf("tank at rest, antilocking %-5s, ghost nodes %s: RMS(p - rho g depth) / rho g h = "
              "%.4f (%zu particles); floor force RMS(R - m g) / m g = %.2e\n",
              method.c_str(), ghosts.empty() ? "default" : ghosts.c_str(), rms, samples.pressure.size(), noise);
  EXPECT_LT(noise, 0.02) << "the floor must carry the weight";
  return rms;
}

// The specific Kirchhoff stress tau/rho0 = J V0 sigma / m of every particle after one step of the
// sand column collapse (flow under way at 0.02 s), grouped by the grid cell of the particle at x_n
// (the positions the projection used), with the particle's position xi in the cell.
struct CellStress {
  struct Sample {
    Real xi, eta;  // position in the cell [cells]
    Mat3 q;        // tau / rho0 [m^2/s^2]
  };
  std::map<std::pair<int, int>, std::vector<Sample>> cells;
  Real scale = 0;  // largest |q_ij| over all particles

  // Largest in-cell spread (max - min) of component(q), relative to the scale.
  template <class C>
  Real Spread(const C& component) const {
    Real spread = 0;
    for (const auto& [cell, v] : cells) {
      Real lo = component(v[0].q), hi = lo;
      for (const Sample& s : v) lo = std::min(lo, component(s.q)), hi = std::max(hi, component(s.q));
      spread = std::max(spread, hi - lo);
    }
    return spread / scale;
  }
  // Largest residual, relative to the scale, of the least-squares plane a + b xi + c eta through
  // component(q) in each cell with at least 4 particles spread over the cell (0 when the values
  // are linear in the cell, as the linear fit (4.25)-(4.27) makes them).
  template <class C>
  Real PlaneResidual(const C& component) const {
    Real worst = 0;
    for (const auto& [cell, v] : cells) {
      if (v.size() < 4) continue;
      Eigen::MatrixXd A(v.size(), 3);
      Eigen::VectorXd y(v.size());
      for (size_t k = 0; k < v.size(); ++k) {
        A.row(Eigen::Index(k)) << 1, v[k].xi, v[k].eta;
        y(Eigen::Index(k)) = component(v[k].q);
      }
      if (A.jacobiSvd().singularValues()(2) < 1e-3) continue;  // particles on a line
      const Eigen::Vector3d c = A.colPivHouseholderQr().solve(y);
      worst = std::max(worst, (A * c - y).cwiseAbs().maxCoeff());
    }
    return worst / scale;
  }
};

CellStress ColumnCollapseCellStress(const std::string& antilocking) {
  LoadedScene scene = LoadScene(testing::ScenePath("column_collapse_2d.yaml"),
                                {"materials.sand.antilocking=" + antilocking});
  const Real dx = scene.model.dx;
  testing::RunUntil(scene, 0.02, [](const State&, const StepReport&) {});  // flow under way
  const std::vector<Vec3> x_n = scene.state.particles.x;
  const std::vector<int64_t> id_n = scene.state.particles.id;
  testing::RunUntil(scene, scene.state.time + 1e-9, [](const State&, const StepReport&) {});
  const Particles& P = scene.state.particles;
  std::map<int64_t, Vec3> x_of;  // by id: the position at x_n
  for (size_t p = 0; p < x_n.size(); ++p) x_of[id_n[p]] = x_n[p];
  CellStress out;
  for (size_t p = 0; p < P.size(); ++p) {
    const Mat3 q = P.F[p].determinant() * P.volume0[p] * P.stress[p].matrix() / P.mass[p];
    const Vec3 u = x_of.at(P.id[p]) / dx;
    const std::pair<int, int> cell{int(std::floor(u.x())), int(std::floor(u.y()))};
    out.cells[cell].push_back({u.x() - cell.first, u.y() - cell.second, q});
    out.scale = std::max(out.scale, q.cwiseAbs().maxCoeff());
  }
  return out;
}

// Largest in-cell spread of the specific mean stress tr(tau)/(3 rho0), relative to the largest
// component. With cell-based stress averaging (seed (4.25)_2, (4.28)) every particle of a cell
// carries the cell's value; without it the return mapping leaves them different.
Real CellSpreadOfMeanStress(const std::string& antilocking) {
  const Real spread = ColumnCollapseCellStress(antilocking).Spread([](const Mat3& q) {
    return q.trace() / 3;
  });
  std::printf("column collapse, antilocking %s: largest in-cell spread of tr(tau)/(3 rho0) = %.3g "
              "of the largest stress component\n", antilocking.c_str(), spread);
  return spread;
}

// The optional stress approximation (Table 4.1 steps 6-7): cell-based, it makes the mean stress
// cell-constant (it does not hold without it, so the check is not vacuous).
TEST(AntilockingTest, CellStressAveragingMakesTheMeanStressCellConstant) {
  EXPECT_LT(CellSpreadOfMeanStress("{method: cell, stress: true}"), 1e-12);
  EXPECT_GT(CellSpreadOfMeanStress("{method: cell}"), 1e-3);
}

// The stress approximation with the full-tensor approaches (Table 4.1 steps 6-7 with AS2 (4.17)-
// (4.22) and the hybrid (4.35)), on the plane-strain components of tau/rho0: with the constant fit
// every component is cell-constant; with the linear fit the shear is cell-constant and the normal
// components are linear in the cell; the hybrid's deviator is the cell-based AS2 one. Each check is
// also shown to fail without the stress approximation.
TEST(AntilockingTest, FullTensorStressAveragingGivesTheFittedFieldInEachCell) {
  const auto q00 = [](const Mat3& q) { return q(0, 0); };
  const auto q11 = [](const Mat3& q) { return q(1, 1); };
  const auto q01 = [](const Mat3& q) { return q(0, 1); };
  const auto dev = [](const Mat3& q) { return (q(0, 0) - q(1, 1)) / 2; };
  const std::string as2 = "{method: cell, approach: volumetric_deviatoric";
  {
    const CellStress c = ColumnCollapseCellStress(as2 + ", fit: constant, stress: true}");
    std::printf("AS2 constant + stress: in-cell spread of q00 %.3g, q11 %.3g, q01 %.3g\n",
                c.Spread(q00), c.Spread(q11), c.Spread(q01));
    EXPECT_LT(c.Spread(q00), 1e-12);
    EXPECT_LT(c.Spread(q11), 1e-12);
    EXPECT_LT(c.Spread(q01), 1e-12);
    const CellStress off = ColumnCollapseCellStress(as2 + ", fit: constant}");
    std::printf("AS2 constant, strain only: in-cell spread of q01 %.3g\n", off.Spread(q01));
    EXPECT_GT(off.Spread(q01), 1e-5);  // 9.7e-5 measured: the elastic shear follows the strain
  }
  {
    const CellStress c = ColumnCollapseCellStress(as2 + ", stress: true}");
    std::printf("AS2 linear + stress: q01 spread %.3g; plane residual q00 %.3g, q11 %.3g\n",
                c.Spread(q01), c.PlaneResidual(q00), c.PlaneResidual(q11));
    EXPECT_LT(c.Spread(q01), 1e-12);
    EXPECT_LT(c.PlaneResidual(q00), 1e-10);
    EXPECT_LT(c.PlaneResidual(q11), 1e-10);
    const CellStress off = ColumnCollapseCellStress(as2 + "}");
    std::printf("AS2 linear, strain only: plane residual q00 %.3g\n", off.PlaneResidual(q00));
    EXPECT_GT(off.PlaneResidual(q00), 1e-4);
  }
  {
    const CellStress c = ColumnCollapseCellStress("{method: hybrid, stress: true}");
    std::printf("hybrid + stress: q01 spread %.3g, deviator plane residual %.3g, q00 plane residual "
                "%.3g\n", c.Spread(q01), c.PlaneResidual(dev), c.PlaneResidual(q00));
    EXPECT_LT(c.Spread(q01), 1e-12);
    EXPECT_LT(c.PlaneResidual(dev), 1e-10);
    EXPECT_GT(c.PlaneResidual(q00), 1e-6);  // the trace is node-based, not a cell plane
  }
}

// In the tank at rest, the stress approximation on top of the strain one: cell-based it changes
// nothing (the strain projection already makes a fluid's pressure cell-constant), node-based it
// smooths the pressure a second time (docs/antilocking.md).
// Mirrored ghost nodes (domain.ghost_nodes: mirror, docs/walls.md) in the same tank: with the
// interpolated normal velocity zero on the walls the pressure RMS falls from 4.2 % to 3.3 %
// (node-based AS1, measured 2026-12-01). The other tank tests run with the default, mirror.
TEST(AntilockingTest, MirroredGhostNodesLowerTheTankPressureError) {
  const Real constrained = TankPressureRms("node", "constrain");
  const Real mirrored = TankPressureRms("node", "mirror");
  std::printf("tank, node-based: ghost nodes constrain %.4f, mirror %.4f\n", constrained, mirrored);
  EXPECT_LT(mirrored, 0.9 * constrained);
  EXPECT_LT(mirrored, 0.04);
}

TEST(AntilockingTest, StressAveragingInATank) {
  const Real node = TankPressureRms("node, stress: true");
  const Real cell = TankPressureRms("cell, stress: true");
  std::printf("tank with stress averaging: node %.4f, cell %.4f\n", node, cell);
  EXPECT_LT(node, 0.05);
  EXPECT_LT(cell, 0.10);
  const Real hybrid = TankPressureRms("hybrid, stress: true");
  const Real node_as2 = TankPressureRms("node, approach: volumetric_deviatoric, fit: constant, stress: true");
  const Real cell_as3 = TankPressureRms("cell, approach: constant_volumetric, stress: true");
  std::printf("tank with stress averaging: hybrid %.4f, node AS2 constant %.4f, cell AS3CV %.4f\n",
              hybrid, node_as2, cell_as3);
  EXPECT_LT(hybrid, 0.05);
  EXPECT_LT(node_as2, 0.05);
  EXPECT_LT(cell_as3, 0.10);
}

// The cantilever at nu = 0.49 with the full-tensor stress approximation on top of the strain one
// (Table 4.1 steps 6-7): cell-based AS3CV stays unlocked (1.0260 / 1.0194, as without it). On node
// supports (node AS1, hybrid) the stress step projects the *total* mean stress, and the beam loses
// its oscillation as with `strain: total` (docs/antilocking.md); that is not asserted here.
TEST(AntilockingTest, CellStressAveragingKeepsTheCantileverUnlocked) {
  const BeamResult as3 = Cantilever("method: cell, approach: constant_volumetric, stress: true");
  EXPECT_NEAR(as3.period_ratio, 1.0, 0.03);
  EXPECT_NEAR(as3.amplitude_ratio, 1.0, 0.03);
}

// The viscoplastic fluids (Anura3D §7.2.2-7.2.3) take their pressure from the same equation of
// state as the Newtonian fluid: a Bingham mud (tau_y = 200 Pa, mu_d = 5 Pa s, mu_max = 500 Pa s:
// scenes/mudflow_2d.yaml's, at the water's density and K) and a frictional fluid (phi = 30 deg,
// c = 0, same viscosities) at rest in the tank. At rest the regularised flow stress vanishes and
// the pressure is rho g depth, but the fluid sits on its viscous plateau mu_max, which damps the
// checkerboard (plain 13.6 %, water 50 %) and slows the flow that corrects the volume field. The
// node-based projection of the *total* volumetric strain then makes it worse (21 %; a Newtonian
// fluid of 500 Pa s does the same, 24 %, one of 50 Pa s not: 3.3 %), the projection of the
// step's increment better (8.8 %): docs/antilocking.md, "Viscoplastic fluids".
TEST(AntilockingTest, ViscoplasticFluidsGetHydrostaticPressureWithIncrementAntiLocking) {
  const std::string mud =
      "{model: bingham_fluid, density: 997.5, bulk_modulus: 2.0e6, viscosity: 5, "
      "yield_stress: 200, max_viscosity: 500}";
  const std::string frictional =
      "{model: frictional_fluid, density: 997.5, bulk_modulus: 2.0e6, viscosity: 5, "
      "friction_angle_deg: 30, max_viscosity: 500}";
  for (const std::string& material : {mud, frictional}) {
    const Real plain = TankPressureRms("none", "", material);
    const Real increment = TankPressureRms("node, strain: increment", "", material);
    std::printf("tank of %s: pressure RMS plain %.4f, node increment %.4f\n", material.c_str(),
                plain, increment);
    EXPECT_LT(increment, 0.10);
    EXPECT_LT(increment, 0.8 * plain);
  }
}

TEST(AntilockingTest, NodeBasedGivesHydrostaticPressureInATank) {
  const Real plain = TankPressureRms("none");
  const Real node = TankPressureRms("node");
  const Real cell = TankPressureRms("cell");
  std::printf("tank: RMS ratio plain / node = %.2f, plain / cell = %.2f\n", plain / node,
              plain / cell);
  EXPECT_LT(node, 0.05);
  EXPECT_GT(plain / node, 2.0);  // plain MPM is clearly worse
}

// The full-tensor approaches on the same beam (seed §4.2-4.3, Fig. 6.11): AS3CV (constant trace,
// linear normal deviator, constant shears per cell) unlocks it, as in the seed where it was the
// only full-tensor variant accurate as nu -> 0.49; AS2 (a linear trace per cell) does not cure
// volumetric locking, only shear locking, and stays as stiff as plain MPM; the hybrid (node-based
// trace, cell-based deviator) unlocks it on the increment, like node-based AS1.
TEST(AntilockingTest, FullTensorApproachesOnTheIncompressibleCantilever) {
  const BeamResult as3 = Cantilever("method: cell, approach: constant_volumetric");
  EXPECT_NEAR(as3.period_ratio, 1.0, 0.03);
  EXPECT_NEAR(as3.amplitude_ratio, 1.0, 0.03);
  const BeamResult hybrid = Cantilever("method: hybrid, strain: increment");
  EXPECT_NEAR(hybrid.period_ratio, 1.0, 0.03);
  EXPECT_NEAR(hybrid.amplitude_ratio, 1.0, 0.03);
  const BeamResult as2 = Cantilever("method: cell, approach: volumetric_deviatoric");
  EXPECT_LT(as2.period_ratio, 0.9) << "a linear trace per cell must not unlock the beam";
  // Node-based AS2 on the increment unlocks the beam (measured 1.004 / 0.998), unlike cell-based
  // AS2.
  const BeamResult node_as2 = Cantilever("method: node, approach: volumetric_deviatoric, strain: increment");
  EXPECT_NEAR(node_as2.period_ratio, 1.0, 0.03);
  EXPECT_NEAR(node_as2.amplitude_ratio, 1.0, 0.03);
  // `fit: constant` (the seed's ConstantAntiLocking AS2): every component constant per cell. The
  // constant trace unlocks the beam as AS3CV does, and the constant deviator softens it a little
  // more (measured 1.036 / 1.028, AS3CV 1.026 / 1.019); the hybrid with a constant cell deviator
  // is as close as the linear one (1.004 / 0.998).
  const BeamResult as2c = Cantilever("method: cell, approach: volumetric_deviatoric, fit: constant");
  EXPECT_GT(as2c.period_ratio, 1.0);
  EXPECT_LT(as2c.period_ratio, 1.05);
  EXPECT_NEAR(as2c.amplitude_ratio, 1.0, 0.05);
  const BeamResult hybrid_c = Cantilever("method: hybrid, strain: increment, fit: constant");
  EXPECT_NEAR(hybrid_c.period_ratio, 1.0, 0.03);
  EXPECT_NEAR(hybrid_c.amplitude_ratio, 1.0, 0.03);
}

// In the tank at rest the hybrid's pressure is the node-based one (its trace is node-based AS1;
// the deviator of a fluid at rest carries no pressure): below 5 %.
TEST(AntilockingTest, HybridGivesHydrostaticPressureInATank) {
  EXPECT_LT(TankPressureRms("hybrid"), 0.05);
  // Node-based AS3CV: the trace is node-based AS1's (3.3 %); node-based AS2 fits the trace
  // linearly over each node's support (6.2 % with constrained ghost nodes). With mirrored ghost
  // nodes (the default) AS2's column rings on after the gravity ramp (floor force RMS 18 % of the
  // weight over 0.75-1 s, 3 % over 0.9-1 s; constrained 0.7 % and 0.03 %): the wall layer
  // dissipates less, and AS2's ringing decays more slowly than AS1's (docs/walls.md). Its
  // settled pressure is therefore measured with constrained ghosts.
  EXPECT_LT(TankPressureRms("node, approach: constant_volumetric"), 0.05);
  EXPECT_LT(TankPressureRms("node, approach: volumetric_deviatoric", "constrain"), 0.10);
  // Node-based AS2 with `fit: constant` (every component the node's weighted mean): 3.26 %.
  EXPECT_LT(TankPressureRms("node, approach: volumetric_deviatoric, fit: constant"), 0.05);
}

// The seed's dam break with barrier (§6.1.2, scenes/dam_break_barrier_2d.yaml: a 4 x 2 m column
// surges 6 m along the floor into a barrier and rebounds), run undamped through the impact to
// t = 2 s as in the seed, then damped (local damping alpha = 0.7 until `settled`, 1.25 s by
// default, Anura3D (6.23)) and let go undamped for 0.25 s. Returns the RMS over particles of
// their pressure (time-averaged over the last 0.25 s) minus rho g depth, relative to rho g h,
// with h = m / (rho0 x 6 m) the incompressible depth over the floor between the left wall and
// the barrier. The water is not at rest by then (currents up to ~1 m/s remain; after 6 s of
// damping still 0.06 m/s; docs/antilocking.md), so this measures the pressure noise after an
// impact, not a settled state.
Real BarrierPressureRms(const std::string& antilocking, Real settled = 3.25) {
  constexpr Real kRho = 997.5, kG = 9.81, kFloor = 6.0, kImpact = 2.0;
  const Real end = settled + 0.25;
  LoadedScene scene = LoadScene(testing::ScenePath("dam_break_barrier_2d.yaml"),
                                {"materials.water.antilocking={" + antilocking + "}"});
  Real mass = 0;
  for (Real m : scene.state.particles.mass) mass += m;
  const Real h = mass / (kRho * kFloor);
  testing::RunUntil(scene, kImpact, [](const State&, const StepReport&) {});
  scene.model.damping = LocalDamping{0.7, settled};
  PressureSamples samples;
  Real vmax = 0;
  testing::RunUntil(scene, end, [&](const State& s, const StepReport&) {
    if (s.time < settled) return;
    samples.Add(s.particles);
    for (const Vec3& v : s.particles.v) vmax = std::max(vmax, v.norm());
  });
  const Real rms = samples.RmsAboutHydrostatic(kRho, kG, h);
  std::printf("dam break with barrier after the impact, antilocking {%s}: RMS(p - rho g depth) / rho g h "
              "= %.4f (%zu particles, h = %.3f m, max |v| after release %.2e m/s)\n",
              antilocking.c_str(), rms, samples.pressure.size(), h, vmax);
  return rms;
}

// The seed's dam break with barrier after the impact: with node-based averaging (the water's
// default; the hybrid gives the same fluid pressure, see the tank) the pressure is within 5 % of
// hydrostatic (measured 3.4 %; 4.9 % with constrained ghost nodes), plain MPM's is off by several times rho g h (ratio > 10).
TEST(AntilockingTest, DamBreakWithBarrierPressureAfterTheImpact) {
  const Real plain = BarrierPressureRms("method: none");
  const Real node = BarrierPressureRms("method: node");
  std::printf("dam break with barrier: RMS ratio plain / node = %.2f\n", plain / node);
  EXPECT_LT(node, 0.05);
  EXPECT_GT(plain / node, 10.0);
}

// Anura3D's strain smoothing (manual §6.7, (6.34)-(6.37)) on the strain increment, its default:
// unlocks the nu = 0.49 beam within 3 %. In the tank at rest the smoothed total strain brings
// the pressure RMS to 6 % (node-based AS1: 4.2 %), the increment alone to 9.6 % (as cell-based):
// gated below 10 % (plain MPM: 0.50).
TEST(AntilockingTest, StrainSmoothingUnlocksTheCantileverAndSmoothsTheTankPressure) {
  const BeamResult beam = Cantilever("method: smoothing");
  EXPECT_NEAR(beam.period_ratio, 1.0, 0.03);
  EXPECT_NEAR(beam.amplitude_ratio, 1.0, 0.03);
  EXPECT_LT(TankPressureRms("smoothing, strain: total"), 0.10);
}


struct SettledBarrier {
  Real rms;       // pressure RMS about rho g depth over rho g h (PressureSamples)
  Real crowding;  // the bottom 0.15 m band: sum of the particles' V0 over the band's volume
};

// The dam break with barrier (scenes/dam_break_barrier_2d.yaml) run undamped through the impact
// to t = 2 s, then with local damping alpha = 0.7 to `end`, each particle's pressure averaged
// over [end, end + 0.25 s]; prints the pressure error by height band and the largest speed.
SettledBarrier BarrierSettled(const std::string& ghosts, const std::string& method, bool shift,
                              Real end) {
  constexpr Real kRho = 997.5, kG = 9.81, kFloor = 6.0, kBand = 0.15;
  LoadedScene scene = LoadScene(testing::ScenePath("dam_break_barrier_2d.yaml"),
                                {"domain.ghost_nodes=" + ghosts,
                                 "materials.water.antilocking={method: " + method + "}",
                                 std::string("materials.water.particle_shifting=") +
                                     (shift ? "true" : "false")});
  const Real h = testing::TotalMass(scene.state.particles) / (kRho * kFloor);
  testing::RunUntil(scene, 2.0, [](const State&, const StepReport&) {});
  scene.model.damping = LocalDamping{0.7, end};
  PressureSamples samples;
  testing::RunUntil(scene, end + 0.25, [&](const State& s, const StepReport&) {
    if (s.time >= end) samples.Add(s.particles);
  });
  Real volume = 0, vmax = 0;
  const Particles& P = scene.state.particles;
  for (size_t p = 0; p < P.size(); ++p) {
    if (P.x[p].y() < kBand && P.x[p].x() < kFloor) volume += P.volume0[p];
    vmax = std::max(vmax, P.v[p].norm());
  }
  const SettledBarrier r{samples.RmsAboutHydrostatic(kRho, kG, h), volume / (kBand * kFloor)};
  std::printf("barrier damped to %g s, ghost nodes %s, antilocking %s%s: RMS %.4f, bottom band "
              "crowding %.3f, largest speed %.4f m/s\n", end, ghosts.c_str(), method.c_str(),
              shift ? ", particle shifting" : "", r.rms, r.crowding, vmax);
  samples.PrintBands(kRho, kG, h, {0, 0.15, 0.3, 0.6, 0.9, 1.2, 1.5});
  return r;
}

// Particle shifting (the delta-correction, src/stabilize/particle_shifting.h) against the
// crowding that node-based AS1 lets build at the floor of the settled barrier: damped to 4 s,
// node-based alone crowds the bottom band to 1.256 with a pressure RMS of 0.073 (and the
// crowding keeps growing: 1.41 / 0.085 at 8 s, 1.60 / 0.137 at 14 s); with shifting the band
// holds 0.983 and the RMS is 0.054 (0.057 at 8 s, 0.058 at 14 s). Measured 2026-12-05, 41 s.
TEST(AntilockingTest, ParticleShiftingRemovesTheFloorCrowdingOfTheSettledBarrier) {
  const SettledBarrier node = BarrierSettled("mirror", "node", false, 4.0);
  const SettledBarrier shifted = BarrierSettled("mirror", "node", true, 4.0);
  EXPECT_GT(node.crowding, 1.15);  // the problem is there without shifting
  EXPECT_NEAR(shifted.crowding, 1.0, 0.03);
  EXPECT_LT(shifted.rms, 0.065);
  EXPECT_LT(shifted.rms, 0.85 * node.rms);
}

// Water at rest without damping: a 2-D tank 0.6 m wide, 0.16 m deep (K = 2e5 Pa, mu = 5 Pa s,
// h = 0.02 m, 2 x 2 particles per cell, mirrored ghosts), gravity ramped over 0.1 s, run to
// 2 s. Returns the bottom band's crowding: the particles' J V0 in y < 0.04 m over the band's
// area.
Real TankFloorCrowding(const std::string& antilocking, bool shifting) {
  const std::string text = R"(name: tank_at_rest
dimension: 2
time: {end: 2.0, cfl: 0.3}
gravity: [0, -9.81]
gravity_ramp: 0.1
grid: {cell_size: 0.02, shape_function: quadratic_bspline, transfer: apic, update: usl}
domain: {min: [0, 0], max: [0.6, 0.4], walls: {x-: slip, x+: slip, y-: slip}}
materials:
  water: {model: newtonian_fluid, density: 1000, bulk_modulus: 2.0e5, viscosity: 5.0,
          antilocking: {)" + antilocking + "}, particle_shifting: " +
                           (shifting ? "true" : "false") + R"(}
bodies:
  - {name: water, material: water, region: {box: {min: [0, 0], max: [0.6, 0.16]}}, particles_per_cell: 2}
)";
  constexpr Real kBand = 0.04, kWidth = 0.6;
  LoadedScene scene = LoadSceneFromString(text, "tank_at_rest.yaml");
  testing::RunUntil(scene, 2.0, [](const State&, const StepReport&) {});
  const Particles& P = scene.state.particles;
  Real volume = 0;
  for (size_t p = 0; p < P.size(); ++p)
    if (P.x[p].y() < kBand) volume += Det3(P.F[p]) * P.volume0[p];
  const Real crowding = volume / (kBand * kWidth);
  std::printf("tank at rest to 2 s, antilocking {%s}%s: bottom band crowding %.3f\n",
              antilocking.c_str(), shifting ? ", particle shifting" : "", crowding);
  return crowding;
}

// KNOWN GAP: node-based AS1 on the total strain (the Newtonian fluid's default) lets water at
// rest crowd at the floor even without damping. Each particle's J is replaced by its supports'
// mean, so a particle pressed closer to its neighbours than its J says meets no pressure of its
// own. Projecting only the increment keeps each particle's own J and does not crowd, but leaves
// impact noise in the pressure (the barrier's RMS 0.486 against 0.030, docs/antilocking.md).
// Particle shifting removes the crowding. Measured 2026-12-08 (2-D): bottom band 1.360 / 1.718
// at 2 / 5 s under the default (3-D slabs alike); without anti-locking, with the increment or
// with shifting within 0.93-1.07. A floating body rides the crowding water down
// (rigid_coupling_test, NodeAntiLockingLetsTheFloatingBoxSinkUnlessTheParticlesShift).
TEST(AntilockingTest, TotalStrainProjectionCrowdsWaterAtRestUnlessTheParticlesShift) {
  const Real total = TankFloorCrowding("method: node", false);
  const Real increment = TankFloorCrowding("method: node, strain: increment", false);
  const Real shifted = TankFloorCrowding("method: node", true);
  EXPECT_GT(total, 1.2);  // the gap: more particle volume in the bottom band than it holds
  EXPECT_NEAR(increment, 1.0, 0.08);
  EXPECT_NEAR(shifted, 1.0, 0.08);
}

// The linear node fit (`{method: node, fit: linear}`: each node's trace is its support's
// weighted least-squares linear fit evaluated at the node, seed (4.29)-(4.32))
// with the ghost nodes folded at every frictionless wall (`domain.ghost_nodes: fold_all`,
// docs/walls.md), the settle recipe of docs/antilocking.md. The plain node average (AS1) takes
// the support's centroid value: at a floor node the centroid lies about half a cell inside the
// water, at a surface node half a cell below the surface, so the interpolated pressure is
// biased low at the floor and high at the surface. The linear fit removes that bias, but only
// with the fold: with the velocity mirror it is worse than AS1. Measured 2026-12-07: tank at
// rest RMS 0.0136 (node AS1 with the default mirror 0.0326; node AS1 with fold_all 0.053; the
// linear fit with the mirror 0.076, and the floor reaction still rings at 6 % of the weight).
TEST(AntilockingTest, LinearNodeFitWithFoldedGhostsGivesHydrostaticTank) {
  const std::string linear = "node, fit: linear";
  const Real folded = TankPressureRms(linear, "fold_all");
  const Real node = TankPressureRms("node");
  std::printf("tank: linear node fit with fold_all %.4f; node AS1 %.4f\n", folded, node);
  EXPECT_LT(folded, 0.02);
  EXPECT_LT(folded, 0.5 * node);
}

// The settle recipe on the seed's dam break with barrier (§6.1.2): undamped through the impact
// to 2 s, damped (alpha = 0.7) to 6 s, pressure averaged over 6-6.25 s, with the linear node
// fit, folded ghosts and particle shifting (docs/antilocking.md, "Linear node fit"). Measured
// 2026-12-07: RMS 0.0183, bottom band crowding 0.989 (the default, node AS1 with mirrored
// ghosts and shifting: 0.048 at 6 s, 0.054-0.058 at 4-14 s; the recipe without shifting 0.032,
// crowding 1.044). With node AS2 instead of `fit: linear` and no extrapolation limit
// (kMaxNodeExtrapolation) this run blew up at the folded side wall. The issue's gate is 5 %.
// The same run without anti-locking (plain MPM, the same ghosts and shifting) shows what the
// averaging removes: its checkerboard leaves an RMS of 4.01 (measured 2026-12-07 after the
// trace-only moments, with the recipe's 0.0184: ratio 0.0046; mirror, no shifting: 3.05 at 8 s,
// DISABLED_BarrierSettledWithMirroredGhostNodes). 25-60 s for both.
TEST(AntilockingTest, LinearNodeFitSettlesTheBarrierHydrostaticWithinFivePercent) {
  const SettledBarrier r =
      BarrierSettled("fold_all", "node, fit: linear", true, 6.0);
  const SettledBarrier plain = BarrierSettled("fold_all", "none", true, 6.0);
  std::printf("settled barrier: recipe RMS %.4f, plain MPM %.4f (ratio %.4f)\n", r.rms, plain.rms,
              r.rms / plain.rms);
  EXPECT_LT(r.rms, 0.035);
  EXPECT_NEAR(r.crowding, 1.0, 0.03);
  EXPECT_GT(plain.rms, 0.2);  // the locking the averaging fixes is there without it
  EXPECT_LT(r.rms, 0.1 * plain.rms);
}

// By hand (about 4 min): the dam break with barrier damped for 6 s after the impact (to 8 s;
// SURGE_BARRIER_END sets another end), with mirrored and constrained ghost nodes, without
// anti-locking and with particle shifting (SURGE_BARRIER_RUNS="mirror node shift|..." picks runs).
// Measured 2026-12-01: mirror + node RMS 0.080, crowding 1.40; constrain + node 0.102,
// 1.43; mirror + none 3.05 (checkerboard), 0.94. The crowding comes from the node-averaged J,
// not from the wall (docs/antilocking.md, docs/walls.md). Measured 2026-12-03: mirror + node on
// the increment: no crowding (0.997) but RMS 0.498 (the noise of the impact is never removed).
// 2026-12-05: mirror + node 0.085 / 1.41, with particle shifting 0.057 / 0.997.
TEST(AntilockingTest, DISABLED_BarrierSettledWithMirroredGhostNodes) {
  const char* only = std::getenv("SURGE_BARRIER_RUNS");
  const char* end = std::getenv("SURGE_BARRIER_END");
  for (const std::string run : {"mirror node", "constrain node", "mirror none",
                                "mirror node, strain: increment", "mirror node shift"}) {
    if (only && std::string(only).find(run) == std::string::npos) continue;
    const bool shift = run.ends_with(" shift");
    const std::string plain = shift ? run.substr(0, run.size() - 6) : run;
    const SettledBarrier r = BarrierSettled(plain.substr(0, plain.find(' ')),
                                            plain.substr(plain.find(' ') + 1), shift,
                                            end ? std::atof(end) : 8.0);
    if (plain.ends_with(" node")) {
      EXPECT_LT(r.rms, 0.2);
    }
  }
}

}  // namespace
}  // namespace surge
