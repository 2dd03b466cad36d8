#include "core/registration/rigid_dofs.h"

#include <gtest/gtest.h>

#include <random>

namespace surfinspect {
namespace {

RigidParams RandomParams(std::mt19937& rng, double mm, double rad) {
  std::uniform_real_distribution<double> u(-1, 1);
  RigidParams x;
  x << mm * u(rng), mm * u(rng), mm * u(rng), rad * u(rng), rad * u(rng), rad * u(rng);
  return x;
}

// Rows [n, p × n] of points on the plane z = 0 with normal +z, scaled about
// the origin by 100 mm: they hold z, rotation about x and about y only.
DofMatrix PlaneNormal() {
  DofMatrix h = DofMatrix::Zero();
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(100, 0, 0),
                                   Eigen::Vector3d(0, 80, 0), Eigen::Vector3d(-50, -60, 0)}) {
    const RigidParams row =
        ScaledAnalysisRow(p, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::Zero(), 100);
    h += row * row.transpose();
  }
  return h;
}

TEST(RigidDofs, NamesTheDegreesOfFreedom) {
  EXPECT_STREQ(DofName(kTx), "translation along x");
  EXPECT_STREQ(DofName(kTz), "translation along z");
  EXPECT_STREQ(DofName(kRy), "rotation about y");
  EXPECT_STREQ(DofName(kRz), "rotation about z");
  EXPECT_STREQ(DofName(6), "unknown");
  LockedDofs locked;
  locked.ty = locked.rz = true;
  EXPECT_TRUE(locked.IsLocked(kTy));
  EXPECT_TRUE(locked.IsLocked(kRz));
  EXPECT_FALSE(locked.IsLocked(kTx));
  EXPECT_FALSE(locked.IsLocked(-1));
  EXPECT_EQ(locked.FreeCount(), 4);
}

TEST(RigidDofs, TransformIsTranslationTimesRzRyRx) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 50; ++trial) {
    const RigidParams x = RandomParams(rng, 10, 1.0);
    const Eigen::Matrix3d expected = (Eigen::AngleAxisd(x[kRz], Eigen::Vector3d::UnitZ()) *
                                      Eigen::AngleAxisd(x[kRy], Eigen::Vector3d::UnitY()) *
                                      Eigen::AngleAxisd(x[kRx], Eigen::Vector3d::UnitX()))
                                         .toRotationMatrix();
    const Eigen::Isometry3d t = RigidMotion(x).transform();
    EXPECT_LT((t.linear() - expected).norm(), 1e-15);
    EXPECT_EQ(t.translation(), Eigen::Vector3d(x.head<3>()));
    // The inverse map reads the same x back.
    EXPECT_LT((ParamsFromTransform(t) - x).cwiseAbs().maxCoeff(), 1e-14);
  }
}

TEST(RigidDofs, ZeroComponentsLeaveTheirFactorsExactlyTheIdentity) {
  RigidParams x;
  x << 0.3, 0, -0.2, 0, 0.004, 0;  // ty, rx and rz zero
  const Eigen::Isometry3d t = RigidMotion(x).transform();
  const RigidParams back = ParamsFromTransform(t);
  EXPECT_EQ(back[kTy], 0.0);
  EXPECT_EQ(back[kRx], 0.0);
  EXPECT_EQ(back[kRz], 0.0);
  EXPECT_EQ(t.linear()(1, 0), 0.0);  // Ry alone: no coupling into y
  EXPECT_EQ(t.linear()(1, 1), 1.0);
  EXPECT_TRUE(RigidMotion(RigidParams::Zero()).transform().matrix() == Eigen::Matrix4d::Identity());
}

TEST(RigidDofs, JacobianMatchesCentralDifferences) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-300, 300);
  for (int trial = 0; trial < 50; ++trial) {
    const RigidParams x = RandomParams(rng, 5, 0.8);
    const Eigen::Vector3d p(u(rng), u(rng), u(rng));
    const Eigen::Matrix<double, 3, kRigidDofs> j = RigidMotion(x).Jacobian(p);
    for (int k = 0; k < kRigidDofs; ++k) {
      const double h = 1e-6;
      RigidParams a = x, b = x;
      a[k] += h;
      b[k] -= h;
      const Eigen::Vector3d fd =
          (RigidMotion(a).transform() * p - RigidMotion(b).transform() * p) / (2 * h);
      // Central differences err by h²/6·|T'''p| ~ 1e-12·300 mm plus rounding
      // 1e-16·300/1e-6 ~ 3e-8.
      EXPECT_LT((fd - j.col(k)).norm(), 1e-7) << "dof " << k;
    }
  }
}

TEST(RigidDofs, AnalysisNamesAxisAlignedFreeMotions) {
  const DofAnalysis a = AnalyseDofs(PlaneNormal());
  ASSERT_EQ(a.free.size(), 3u);
  EXPECT_EQ(a.free[0], "translation along x");
  EXPECT_EQ(a.free[1], "translation along y");
  EXPECT_EQ(a.free[2], "rotation about z");
  EXPECT_TRUE(std::isinf(a.condition));
  EXPECT_EQ(JoinFree(a.free), "translation along x, translation along y, rotation about z");
}

TEST(RigidDofs, LockingTheFreeMotionsLeavesNoneFree) {
  LockedDofs locked;
  locked.tx = locked.ty = locked.rz = true;
  const DofAnalysis a = AnalyseDofs(PlaneNormal(), locked);
  EXPECT_TRUE(a.free.empty());
  EXPECT_TRUE(std::isfinite(a.condition));
  EXPECT_GE(a.condition, 1.0);
  // Everything locked: nothing to analyse.
  const LockedDofs all{true, true, true, true, true, true};
  EXPECT_TRUE(AnalyseDofs(PlaneNormal(), all).free.empty());
  EXPECT_TRUE(std::isnan(AnalyseDofs(PlaneNormal(), all).condition));
}

TEST(RigidDofs, AnalysisNamesACoupledMotionByItsLargestComponentFirst) {
  // Null space spanned by 0.6·ty + 0.8·rz.
  RigidParams v;
  v << 0, 0.6, 0, 0, 0, 0.8;
  const DofMatrix h = DofMatrix::Identity() - v * v.transpose();
  const DofAnalysis a = AnalyseDofs(h);
  ASSERT_EQ(a.free.size(), 1u);
  EXPECT_EQ(a.free[0], "rotation about z with translation along y");
  // The zero matrix leaves everything free.
  EXPECT_EQ(AnalyseDofs(DofMatrix::Zero()).free.size(), 6u);
}

TEST(RigidDofs, FullRankMatrixLeavesNothingFreeAndReportsItsCondition) {
  DofMatrix h = DofMatrix::Identity();
  h(kRz, kRz) = 1e-6;  // weak but not free
  const DofAnalysis a = AnalyseDofs(h);
  EXPECT_TRUE(a.free.empty());
  EXPECT_NEAR(a.condition, 1e6, 1e-3);
  h(kRz, kRz) = 1e-10;  // below 1e-9 of the largest: free
  EXPECT_EQ(AnalyseDofs(h).free, std::vector<std::string>{"rotation about z"});
}

}  // namespace
}  // namespace surfinspect
