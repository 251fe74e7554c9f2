// Tests of core/brdf_coords.h: the local frame, spherical angles, the isotropic form and
// Rusinkiewicz's half/difference angles, including their degenerate and grazing cases.
#include "core/brdf_coords.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

namespace ibrdf {
namespace {

// A uniformly distributed unit vector; `upper` restricts it to z > 0.
Eigen::Vector3d RandomDirection(std::mt19937& rng, bool upper) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Vector3d v(normal(rng), normal(rng), normal(rng));
  v.normalize();
  if (upper && v.z() < 0) v.z() = -v.z();
  return v;
}

bool AllFinite(const HalfDiffAngles& a) {
  return std::isfinite(a.theta_h) && std::isfinite(a.phi_h) && std::isfinite(a.theta_d) && std::isfinite(a.phi_d);
}

bool AllFinite(const IsotropicAngles& a) {
  return std::isfinite(a.theta_i) && std::isfinite(a.theta_e) && std::isfinite(a.delta_phi);
}

// The frame (s, t, n) is orthonormal and right-handed (s x t = n), and keeps n exactly.
void ExpectOrthonormalRightHanded(const Eigen::Vector3d& n) {
  const LocalFrame frame = LocalFrame::FromNormal(n);
  EXPECT_EQ(frame.n, n);
  EXPECT_NEAR(frame.s.norm(), 1.0, 1e-14) << n.transpose();
  EXPECT_NEAR(frame.t.norm(), 1.0, 1e-14) << n.transpose();
  EXPECT_NEAR(frame.s.dot(frame.t), 0.0, 1e-14) << n.transpose();
  EXPECT_NEAR(frame.s.dot(frame.n), 0.0, 1e-14) << n.transpose();
  EXPECT_NEAR(frame.t.dot(frame.n), 0.0, 1e-14) << n.transpose();
  EXPECT_LT((frame.s.cross(frame.t) - frame.n).norm(), 1e-14) << n.transpose();
  EXPECT_TRUE(frame.s.allFinite() && frame.t.allFinite()) << n.transpose();
}

TEST(LocalFrame, OrthonormalRightHandedForSpecialNormals) {
  const std::vector<Eigen::Vector3d> normals = {
      {0, 0, 1},
      {0, 0, -1},
      {1, 0, 0},
      {0, 1, 0},
      {-1, 0, 0},
      {0, -1, 0},
      {1, 0, -0.0},  // z = -0: the sign switch must still give a valid frame
      Eigen::Vector3d(1e-9, 0, -1).normalized(),
      Eigen::Vector3d(0, 1e-9, -1).normalized(),
      Eigen::Vector3d(1e-9, 1e-9, 1).normalized(),
      Eigen::Vector3d(-1e-12, 3e-12, -1).normalized(),
      Eigen::Vector3d(1, 1, 1e-15).normalized(),
      Eigen::Vector3d(1, -1, -1e-15).normalized(),
  };
  for (const Eigen::Vector3d& n : normals) ExpectOrthonormalRightHanded(n);
}

TEST(LocalFrame, OrthonormalRightHandedForRandomNormals) {
  std::mt19937 rng(11);
  for (int i = 0; i < 2000; ++i) ExpectOrthonormalRightHanded(RandomDirection(rng, false));
}

// With n = +z the frame is the identity, so local and world coordinates agree.
TEST(LocalFrame, UpNormalGivesIdentityFrame) {
  const LocalFrame frame = LocalFrame::FromNormal(Eigen::Vector3d::UnitZ());
  EXPECT_LT((frame.s - Eigen::Vector3d::UnitX()).norm(), 1e-15);
  EXPECT_LT((frame.t - Eigen::Vector3d::UnitY()).norm(), 1e-15);
}

// ToLocal and FromLocal invert each other; the normal maps to +z.
TEST(LocalFrame, ToLocalFromLocalRoundTrip) {
  std::mt19937 rng(12);
  for (int i = 0; i < 500; ++i) {
    const LocalFrame frame = LocalFrame::FromNormal(RandomDirection(rng, false));
    const Eigen::Vector3d v = RandomDirection(rng, false) * 2.5;
    EXPECT_LT((frame.FromLocal(frame.ToLocal(v)) - v).norm(), 1e-13);
    EXPECT_LT((frame.ToLocal(frame.n) - Eigen::Vector3d::UnitZ()).norm(), 1e-14);
    EXPECT_NEAR(frame.ToLocal(v).norm(), v.norm(), 1e-13);
  }
}

// PolarAngle near the pole: a vector 1e-8 rad off +z gives 1e-8 to full relative precision (acos of
// its z component, which rounds to 1, would give 0).
TEST(SphericalAngles, PolarAngleAccurateNearPole) {
  for (double theta : {1e-8, 3e-10, 1e-15}) {
    const Eigen::Vector3d w = FromSpherical(theta, 0.7);
    EXPECT_NEAR(PolarAngle(w), theta, 1e-14 * theta) << theta;
  }
  const Eigen::Vector3d w = Eigen::Vector3d(1e-8, 0, 1).normalized();
  EXPECT_NEAR(PolarAngle(w), std::atan(1e-8), 1e-22);
  EXPECT_EQ(PolarAngle(Eigen::Vector3d(0, 0, 1)), 0.0);
  EXPECT_DOUBLE_EQ(PolarAngle(Eigen::Vector3d(0, 0, -1)), M_PI);
}

// At grazing (theta = pi/2 - 1e-9) the polar angle is accurate to rounding.
TEST(SphericalAngles, PolarAngleAccurateAtGrazing) {
  const double theta = M_PI / 2 - 1e-9;
  EXPECT_NEAR(PolarAngle(FromSpherical(theta, 1.1)), theta, 1e-15);
  EXPECT_NEAR(PolarAngle(Eigen::Vector3d(1, 0, 1e-9)), M_PI / 2 - 1e-9, 1e-15);
  // PolarAngle does not need a unit vector.
  EXPECT_NEAR(PolarAngle(Eigen::Vector3d(3, 0, 3)), M_PI / 4, 1e-15);
}

// Azimuth is in (-pi, pi]: the negative x axis is +pi even from -0 in y; the pole is 0.
TEST(SphericalAngles, AzimuthRange) {
  EXPECT_EQ(Azimuth(Eigen::Vector3d(0, 0, 1)), 0.0);
  EXPECT_EQ(Azimuth(Eigen::Vector3d(0, 0, -1)), 0.0);
  EXPECT_DOUBLE_EQ(Azimuth(Eigen::Vector3d(-1, 0, 0)), M_PI);
  EXPECT_DOUBLE_EQ(Azimuth(Eigen::Vector3d(-1, -0.0, 0)), M_PI);
  EXPECT_DOUBLE_EQ(Azimuth(Eigen::Vector3d(0, 1, 0)), M_PI / 2);
  EXPECT_DOUBLE_EQ(Azimuth(Eigen::Vector3d(0, -1, 0)), -M_PI / 2);
}

// FromSpherical and the angle functions invert each other away from the pole.
TEST(SphericalAngles, FromSphericalRoundTrip) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> theta(1e-6, M_PI - 1e-6), phi(-M_PI + 1e-9, M_PI);
  for (int i = 0; i < 1000; ++i) {
    const double t = theta(rng), p = phi(rng);
    const Eigen::Vector3d w = FromSpherical(t, p);
    EXPECT_NEAR(w.norm(), 1.0, 1e-15);
    EXPECT_NEAR(PolarAngle(w), t, 1e-13);
    EXPECT_NEAR(Azimuth(w), p, 1e-9);
  }
}

