// ArmPlane (workspace <-> robot frame, box) and ArmMotion (speed and acceleration limits), the
// pure parts of ros2_cartesian, against closed forms.
#include "arm_plane.hpp"

#include <gtest/gtest.h>

namespace dyad::cartesian {
namespace {

ArmPlaneOptions Skewed() {
  ArmPlaneOptions o;
  o.origin = {0.4, 0.0, 0.3};
  o.x_axis = {0.0, -2.0, 0.0};  // not unit: normalised
  o.y_axis = {0.0, 1.0, 1.0};   // 45 degrees to x_axis: not orthogonal
  o.scale = 0.002;
  return o;
}

TEST(ArmPlaneTest, MapsTheWorkspaceOntoThePlaneAndBack) {
  const ArmPlane plane(Skewed());
  const Vec3 p = plane.ToRobot(10, 20);
  // origin + 0.002 * (10 * (0,-1,0) + 20 * (0, 1/sqrt2, 1/sqrt2))
  EXPECT_NEAR(p[0], 0.4, 1e-12);
  EXPECT_NEAR(p[1], 0.002 * (-10 + 20 / std::sqrt(2.0)), 1e-12);
  EXPECT_NEAR(p[2], 0.3 + 0.002 * 20 / std::sqrt(2.0), 1e-12);
  const ArmPlane::Workspace w = plane.ToWorkspace(p);
  EXPECT_NEAR(w.x, 10, 1e-9);
  EXPECT_NEAR(w.y, 20, 1e-9);
  EXPECT_NEAR(w.off_plane, 0, 1e-9);
  // 1 cm along the plane's normal (u x v = (-1,0,0) here): the same point, 5 units off the plane.
  const ArmPlane::Workspace off = plane.ToWorkspace(p + Vec3{-0.01, 0, 0});
  EXPECT_NEAR(off.x, 10, 1e-9);
  EXPECT_NEAR(off.y, 20, 1e-9);
  EXPECT_NEAR(off.off_plane, 5, 1e-9);
}

TEST(ArmPlaneTest, ClampsIntoTheBox) {
  const ArmPlane plane(Skewed());
  bool clamped = false;
  const Vec3 q = plane.Clamp({0.9, -0.5, 0.3}, &clamped);
  EXPECT_TRUE(clamped);
  EXPECT_EQ(q, (Vec3{0.6, -0.3, 0.3}));
  EXPECT_TRUE(plane.Inside(q));
  plane.Clamp({0.4, 0, 0.3}, &clamped);
  EXPECT_FALSE(clamped);
  EXPECT_FALSE(plane.Inside({0.4, 0, 0.55}));
}

TEST(ArmPlaneTest, RefusesBadPlanesNamingTheField) {
  auto message = [](ArmPlaneOptions o) { return o.Validate().message(); };
  ArmPlaneOptions o = Skewed();
  o.y_axis = {0, -1, 0.01};
  EXPECT_NE(message(o).find("parallel"), std::string::npos) << message(o);
  o = Skewed();
  o.origin[1] = std::nan("");
  EXPECT_NE(message(o).find("origin"), std::string::npos);
  o = Skewed();
  o.x_axis = {0, 0, 0};
  EXPECT_NE(message(o).find("x_axis: must not be zero"), std::string::npos);
  o = Skewed();
  o.box_max[2] = 0.05;
  EXPECT_NE(message(o).find("box_min"), std::string::npos);
  o = Skewed();
  o.origin = {1.0, 0, 0.3};
  EXPECT_NE(message(o).find("outside the box"), std::string::npos);
  o = Skewed();
  o.scale = 0;
  EXPECT_NE(message(o).find("scale"), std::string::npos);
  EXPECT_TRUE(Skewed().Validate().ok());
}

TEST(ArmMotionTest, ReachesTheGoalWithinItsLimitsWithoutOvershoot) {
  const double vmax = 0.25, amax = 2.0, dt = 0.01;
  ArmMotion motion(vmax, amax);
  Vec3 p{0, 0, 0}, v_prev{0, 0, 0};
  const Vec3 goal{0.3, 0.1, 0};
  double closest = 1e9;
  int steps = 0;
  for (; steps < 1000 && Norm(goal - p) > 1e-9; ++steps) {
    const Vec3 v = motion.Toward(p, goal, dt);
    EXPECT_LE(Norm(v), vmax + 1e-12);
    EXPECT_LE(Norm(v - v_prev), amax * dt + 1e-12);
    p = p + dt * v;
    v_prev = v;
    // Never past the goal: the distance only shrinks.
    EXPECT_LE(Norm(goal - p), closest + 1e-12);
    closest = std::min(closest, Norm(goal - p));
  }
  EXPECT_LT(Norm(goal - p), 1e-6);
  // |d| = 0.316 m at 0.25 m/s after 0.125 s of acceleration and as much braking: ~1.39 s.
  EXPECT_NEAR(steps * dt, 0.3162 / 0.25 + 0.125, 0.06);
}

TEST(ArmMotionTest, BrakesAtItsAcceleration) {
  ArmMotion motion(0.25, 2.0);
  for (int i = 0; i < 50; ++i) motion.Toward({0, 0, 0}, {1, 0, 0}, 0.01);
  EXPECT_NEAR(motion.velocity()[0], 0.25, 1e-12);
  EXPECT_NEAR(motion.Brake(0.01)[0], 0.23, 1e-12);
  for (int i = 0; i < 20; ++i) motion.Brake(0.01);
  EXPECT_EQ(motion.velocity()[0], 0);
}

}  // namespace
}  // namespace dyad::cartesian
