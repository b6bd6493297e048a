#include "cranioplan/algorithms/geometry/thin_plate_spline.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace cranioplan {
namespace {

// Scattered sites in a 40 mm square (a fixed seed: the same sites every run).
std::vector<Eigen::Vector2d> scattered_sites(int n) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-20.0, 20.0);
  std::vector<Eigen::Vector2d> sites;
  for (int i = 0; i < n; ++i) sites.emplace_back(u(rng), u(rng));
  return sites;
}

// A quadratic field is the spline's trend: reproduced everywhere, far from the sites too, and
// its gradient with it.
TEST(ThinPlateSpline, ReproducesAQuadraticFieldAndItsGradient) {
  auto field = [](const Eigen::Vector2d& p) {
    return 3.0 + 0.2 * p.x() - 0.1 * p.y() + 0.01 * p.x() * p.x() - 0.02 * p.x() * p.y() +
           0.005 * p.y() * p.y();
  };
  const std::vector<Eigen::Vector2d> sites = scattered_sites(40);
  std::vector<double> values;
  for (const auto& p : sites) values.push_back(field(p));
  ThinPlateSpline tps;
  ASSERT_TRUE(tps.fit(sites, values));
  for (const Eigen::Vector2d& p :
       {Eigen::Vector2d(0, 0), Eigen::Vector2d(35, -30), Eigen::Vector2d(-12.5, 7.25)}) {
    EXPECT_NEAR(tps(p), field(p), 1e-6) << p.transpose();
    const Eigen::Vector2d g(0.2 + 0.02 * p.x() - 0.02 * p.y(), -0.1 - 0.02 * p.x() + 0.01 * p.y());
    EXPECT_NEAR((tps.gradient(p) - g).norm(), 0.0, 1e-6) << p.transpose();
  }
}

// Without smoothing the spline passes through every site; with smoothing it does not, and with
// the quadratic trend off an affine field is still reproduced.
TEST(ThinPlateSpline, InterpolatesUnlessSmoothedAndKeepsAnAffineTrend) {
  const std::vector<Eigen::Vector2d> sites = scattered_sites(30);
  std::vector<double> bumpy;
  for (const auto& p : sites) bumpy.push_back(std::sin(0.3 * p.x()) * std::cos(0.2 * p.y()));
  ThinPlateSpline exact;
  ASSERT_TRUE(exact.fit(sites, bumpy));
  for (size_t i = 0; i < sites.size(); ++i) EXPECT_NEAR(exact(sites[i]), bumpy[i], 1e-8);
  ThinPlateSpline smooth;
  ASSERT_TRUE(smooth.fit(sites, bumpy, std::vector<double>(sites.size(), 1.0)));
  double off = 0.0;
  for (size_t i = 0; i < sites.size(); ++i)
    off = std::max(off, std::abs(smooth(sites[i]) - bumpy[i]));
  EXPECT_GT(off, 1e-3) << "smoothing lets the spline leave the sites";

  std::vector<double> plane;
  for (const auto& p : sites) plane.push_back(1.0 + 0.5 * p.x() - 0.25 * p.y());
  ThinPlateSpline affine;
  affine.set_quadratic_trend(false);
  ASSERT_TRUE(affine.fit(sites, plane));
  EXPECT_NEAR(affine(Eigen::Vector2d(50, 50)), 1.0 + 25.0 - 12.5, 1e-6);
}

// Fewer than three sites, or sites on a line, fit no surface; a site closer than the minimum
// separation to an earlier one is dropped, so the earlier one's height is met.
TEST(ThinPlateSpline, RefusesDegenerateSitesAndDropsNearDuplicates) {
  ThinPlateSpline tps;
  EXPECT_FALSE(tps.fit({{0, 0}, {1, 0}}, {0, 0}));
  EXPECT_FALSE(tps.fit({{0, 0}, {1, 1}, {2, 2}, {3, 3}}, {0, 1, 2, 3}));
  const std::vector<Eigen::Vector2d> sites = {{0, 0}, {10, 0}, {0, 10}, {10, 10}, {5, 5}, {5.2, 5}};
  ASSERT_TRUE(tps.fit(sites, {0, 0, 0, 0, 1.0, -3.0}, {}, 0.5));
  EXPECT_NEAR(tps(Eigen::Vector2d(5, 5)), 1.0, 1e-8) << "the earlier of two close sites wins";
}

}  // namespace
}  // namespace cranioplan