// WrapAngle lands in (-pi, pi]: +pi stays, -pi and odd multiples of pi become +pi.
TEST(WrapAngle, EdgeValues) {
  EXPECT_EQ(WrapAngle(M_PI), M_PI);
  EXPECT_EQ(WrapAngle(-M_PI), M_PI);
  EXPECT_EQ(WrapAngle(3 * M_PI), M_PI);
  EXPECT_EQ(WrapAngle(-3 * M_PI), M_PI);
  EXPECT_EQ(WrapAngle(0.0), 0.0);
  EXPECT_NEAR(WrapAngle(2 * M_PI), 0.0, 1e-15);
  EXPECT_NEAR(WrapAngle(-2 * M_PI), 0.0, 1e-15);
  EXPECT_NEAR(WrapAngle(M_PI + 0.5), -M_PI + 0.5, 1e-15);
  EXPECT_NEAR(WrapAngle(-M_PI - 0.5), M_PI - 0.5, 1e-15);
  EXPECT_NEAR(WrapAngle(7.0), 7.0 - 2 * M_PI, 1e-15);
  EXPECT_NEAR(WrapAngle(-100.0), -100.0 + 32 * M_PI, 1e-13);
  EXPECT_EQ(WrapAngle(0.3), 0.3);
  EXPECT_EQ(WrapAngle(-0.3), -0.3);
}

