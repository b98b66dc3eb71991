// The fast bond kernel (docs/performance.md): the same physics as the textbook formulas, breaking
// fused into the force pass with exactly the semantics of the separate pass, the same bits for any
// thread count, and at most 8 bytes of bond storage per directed bond.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstring>
#include <random>

#include "core/avx2.hpp"
#include "core/partial_volume.hpp"
#include "materials/pmb/pmb.hpp"
#include "lattice.hpp"
#include "pmb_s0.hpp"

namespace {

constexpr double kDx = 1e-3;

// A 9×8×7 brick (rows longer and shorter than the kernel's 64-bond chunks), breakable with a low
// fracture energy; with two_blocks the upper half is a second, stiffer block, and the bottom layer
// is a no-fail set.
pd::Model brick(bool two_blocks, const std::string& partial_volume = "none") {
  pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 1e9, 1000.0, 0.05);
  c.partial_volume = partial_volume;
  pd::Nodes nodes = pdtest::cubic_lattice(9, 8, 7, kDx, 3);
  if (two_blocks) {
    pdtest::add_stiff_top_and_no_fail_bottom(c, nodes, kDx, 3e9, 0.2);
  } else {  // the no-fail bottom layer alone
    pd::NodeSet bottom{"bottom", std::vector<std::uint8_t>(nodes.size(), 0)};
    for (std::size_t i = 0; i < nodes.size(); ++i) bottom.member[i] = nodes.x[2][i] < 0.5 * kDx;
    nodes.sets.push_back(bottom);
    c.no_fail_sets = {"bottom"};
  }
  return pd::build_model(c, std::move(nodes));
}

// Random displacements of a few percent of dx: stretches up to ~1e-2, well past s0 for many bonds.
pd::Vec3Array shaken(const pd::Model& m, unsigned seed, double amplitude = 0.03 * kDx) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> d(-amplitude, amplitude);
  pd::Vec3Array u = pd::make_vec3(m.nodes.size());
  for (auto& c : u)
    for (double& x : c) x = d(rng);
  return u;
}

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

}  // namespace

TEST(Kernel, FusedBreakingGivesBitwiseTheSeparatePassThenTheForce) {
  for (bool two_blocks : {false, true}) {
    pd::Model separate = brick(two_blocks), fused = brick(two_blocks);
    const std::size_t n = separate.nodes.size();
    // Three rounds, so that already-broken bonds and newly broken ones mix.
    for (unsigned round = 0; round < 3; ++round) {
      const pd::Vec3Array u = shaken(separate, 7 + round, (0.005 + 0.01 * round) * kDx);
      pd::Vec3Array f_sep = pd::make_vec3(n), f_fused = pd::make_vec3(n);
      std::vector<double> w_sep(n), w_fused(n);
      double e_sep = 0.0, e_fused = 0.0;
      const std::int64_t n_sep = pd::update_broken_bonds(separate, u, &e_sep);
      pd::add_pmb_force(separate, u, f_sep, w_sep.data());
      const std::int64_t n_fused = pd::break_bonds_and_add_pmb_force(fused, u, f_fused, w_fused.data(), &e_fused);
      EXPECT_GT(n_sep, 0) << "round " << round << " breaks nothing: the test would prove nothing";
      EXPECT_EQ(n_fused, n_sep);
      EXPECT_EQ(e_fused, e_sep);
      EXPECT_EQ(fused.bonds.broken, separate.bonds.broken);
      for (std::size_t d = 0; d < 3; ++d) EXPECT_TRUE(same_bits(f_fused[d], f_sep[d])) << "component " << d;
      EXPECT_TRUE(same_bits(w_fused, w_sep));
    }
    // No bond with an end in the no-fail set broke.
    for (std::size_t i = 0; i < n; ++i)
      for (auto k = fused.bonds.offsets[i]; k < fused.bonds.offsets[i + 1]; ++k)
        if (fused.no_fail[i] || fused.no_fail[static_cast<std::size_t>(fused.bonds.neighbour[static_cast<std::size_t>(k)])])
          ASSERT_EQ(fused.bonds.broken[static_cast<std::size_t>(k)], 0);
  }
}

