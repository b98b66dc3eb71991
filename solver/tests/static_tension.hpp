// Test helper: the linear static tension of a lattice bar or plate (docs/theory.md C3), solved by
// conjugate gradients on the matrix-free J(0)·x of the material (the implicit integrators' path),
// and the strains read back from it: of the interior (least squares away from every face) and of
// the whole cross-section (the bar's apparent stiffness, surface layers included).
#pragma once
#include <array>
#include <cmath>
#include <vector>

#include "core/model.hpp"
#include "lattice.hpp"

namespace pdtest {

struct Tension {
  int iterations = 0;
  bool converged = false;
  double interior_xx = 0.0, interior_yy = 0.0;  // ε fitted 2δ or more from the lateral faces
  double section_xx = 0.0, section_yy = 0.0;    // ε fitted over every node of the middle third
  // Where the interior's strain comes from (measurement, validation/README.md): per x layer i the
  // interior ε_yy (slope of u_y over y, and of u_z over z in 3D, averaged) and ε_xx (central
  // difference of the interior's mean u_x); per gap j between y rows, (u_y(j+1) − u_y(j))/dx averaged
  // over the middle third in x and the interior in z.
  std::vector<double> layer_xx, layer_yy, gap_yy;
};

// An nx × ny × nz lattice (nz = 1 in 2D) at spacing dx: u_x = 0 on its left face (x = 0), and u_y,
// u_z (and u_z everywhere in 2D) held where needed against rigid motion; σ [Pa] on its right face as
// the body force σ/dx on the last layer (each node carries σ dx² of the load), or spread over the
// last `load_layers` layers as σ/(load_layers dx) (a traction carried by a layer of about δ, as the
// body-force loading of docs/theory.md C7, rather than by the one row of surface nodes whose families
// are the most truncated). Fits over the middle third in x: interior = nodes whose y (and z) index
// lies in [inner, n − 1 − inner].
inline Tension static_tension(const pd::Model& m, int nx, int ny, int nz, double dx, double sigma, int inner,
                              int load_layers = 1) {
  const std::size_t n = m.nodes.size();
  if (static_cast<std::size_t>(nx) * ny * nz != n) return Tension{};  // not this lattice: not converged
  const bool plane = m.nodes.dimension == 2;
  std::vector<std::array<bool, 3>> fixed(n, {false, false, plane});
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j) fixed[node_index(0, j, k, nx, ny)][0] = true;
  const std::size_t mid = node_index(0, ny / 2, nz / 2, nx, ny);
  fixed[mid][1] = fixed[mid][2] = true;
  if (!plane) fixed[node_index(0, 0, nz / 2, nx, ny)][2] = true;  // no rotation about x
  pd::Vec3Array b = pd::make_vec3(n);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int l = 1; l <= load_layers; ++l) b[0][node_index(nx - l, j, k, nx, ny)] = sigma / (load_layers * dx);
  const pd::Vec3Array zero = pd::make_vec3(n);
  const auto apply = [&](const pd::Vec3Array& x) {  // −J(0) x on the free components
    pd::Vec3Array y = pd::make_vec3(n);
    m.bond_model->add_jacobian_product(m, zero, x, y);
    for (int d = 0; d < 3; ++d)
      for (std::size_t i = 0; i < n; ++i) y[d][i] = fixed[i][d] ? 0.0 : -y[d][i];
    return y;
  };
  const auto dot = [&](const pd::Vec3Array& p, const pd::Vec3Array& q) {
    double s = 0.0;
    for (int d = 0; d < 3; ++d)
      for (std::size_t i = 0; i < n; ++i) s += p[d][i] * q[d][i];
    return s;
  };
  Tension out;
  pd::Vec3Array u = pd::make_vec3(n), r = b, p = b;
  double rr = dot(r, r);
  const double target = 1e-20 * rr;
  for (; out.iterations < 20000 && rr > target; ++out.iterations) {
    const pd::Vec3Array ap = apply(p);
    const double alpha = rr / dot(p, ap);
    for (int d = 0; d < 3; ++d)
      for (std::size_t i = 0; i < n; ++i) {
        u[d][i] += alpha * p[d][i];
        r[d][i] -= alpha * ap[d][i];
      }
    const double next = dot(r, r);
    for (int d = 0; d < 3; ++d)
      for (std::size_t i = 0; i < n; ++i) p[d][i] = r[d][i] + next / rr * p[d][i];
    rr = next;
  }
  out.converged = rr <= target;
  // Least squares u_c = c0 + c1 x + c2 y + c3 z (component c = x, y) over the chosen nodes.
  const auto fit = [&](int lo_j, int hi_j, int lo_k, int hi_k, double& exx, double& eyy) {
    double s[2][4][5] = {};
    for (int k = lo_k; k <= hi_k; ++k)
      for (int j = lo_j; j <= hi_j; ++j)
        for (int i = nx / 3; i < 2 * nx / 3; ++i) {
          const std::size_t q = node_index(i, j, k, nx, ny);
          const double row[4] = {1.0, m.nodes.x[0][q], m.nodes.x[1][q], plane ? 0.0 : m.nodes.x[2][q]};
          for (int c = 0; c < 2; ++c)
            for (int a = 0; a < 4; ++a) {
              for (int e = 0; e < 4; ++e) s[c][a][e] += row[a] * row[e];
              s[c][a][4] += row[a] * u[static_cast<std::size_t>(c)][q];
            }
        }
    double coef[2][4] = {};
    const int unknowns = plane ? 3 : 4;  // no z column in 2D
    for (int c = 0; c < 2; ++c) {  // Gauss elimination on the normal equations
      for (int a = 0; a < unknowns; ++a)
        for (int e = a + 1; e < unknowns; ++e) {
          const double f = s[c][e][a] / s[c][a][a];
          for (int g = a; g < 5; ++g) s[c][e][g] -= f * s[c][a][g];
        }
      for (int a = unknowns - 1; a >= 0; --a) {
        double v = s[c][a][4];
        for (int g = a + 1; g < unknowns; ++g) v -= s[c][a][g] * coef[c][g];
        coef[c][a] = v / s[c][a][a];
      }
    }
    exx = coef[0][1];
    eyy = coef[1][2];
  };
  const int kin_lo = plane ? 0 : inner, kin_hi = plane ? 0 : nz - 1 - inner;
  fit(inner, ny - 1 - inner, kin_lo, kin_hi, out.interior_xx, out.interior_yy);
  fit(0, ny - 1, 0, nz - 1, out.section_xx, out.section_yy);
  // The profiles. Slope of u_c over coordinate c on layer i: least squares over the interior nodes.
  std::vector<double> mean_ux(static_cast<std::size_t>(nx), 0.0);
  out.layer_yy.assign(static_cast<std::size_t>(nx), 0.0);
  for (int i = 0; i < nx; ++i) {
    double slope_sum = 0.0;
    int slopes = 0, count = 0;
    for (int c = 1; c <= (plane ? 1 : 2); ++c) {
      double sx = 0.0, sxx = 0.0, su = 0.0, sxu = 0.0;
      int n_c = 0;
      for (int k = kin_lo; k <= kin_hi; ++k)
        for (int j = inner; j <= ny - 1 - inner; ++j) {
          const std::size_t q = node_index(i, j, k, nx, ny);
          const double xc = m.nodes.x[static_cast<std::size_t>(c)][q], uc = u[static_cast<std::size_t>(c)][q];
          sx += xc, sxx += xc * xc, su += uc, sxu += xc * uc, ++n_c;
          if (c == 1) mean_ux[static_cast<std::size_t>(i)] += u[0][q], ++count;
        }
      slope_sum += (n_c * sxu - sx * su) / (n_c * sxx - sx * sx);
      ++slopes;
    }
    out.layer_yy[static_cast<std::size_t>(i)] = slope_sum / slopes;
    mean_ux[static_cast<std::size_t>(i)] /= count;
  }
  out.layer_xx.assign(static_cast<std::size_t>(nx), 0.0);
  for (int i = 1; i + 1 < nx; ++i)
    out.layer_xx[static_cast<std::size_t>(i)] =
        (mean_ux[static_cast<std::size_t>(i + 1)] - mean_ux[static_cast<std::size_t>(i - 1)]) / (2.0 * dx);
  out.gap_yy.assign(static_cast<std::size_t>(ny - 1), 0.0);
  for (int j = 0; j + 1 < ny; ++j) {
    double s = 0.0;
    int c = 0;
    for (int k = kin_lo; k <= kin_hi; ++k)
      for (int i = nx / 3; i < 2 * nx / 3; ++i, ++c)
        s += u[1][node_index(i, j + 1, k, nx, ny)] - u[1][node_index(i, j, k, nx, ny)];
    out.gap_yy[static_cast<std::size_t>(j)] = s / (c * dx);
  }
  return out;
}

}  // namespace pdtest