// Every wrapped value is in (-pi, pi] and differs from the input by a multiple of 2 pi.
TEST(WrapAngle, RangeAndPeriod) {
  std::mt19937 rng(14);
  std::uniform_real_distribution<double> angle(-50.0, 50.0);
  for (int i = 0; i < 10000; ++i) {
    const double a = angle(rng);
    const double w = WrapAngle(a);
    EXPECT_GT(w, -M_PI);
    EXPECT_LE(w, M_PI);
    const double turns = (a - w) / (2 * M_PI);
    EXPECT_NEAR(turns, std::round(turns), 1e-12);
  }
}

TEST(BrdfAngles, RoundTrip) {
  std::mt19937 rng(15);
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector3d wi = RandomDirection(rng, true), wo = RandomDirection(rng, true);
    Eigen::Vector3d wi2, wo2;
    FromBrdfAngles(ToBrdfAngles(wi, wo), &wi2, &wo2);
    EXPECT_LT((wi2 - wi).norm(), 1e-14);
    EXPECT_LT((wo2 - wo).norm(), 1e-14);
  }
}

// delta_phi = phi_e - phi_i with its sign: wi at phi 0 and wo at phi +0.3 give +0.3; swapping the
// directions gives -0.3; the difference wraps into (-pi, pi].
TEST(Isotropic, DeltaPhiSign) {
  const IsotropicAngles a = ToIsotropic(FromSpherical(0.5, 0.0), FromSpherical(0.7, 0.3));
  EXPECT_NEAR(a.theta_i, 0.5, 1e-15);
  EXPECT_NEAR(a.theta_e, 0.7, 1e-15);
  EXPECT_NEAR(a.delta_phi, 0.3, 1e-15);
  EXPECT_NEAR(ToIsotropic(FromSpherical(0.7, 0.3), FromSpherical(0.5, 0.0)).delta_phi, -0.3, 1e-15);
  EXPECT_NEAR(ToIsotropic(FromSpherical(0.5, 1.0), FromSpherical(0.7, 1.3)).delta_phi, 0.3, 1e-15);
  EXPECT_NEAR(ToIsotropic(FromSpherical(0.5, 3.0), FromSpherical(0.7, -3.0)).delta_phi, 2 * M_PI - 6.0, 1e-14);
  // Opposite azimuths (the plane of incidence, back-scattering side) give +pi, never -pi.
  EXPECT_DOUBLE_EQ(
      ToIsotropic(Eigen::Vector3d(1, 0, 1).normalized(), Eigen::Vector3d(-1, -0.0, 1).normalized()).delta_phi, M_PI);
}