TEST(Kernel, FusedPassIsBitwiseTheSameWithOneAndTwoThreads) {
  const int saved = omp_get_max_threads();
  for (bool two_blocks : {false, true}) {
    pd::Vec3Array f[2];
    std::vector<double> w[2];
    std::vector<std::uint8_t> broken[2];
    double energy[2] = {0.0, 0.0};
    std::int64_t count[2] = {0, 0};
    for (int r = 0; r < 2; ++r) {
      omp_set_num_threads(r + 1);
      pd::Model m = brick(two_blocks, "lammps");
      f[r] = pd::make_vec3(m.nodes.size());
      w[r].assign(m.nodes.size(), 0.0);
      for (unsigned round = 0; round < 3; ++round)
        count[r] += pd::break_bonds_and_add_pmb_force(m, shaken(m, 3 + round, 0.01 * kDx), f[r], w[r].data(), &energy[r]);
      broken[r] = m.bonds.broken;
    }
    omp_set_num_threads(saved);
    EXPECT_GT(count[0], 0);
    EXPECT_EQ(count[0], count[1]);
    EXPECT_EQ(energy[0], energy[1]);
    EXPECT_EQ(broken[0], broken[1]);
    for (std::size_t d = 0; d < 3; ++d) EXPECT_TRUE(same_bits(f[0][d], f[1][d]));
    EXPECT_TRUE(same_bits(w[0], w[1]));
  }
}

// The kernel's path for one block of full volumes with the same V everywhere (PmbArrays::uniform:
// no gather of V_j, no ν) gives the bits of the general path: forces, W, the flags it breaks, the
// lost energy per node and the count, over rounds that mix old and new breaks.
TEST(Kernel, UniformVolumePathIsBitwiseTheGeneralPath) {
  EXPECT_FALSE(pd::pmb_arrays(brick(true), shaken(brick(true), 1)).uniform);              // two blocks
  EXPECT_FALSE(pd::pmb_arrays(brick(false, "lammps"), shaken(brick(false), 1)).uniform);  // ν from |ξ|
  pd::Model uniform = brick(false), general = brick(false);
  const std::size_t n = uniform.nodes.size();
  std::int64_t broke = 0;
  for (unsigned round = 0; round < 3; ++round) {
    const pd::Vec3Array u = shaken(uniform, 11 + round, (0.005 + 0.01 * round) * kDx);
    pd::Vec3Array f[2] = {pd::make_vec3(n), pd::make_vec3(n)};
    std::vector<double> w[2] = {std::vector<double>(n), std::vector<double>(n)};
    std::vector<double> lost[2] = {std::vector<double>(n), std::vector<double>(n)};
    std::int64_t count[2] = {0, 0};
    for (int r = 0; r < 2; ++r) {
      pd::Model& m = r == 0 ? uniform : general;
      pd::PmbArrays a = pd::pmb_arrays(m, u);
      ASSERT_TRUE(a.uniform);
      a.uniform = r == 0;
      const pd::PmbBreaking br{m.bonds.broken.data(), m.material.critical_pair.data(), m.no_fail.data(), lost[r].data()};
      count[r] = pd::add_pmb_force_density(a, f[r][0].data(), f[r][1].data(), f[r][2].data(), w[r].data(), &br);
    }
    broke += count[0];
    EXPECT_EQ(count[0], count[1]);
    EXPECT_EQ(uniform.bonds.broken, general.bonds.broken);
    for (std::size_t d = 0; d < 3; ++d) EXPECT_TRUE(same_bits(f[0][d], f[1][d])) << "component " << d;
    EXPECT_TRUE(same_bits(w[0], w[1]));
    EXPECT_TRUE(same_bits(lost[0], lost[1]));
  }
  EXPECT_GT(broke, 0) << "nothing broke: the rounds would not test the flags";
}