// The isotropic form depends on the pair only through its invariants: rotating both directions about
// the normal leaves it unchanged, and FromIsotropic's canonical pair has the same invariants.
TEST(Isotropic, RoundTripAndRotationInvariance) {
  std::mt19937 rng(16);
  std::uniform_real_distribution<double> rotation(-M_PI, M_PI);
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector3d wi = RandomDirection(rng, true), wo = RandomDirection(rng, true);
    const IsotropicAngles a = ToIsotropic(wi, wo);
    EXPECT_GT(a.delta_phi, -M_PI);
    EXPECT_LE(a.delta_phi, M_PI);
    Eigen::Vector3d wi2, wo2;
    FromIsotropic(a, &wi2, &wo2);
    EXPECT_NEAR(wi2.y(), 0.0, 1e-15);
    EXPECT_GE(wi2.x(), 0.0);
    EXPECT_NEAR(wi2.z(), wi.z(), 1e-14);
    EXPECT_NEAR(wo2.z(), wo.z(), 1e-14);
    EXPECT_NEAR(wi2.dot(wo2), wi.dot(wo), 1e-14);
    // Same orientation: the sign of the triple product (wi x wo) . n is kept.
    EXPECT_NEAR(wi2.cross(wo2).z(), wi.cross(wo).z(), 1e-14);
    const IsotropicAngles b = ToIsotropic(wi2, wo2);
    EXPECT_NEAR(b.theta_i, a.theta_i, 1e-14);
    EXPECT_NEAR(b.theta_e, a.theta_e, 1e-14);
    EXPECT_NEAR(std::remainder(b.delta_phi - a.delta_phi, 2 * M_PI), 0.0, 1e-12);
    const Eigen::Matrix3d spin = Eigen::AngleAxisd(rotation(rng), Eigen::Vector3d::UnitZ()).matrix();
    const IsotropicAngles c = ToIsotropic(spin * wi, spin * wo);
    EXPECT_NEAR(c.theta_i, a.theta_i, 1e-14);
    EXPECT_NEAR(c.theta_e, a.theta_e, 1e-14);
    EXPECT_NEAR(std::remainder(c.delta_phi - a.delta_phi, 2 * M_PI), 0.0, 1e-12);
  }
}

// theta_i = 0 (wi along the normal): the angles are finite and FromIsotropic reproduces wo exactly.
TEST(Isotropic, IncidenceAlongNormal) {
  const Eigen::Vector3d normal(0, 0, 1);
  const Eigen::Vector3d wo = FromSpherical(0.4, 0.7);
  const IsotropicAngles a = ToIsotropic(normal, wo);
  ASSERT_TRUE(AllFinite(a));
  EXPECT_EQ(a.theta_i, 0.0);
  EXPECT_NEAR(a.theta_e, 0.4, 1e-15);
  Eigen::Vector3d wi2, wo2;
  FromIsotropic(a, &wi2, &wo2);
  EXPECT_LT((wi2 - normal).norm(), 1e-15);
  EXPECT_LT((wo2 - wo).norm(), 1e-14);
}

// theta_e = 0 (wo along the normal), and both along the normal: finite and consistent.
TEST(Isotropic, ExitanceAlongNormal) {
  const Eigen::Vector3d normal(0, 0, 1);
  const Eigen::Vector3d wi = FromSpherical(0.6, -2.0);
  const IsotropicAngles a = ToIsotropic(wi, normal);
  ASSERT_TRUE(AllFinite(a));
  EXPECT_NEAR(a.theta_i, 0.6, 1e-15);
  EXPECT_EQ(a.theta_e, 0.0);
  Eigen::Vector3d wi2, wo2;
  FromIsotropic(a, &wi2, &wo2);
  EXPECT_LT((wo2 - normal).norm(), 1e-15);
  EXPECT_NEAR(wi2.dot(wo2), wi.dot(normal), 1e-15);

  const IsotropicAngles both = ToIsotropic(normal, normal);
  ASSERT_TRUE(AllFinite(both));
  EXPECT_EQ(both.theta_i, 0.0);
  EXPECT_EQ(both.theta_e, 0.0);
}

// Grazing directions (theta = pi/2 - 1e-9) keep their polar angles to rounding.
TEST(Isotropic, GrazingIsAccurate) {
  const double grazing = M_PI / 2 - 1e-9;
  const IsotropicAngles a = ToIsotropic(FromSpherical(grazing, 0.2), FromSpherical(grazing, 1.4));
  EXPECT_NEAR(a.theta_i, grazing, 1e-15);
  EXPECT_NEAR(a.theta_e, grazing, 1e-15);
  EXPECT_NEAR(a.delta_phi, 1.2, 1e-14);
}

// FromHalfDiff inverts ToHalfDiff to 1e-12 over random pairs, in the upper hemisphere and over the
// whole sphere.
TEST(HalfDiff, RoundTripRandomDirections) {
  std::mt19937 rng(17);
  for (bool upper : {true, false}) {
    for (int i = 0; i < 20000; ++i) {
      const Eigen::Vector3d wi = RandomDirection(rng, upper), wo = RandomDirection(rng, upper);
      if ((wi + wo).norm() < 1e-3) continue;
      HalfDiffAngles a;
      ASSERT_TRUE(ToHalfDiff(wi, wo, &a));
      ASSERT_TRUE(AllFinite(a));
      Eigen::Vector3d wi2, wo2;
      FromHalfDiff(a, &wi2, &wo2);
      EXPECT_LT((wi2 - wi).norm(), 1e-12) << wi.transpose() << " / " << wo.transpose();
      EXPECT_LT((wo2 - wo).norm(), 1e-12) << wi.transpose() << " / " << wo.transpose();
    }
  }
}

// The meaning of the angles: theta_h is the angle between h and the normal, theta_d the angle
// between wi and h (so wo makes the same angle with h); angles are in MERL's ranges.
TEST(HalfDiff, AnglesHaveTheirGeometricMeaning) {
  std::mt19937 rng(18);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d wi = RandomDirection(rng, true), wo = RandomDirection(rng, true);
    HalfDiffAngles a;
    ASSERT_TRUE(ToHalfDiff(wi, wo, &a));
    const Eigen::Vector3d h = (wi + wo).normalized();
    EXPECT_NEAR(std::cos(a.theta_h), h.z(), 1e-14);
    EXPECT_NEAR(std::cos(a.theta_d), wi.dot(h), 1e-14);
    EXPECT_NEAR(std::cos(a.theta_d), wo.dot(h), 1e-14);
    EXPECT_GE(a.theta_h, 0.0);
    EXPECT_LE(a.theta_h, M_PI / 2);
    EXPECT_GE(a.theta_d, 0.0);
    EXPECT_LE(a.theta_d, M_PI / 2);
    EXPECT_NEAR(std::remainder(a.phi_h - Azimuth(h), 2 * M_PI), 0.0, 1e-12);
  }
}

// The mirror configuration has h on the normal: theta_h = 0 and the difference vector is wi itself,
// up to the rotation by phi_h (arbitrary where h is the pole to rounding, and harmless there).
TEST(HalfDiff, MirrorConfiguration) {
  const Eigen::Vector3d wi = FromSpherical(0.8, 0.5), wo = FromSpherical(0.8, 0.5 + M_PI);
  HalfDiffAngles a;
  ASSERT_TRUE(ToHalfDiff(wi, wo, &a));
  ASSERT_TRUE(AllFinite(a));
  EXPECT_NEAR(a.theta_h, 0.0, 1e-15);
  EXPECT_NEAR(a.theta_d, 0.8, 1e-14);
  EXPECT_NEAR(std::remainder(a.phi_h + a.phi_d - 0.5, 2 * M_PI), 0.0, 1e-14);
  Eigen::Vector3d wi2, wo2;
  FromHalfDiff(a, &wi2, &wo2);
  EXPECT_LT((wi2 - wi).norm(), 1e-14);
  EXPECT_LT((wo2 - wo).norm(), 1e-14);
}