// The AVX2 rows (materials/pmb/pmb_row_avx2.hpp) give the portable rows' bits in every variant
// the kernel has (every brick has a no-fail bottom layer): one block of equal full volumes (the
// uniform path), partial volumes (ν from |ξ|), two blocks, unequal volumes, a surface correction
// with one block and with two, LAMMPS's order (force first) and its per-node s0; rows whose lengths are not multiples of 4; a bond crushed to a
// point; over rounds that break bonds. Forces, W, flags, counts and lost energy are compared.
TEST(Kernel, Avx2RowIsBitwiseThePortableRow) {
  if (!pd::avx2_rows()) GTEST_SKIP() << "no AVX2 rows here (a CPU without AVX2, or a build other than GCC on x86-64)";
  // The switch back on whatever happens below (an ASSERT returns early).
  struct Restore {
    ~Restore() { pd::set_avx2_rows(true); }
  } restore;
  struct Variant {
    const char* name;
    bool two_blocks;
    const char* partial_volume;
    bool unequal_volumes, corrected, lammps_rules;
  };
  const Variant variants[] = {
      {"uniform", false, "none", false, false, false},         {"partial volumes", false, "lammps", false, false, false},
      {"two blocks", true, "none", false, false, false},       {"unequal volumes", false, "none", true, false, false},
      {"surface correction", true, "hhb", false, true, false}, {"lammps rules", true, "lammps", true, true, true},
      {"one block, corrected", false, "hhb", false, true, false},
  };
  std::int64_t rows_not_multiple_of_4 = 0;
  for (const Variant& v : variants) {
    pd::Model models[2] = {brick(v.two_blocks, v.partial_volume), brick(v.two_blocks, v.partial_volume)};
    for (pd::Model& m : models) {
      if (v.unequal_volumes)
        for (std::size_t i = 0; i < m.nodes.size(); ++i) m.nodes.volume[i] *= 1.0 + 0.01 * static_cast<double>(i % 7);
      if (v.corrected) {
        m.bonds.surface_factor.resize(m.bonds.directed());
        for (std::size_t k = 0; k < m.bonds.directed(); ++k) m.bonds.surface_factor[k] = 1.0 + 1e-3 * static_cast<double>(k % 13);
      }
      if (v.lammps_rules) {
        m.break_after_force = true;
        pdtest::declare_s0(m, m.material.critical_pair[0]);
      }
    }
    const std::size_t n = models[0].nodes.size();
    for (std::size_t i = 0; i < n; ++i) rows_not_multiple_of_4 += (models[0].bonds.offsets[i + 1] - models[0].bonds.offsets[i]) % 4 != 0;
    EXPECT_EQ(pd::pmb_arrays(models[0], pd::make_vec3(n)).uniform, std::string(v.name) == "uniform") << v.name;
    std::int64_t broke = 0;
    for (unsigned round = 0; round < 3; ++round) {
      pd::Vec3Array u = shaken(models[0], 21 + round, (0.005 + 0.01 * round) * kDx);
      if (round == 1) {  // node 100's first neighbour moved onto it: y = 0, 1/y replaced by 1
        const auto j = static_cast<std::size_t>(models[0].bonds.neighbour[static_cast<std::size_t>(models[0].bonds.offsets[100])]);
        for (std::size_t d = 0; d < 3; ++d) u[d][j] = models[0].nodes.x[d][100] + u[d][100] - models[0].nodes.x[d][j];
      }
      pd::Vec3Array f[2] = {pd::make_vec3(n), pd::make_vec3(n)};
      std::vector<double> w[2] = {std::vector<double>(n), std::vector<double>(n)};
      double lost[2] = {0.0, 0.0};
      std::int64_t count[2] = {0, 0};
      for (int r = 0; r < 2; ++r) {
        pd::set_avx2_rows(r == 0);
        ASSERT_EQ(pd::pmb_arrays(models[r], u).avx2, r == 0);
        count[r] = v.lammps_rules ? pd::break_bonds_lammps_rules(models[r], u, &f[r], w[r].data(), &lost[r], nullptr, nullptr)
                                  : pd::break_bonds_and_add_pmb_force(models[r], u, f[r], w[r].data(), &lost[r]);
      }
      pd::set_avx2_rows(true);
      broke += count[0];
      EXPECT_EQ(count[0], count[1]) << v.name;
      EXPECT_EQ(std::memcmp(&lost[0], &lost[1], sizeof(double)), 0) << v.name;
      EXPECT_EQ(models[0].bonds.broken, models[1].bonds.broken) << v.name;
      EXPECT_EQ(pdtest::s0_of(models[0]), pdtest::s0_of(models[1])) << v.name;
      for (std::size_t d = 0; d < 3; ++d) EXPECT_TRUE(same_bits(f[0][d], f[1][d])) << v.name << " component " << d;
      EXPECT_TRUE(same_bits(w[0], w[1])) << v.name;
    }
    EXPECT_GT(broke, 0) << v.name << ": nothing broke, the rounds would not test the flags";
  }
  EXPECT_GT(rows_not_multiple_of_4, 0) << "every row a multiple of 4 bonds: the portable tail went untested";
}

TEST(Kernel, MatchesTheTextbookFormulaBondByBond) {
  // f_i = Σ c s ν V_j (y_j − y_i)/|y_j − y_i|, s = (|y_j − y_i| − |ξ|)/|ξ| (thesis eqs. 1.9–1.10,
  // 2.1), W_i = Σ ¼ c s² |ξ| ν V_j, written the plain way with the partial-volume rule's own factor,
  // against the kernel (one division per bond, lengths recomputed, chunked sums): equal to round-off.
  for (const char* rule : {"none", "lammps", "hhb"}) {
    pd::Model m = brick(true, rule);
    const pd::PartialVolumeRule& pv = pd::partial_volume_registry().get(rule);
    const pd::Vec3Array u = shaken(m, 5, 0.002 * kDx);
    const std::size_t n = m.nodes.size();
    m.bonds.broken[5] = m.bonds.broken[77] = 1;  // one direction of two bonds: the flag is per copy
    pd::Vec3Array f = pd::make_vec3(n);
    std::vector<double> w(n);
    pd::add_pmb_force(m, u, f, w.data());
    double worst = 0.0, scale = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      double ref[3] = {0, 0, 0}, ref_w = 0.0;
      for (auto k = static_cast<std::size_t>(m.bonds.offsets[i]); k < static_cast<std::size_t>(m.bonds.offsets[i + 1]); ++k) {
        if (m.bonds.broken[k]) continue;
        const auto j = static_cast<std::size_t>(m.bonds.neighbour[k]);
        double xi2 = 0.0, y2 = 0.0, e[3];
        for (std::size_t d = 0; d < 3; ++d) {
          const double xi = m.nodes.x[d][j] - m.nodes.x[d][i];
          e[d] = xi + u[d][j] - u[d][i];
          xi2 += xi * xi;
          y2 += e[d] * e[d];
        }
        const double len = std::sqrt(xi2), y = std::sqrt(y2), s = (y - len) / len;
        const double c = m.material.micromodulus_pair[static_cast<std::size_t>(m.block_index[i] * m.material.blocks + m.block_index[j])];
        const double cvn = c * m.nodes.volume[j] * pv.factor(len, m.horizon, kDx);
        for (std::size_t d = 0; d < 3; ++d) ref[d] += cvn * s * e[d] / y;
        ref_w += 0.25 * cvn * s * s * len;
      }
      for (std::size_t d = 0; d < 3; ++d) {
        worst = std::max(worst, std::fabs(f[d][i] - ref[d]));
        scale = std::max(scale, std::fabs(ref[d]));
      }
      EXPECT_NEAR(w[i], ref_w, 1e-12 * ref_w) << rule << " node " << i;
    }
    ASSERT_GT(scale, 0.0);
    EXPECT_LT(worst, 1e-12 * scale) << rule;
  }
}

TEST(Kernel, ABondCrushedToAPointHasNoForceAndStretchMinusOne) {
  pd::Model m = brick(false);
  const std::size_t n = m.nodes.size();
  pd::Vec3Array u = pd::make_vec3(n);
  const std::size_t i = pdtest::node_index(4, 4, 3, 9, 8), j = i + 1;  // neighbours one dx apart in x
  u[0][j] = -kDx;                                                      // j moved onto i
  pd::Vec3Array f = pd::make_vec3(n);
  std::vector<double> w(n);
  pd::add_pmb_force(m, u, f, w.data());
  for (std::size_t d = 0; d < 3; ++d) {
    EXPECT_TRUE(std::isfinite(f[d][i]));
    EXPECT_TRUE(std::isfinite(f[d][j]));
  }
  EXPECT_GT(w[i], 0.0);  // the crushed bond holds ¼ c (−1)² |ξ| V_j, finite
  EXPECT_TRUE(std::isfinite(w[i]));
}

TEST(Kernel, BondStorageIsAtMostEightBytesPerDirectedBond) {
  const pd::Model m = brick(false, "lammps");
  const pd::BondList& b = m.bonds;
  const double bytes = static_cast<double>(b.neighbour.capacity() * sizeof(b.neighbour[0]) +
                                           b.broken.capacity() * sizeof(b.broken[0]) +
                                           b.offsets.capacity() * sizeof(b.offsets[0]));
  EXPECT_LE(bytes / static_cast<double>(b.directed()), 8.0);
  EXPECT_EQ(sizeof(b.neighbour[0]) + sizeof(b.broken[0]), 5u);  // 32-bit index + byte flag
}