// theta = 0 cases: wi along the normal, and both along the normal, give finite angles that round-trip.
TEST(HalfDiff, DirectionsAlongNormal) {
  const Eigen::Vector3d normal(0, 0, 1);
  HalfDiffAngles a;
  ASSERT_TRUE(ToHalfDiff(normal, normal, &a));
  ASSERT_TRUE(AllFinite(a));
  EXPECT_EQ(a.theta_h, 0.0);
  EXPECT_NEAR(a.theta_d, 0.0, 1e-15);
  Eigen::Vector3d wi2, wo2;
  FromHalfDiff(a, &wi2, &wo2);
  EXPECT_LT((wi2 - normal).norm(), 1e-15);
  EXPECT_LT((wo2 - normal).norm(), 1e-15);

  const Eigen::Vector3d wo = FromSpherical(0.9, -1.3);
  ASSERT_TRUE(ToHalfDiff(normal, wo, &a));
  ASSERT_TRUE(AllFinite(a));
  EXPECT_NEAR(a.theta_h, 0.45, 1e-14);
  EXPECT_NEAR(a.theta_d, 0.45, 1e-14);
  FromHalfDiff(a, &wi2, &wo2);
  EXPECT_LT((wi2 - normal).norm(), 1e-14);
  EXPECT_LT((wo2 - wo).norm(), 1e-14);
}

// wi == wo (retro-reflection): h = wi, so theta_d is zero to rounding, not sqrt(rounding).
TEST(HalfDiff, RetroReflectionHasZeroDifferenceAngle) {
  std::mt19937 rng(19);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d w = RandomDirection(rng, true);
    HalfDiffAngles a;
    ASSERT_TRUE(ToHalfDiff(w, w, &a));
    EXPECT_LT(a.theta_d, 1e-14);
    EXPECT_NEAR(a.theta_h, PolarAngle(w), 1e-14);
  }
}

// Grazing pairs (theta = pi/2 - 1e-9) round-trip to 1e-12.
TEST(HalfDiff, GrazingRoundTrip) {
  const double grazing = M_PI / 2 - 1e-9;
  for (double phi_o : {0.0, 0.5, 2.0, 3.0}) {
    const Eigen::Vector3d wi = FromSpherical(grazing, 0.1), wo = FromSpherical(grazing, 0.1 + phi_o);
    HalfDiffAngles a;
    ASSERT_TRUE(ToHalfDiff(wi, wo, &a));
    ASSERT_TRUE(AllFinite(a));
    Eigen::Vector3d wi2, wo2;
    FromHalfDiff(a, &wi2, &wo2);
    EXPECT_LT((wi2 - wi).norm(), 1e-12) << phi_o;
    EXPECT_LT((wo2 - wo).norm(), 1e-12) << phi_o;
    EXPECT_NEAR(PolarAngle(wi2), grazing, 1e-12) << phi_o;
  }
}

// wi = -wo leaves h undefined: false, zero angles, no NaN.
TEST(HalfDiff, OppositeDirectionsAreRejected) {
  for (const Eigen::Vector3d& wi : {FromSpherical(M_PI / 2, 0.3), Eigen::Vector3d(0, 0, 1), FromSpherical(0.7, -1.0)}) {
    HalfDiffAngles a;
    a.theta_h = a.phi_h = a.theta_d = a.phi_d = 123.0;
    EXPECT_FALSE(ToHalfDiff(wi, -wi, &a)) << wi.transpose();
    EXPECT_TRUE(AllFinite(a));
    EXPECT_EQ(a.theta_h, 0.0);
    EXPECT_EQ(a.phi_h, 0.0);
    EXPECT_EQ(a.theta_d, 0.0);
    EXPECT_EQ(a.phi_d, 0.0);
  }
}

}  // namespace
}  // namespace ibrdf
