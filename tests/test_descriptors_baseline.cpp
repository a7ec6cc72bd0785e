// The hand-made baseline descriptors: eigenvalue features against hand-computed textbook values,
// FPFH against shapes it must tell apart, and the properties any segment descriptor needs
// (invariance to point order and rigid motion, finite output, batch = one at a time); and the
// factory, which says in one line which option a kind missing from this build needs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include <Eigen/Geometry>

#include "semsegmap/describe/descriptor.h"
#include "semsegmap/describe/eigen_descriptor.h"
#if SEMSEGMAP_WITH_PCL
#include "semsegmap/describe/fpfh_descriptor.h"
#endif
#include "semsegmap/artefacts/model_file.h"

using namespace semsegmap;
namespace ef = semsegmap::eigen_feature;

namespace {

using Features7 = Eigen::Matrix<float, 7, 1>;
using Features33 = Eigen::Matrix<float, 33, 1>;

EnrichedPoint point(const Eigen::Vector3d& p) {
  EnrichedPoint q;
  q.x = static_cast<float>(p.x());
  q.y = static_cast<float>(p.y());
  q.z = static_cast<float>(p.z());
  q.h = 0.2f;
  q.s = q.v = 0.5f;
  q.has_color = true;
  q.has_class = true;
  q.class_id = cls::kBuilding;
  return q;
}

Eigen::Vector3d noise(std::mt19937& rng, double sigma) {
  std::normal_distribution<double> n(0.0, sigma);
  return {n(rng), n(rng), n(rng)};
}

// A rotation about a skew axis and a translation far from the map origin.
Eigen::Isometry3d someRigidMotion() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).matrix();
  T.translation() = Eigen::Vector3d(412.5, -87.25, 12.0);
  return T;
}

EnrichedCloud transformed(const EnrichedCloud& cloud, const Eigen::Isometry3d& T) {
  EnrichedCloud out = cloud;
  for (EnrichedPoint& p : out) {
    const Eigen::Vector3d q = T * Eigen::Vector3d(p.x, p.y, p.z);
    p.x = static_cast<float>(q.x());
    p.y = static_cast<float>(q.y());
    p.z = static_cast<float>(q.z());
  }
  return out;
}

EnrichedCloud shuffled(EnrichedCloud cloud, unsigned seed) {
  std::mt19937 rng(seed);
  std::shuffle(cloud.begin(), cloud.end(), rng);
  return cloud;
}

// Random shapes with sensor-like noise, as segments are after voxelisation.
EnrichedCloud planePatch(int n, double side_m, double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-side_m / 2, side_m / 2);
  EnrichedCloud out;
  for (int i = 0; i < n; ++i)
    out.push_back(point(Eigen::Vector3d(u(rng), u(rng), 0.0) + noise(rng, sigma)));
  return out;
}

EnrichedCloud sphereShell(int n, double radius_m, double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  EnrichedCloud out;
  for (int i = 0; i < n; ++i)
    out.push_back(point(radius_m * noise(rng, 1.0).normalized() + noise(rng, sigma)));
  return out;
}

EnrichedCloud solidBall(int n, double radius_m, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-radius_m, radius_m);
  EnrichedCloud out;
  while (static_cast<int>(out.size()) < n) {
    const Eigen::Vector3d p(u(rng), u(rng), u(rng));
    if (p.norm() <= radius_m) out.push_back(point(p));
  }
  return out;
}

// An axis-aligned nx x ny x nz grid with spacing h: its covariance is exactly
// diag(h^2 (n^2 - 1) / 12) per axis, the variance of a discrete uniform distribution.
EnrichedCloud boxGrid(int nx, int ny, int nz, double h) {
  EnrichedCloud out;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) out.push_back(point(h * Eigen::Vector3d(i, j, k)));
  return out;
}

double gridVariance(int n, double h) {
  return h * h * (n * n - 1) / 12.0;
}

// The textbook definitions, written out independently of the library.
Features7 textbook(double a, double b, double c) {
  double e[3] = {a, b, c};
  std::sort(e, e + 3, [](double x, double y) { return x > y; });
  const double s = e[0] + e[1] + e[2];
  const double e1 = e[0] / s, e2 = e[1] / s, e3 = e[2] / s;
  Features7 f;
  f << (e1 - e2) / e1, (e2 - e3) / e1, e3 / e1, std::pow(e1 * e2 * e3, 1.0 / 3.0), (e1 - e3) / e1,
      -(e1 * std::log(e1) + e2 * std::log(e2) + e3 * std::log(e3)), e3 / (e1 + e2 + e3);
  return f;
}

void expectNear(const Features7& got, const Features7& want, double tol) {
  for (int i = 0; i < 7; ++i) EXPECT_NEAR(got(i), want(i), tol) << "feature " << i;
}

#if SEMSEGMAP_WITH_PCL
double l1(const Features33& a, const Features33& b) {
  return (a - b).cwiseAbs().sum();
}
#endif

}  // namespace

TEST(DescriptorKind, NamesRoundTripAndUnknownNamesThrow) {
  for (const DescriptorKind k : {DescriptorKind::kEigen, DescriptorKind::kFpfh,
                                 DescriptorKind::kSegMapCnn, DescriptorKind::kSemSegMapNet})
    EXPECT_EQ(parseDescriptorKind(descriptorName(k)), k);
  EXPECT_EQ(descriptorName(DescriptorKind::kEigen), "eigen");
  EXPECT_EQ(descriptorName(DescriptorKind::kFpfh), "fpfh");
  EXPECT_EQ(descriptorName(DescriptorKind::kSegMapCnn), "segmap-cnn");
  EXPECT_EQ(descriptorName(DescriptorKind::kSemSegMapNet), "semsegmap-net");
  EXPECT_THROW(parseDescriptorKind("Eigen"), std::invalid_argument);
  EXPECT_THROW(parseDescriptorKind(""), std::invalid_argument);
  EXPECT_THROW(parseDescriptorKind("shot"), std::invalid_argument);
}

TEST(EigenFeatures, AnisotropicGridMatchesTextbookValues) {
  // Three distinct eigenvalues, so a ratio taken over the wrong eigenvalue shows.
  const EnrichedCloud box = transformed(boxGrid(24, 12, 5, 0.1), someRigidMotion());
  const Features7 want =
      textbook(gridVariance(24, 0.1), gridVariance(12, 0.1), gridVariance(5, 0.1));
  expectNear(eigenFeatures(box), want, 1e-4);
}

TEST(EigenFeatures, LineIsLinear) {
  std::mt19937 rng(1);
  const Eigen::Vector3d dir = Eigen::Vector3d(1, 2, 3).normalized();
  EnrichedCloud line;
  for (int i = 0; i < 1000; ++i)
    line.push_back(point(Eigen::Vector3d(5, 1, 2) + (i * 0.01 - 5.0) * dir + noise(rng, 1e-3)));
  const Features7 f = eigenFeatures(line);
  // Eigenvalues ~ (25/3, 1e-6, 1e-6): the limit values e = (1, 0, 0).
  Features7 want;
  want << 1, 0, 0, 0, 1, 0, 0;
  expectNear(f, want, 2e-3);
}

TEST(EigenFeatures, PlaneIsPlanar) {
  // A square grid has the same variance along both in-plane axes, tilted out of the axes.
  std::mt19937 rng(2);
  EnrichedCloud plane;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j)
      plane.push_back(point(Eigen::Vector3d(0.1 * i, 0.1 * j, 0.0) + noise(rng, 1e-3)));
  const Features7 f = eigenFeatures(transformed(plane, someRigidMotion()));
  // Eigenvalues ~ (e, e, 0): e = (1/2, 1/2, 0).
  Features7 want;
  want << 0, 1, 0, 0, 1, std::log(2.0), 0;
  expectNear(f, want, 5e-3);
  // The smallest eigenvalue is the noise, so the omnivariance is small but not zero.
  EXPECT_GT(f(ef::kOmnivariance), 0.0f);
  EXPECT_LT(f(ef::kOmnivariance), 0.05f);
}

TEST(EigenFeatures, BallIsScattered) {
  // e = (1/3, 1/3, 1/3) for a uniform ball; a random sample of 20000 points is within ~2 %.
  const Features7 f = eigenFeatures(solidBall(20000, 1.5, 3));
  Features7 want;
  want << 0, 0, 1, 1.0 / 3.0, 0, std::log(3.0), 1.0 / 3.0;
  EXPECT_NEAR(f(ef::kLinearity), want(ef::kLinearity), 0.05);
  EXPECT_NEAR(f(ef::kPlanarity), want(ef::kPlanarity), 0.05);
  EXPECT_NEAR(f(ef::kScattering), want(ef::kScattering), 0.06);
  EXPECT_NEAR(f(ef::kOmnivariance), want(ef::kOmnivariance), 0.005);
  EXPECT_NEAR(f(ef::kAnisotropy), want(ef::kAnisotropy), 0.06);
  EXPECT_NEAR(f(ef::kEigenentropy), want(ef::kEigenentropy), 0.002);
  EXPECT_NEAR(f(ef::kChangeOfCurvature), want(ef::kChangeOfCurvature), 0.02);
  // A cube grid cut to a ball is isotropic exactly (cubic symmetry); the cut is made in integers
  // so that rounding cannot break the symmetry at the boundary.
  EnrichedCloud grid_ball;
  for (int i = -10; i <= 10; ++i)
    for (int j = -10; j <= 10; ++j)
      for (int k = -10; k <= 10; ++k)
        if (i * i + j * j + k * k <= 100)
          grid_ball.push_back(point(0.1 * Eigen::Vector3d(i, j, k)));
  expectNear(eigenFeatures(grid_ball), want, 1e-4);
}

TEST(EigenFeatures, InvariantToPointOrderAndRigidMotion) {
  const EnrichedCloud cloud = planePatch(800, 3.0, 0.2, 4);  // a thick slab: all three eigenvalues
  const Features7 f = eigenFeatures(cloud);
  expectNear(eigenFeatures(shuffled(cloud, 5)), f, 1e-5);
  expectNear(eigenFeatures(transformed(cloud, someRigidMotion())), f, 1e-4);
}

TEST(EigenFeatures, DegenerateInputsAreFiniteAndDefined) {
  const Features7 zero = Features7::Zero();
  EXPECT_EQ(eigenFeatures({}), zero);
  EXPECT_EQ(eigenFeatures({point({1, 2, 3})}), zero);
  const EnrichedCloud same(300, point({1234.5, -876.25, 31.0}));
  EXPECT_EQ(eigenFeatures(same), zero);
  // Two distinct points are an exact line.
  const Features7 two = eigenFeatures({point({1, 2, 3}), point({2, 2, 3})});
  ASSERT_TRUE(two.allFinite());
  EXPECT_NEAR(two(ef::kLinearity), 1.0, 1e-6);
  EXPECT_NEAR(two(ef::kAnisotropy), 1.0, 1e-6);
  EXPECT_NEAR(two(ef::kEigenentropy), 0.0, 1e-6);
  // Collinear points: two zero eigenvalues, 0 ln 0 = 0.
  EnrichedCloud collinear;
  for (int i = 0; i < 50; ++i) collinear.push_back(point({0.1 * i, 0.0, 0.0}));
  const Features7 c = eigenFeatures(collinear);
  ASSERT_TRUE(c.allFinite());
  EXPECT_NEAR(c(ef::kLinearity), 1.0, 1e-6);
  EXPECT_NEAR(c(ef::kEigenentropy), 0.0, 1e-6);
}

TEST(EigenFeatures, NonFiniteCoordinatesThrow) {
  EnrichedCloud cloud = planePatch(10, 1.0, 0.01, 6);
  cloud[3].y = std::nanf("");
  EXPECT_THROW(eigenFeatures(cloud), std::invalid_argument);
}

TEST(EigenDescriber, BatchGivesOneRowPerInput) {
  EigenDescriber d;
  EXPECT_EQ(d.kind(), DescriptorKind::kEigen);
  EXPECT_EQ(d.dimension(), 7);
  EXPECT_EQ(d.fingerprint(), "eigen-v1");
  const std::vector<EnrichedCloud> clouds = {
      planePatch(300, 2.0, 0.01, 7), sphereShell(400, 1.0, 0.01, 8), {}, solidBall(200, 0.5, 9)};
  std::vector<DescriptorInput> batch;
  for (const EnrichedCloud& c : clouds) batch.push_back({&c});
  const Eigen::MatrixXf rows = d.describe(batch);
  ASSERT_EQ(rows.rows(), 4);
  ASSERT_EQ(rows.cols(), 7);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(rows.row(i), eigenFeatures(clouds[i]).transpose()) << i;
  EXPECT_EQ(d.describe({}).rows(), 0);
  EXPECT_THROW(d.describe({DescriptorInput{}}), std::invalid_argument);
}

// The factory makes every kind this build has; for one it has not, the error is one line that
// names the build option (by kind, and by descriptor.kind from a configuration).
TEST(DescriberFactory, MakesTheKindsOfThisBuildAndNamesTheOptionOfTheOthers) {
  EXPECT_EQ(makeDescriber(DescriptorKind::kEigen, {})->kind(), DescriptorKind::kEigen);
  EXPECT_EQ(descriptorNotBuilt(DescriptorKind::kEigen), "");
  auto expectMissing = [](DescriptorKind kind, const std::string& option) {
    SCOPED_TRACE(descriptorName(kind));
    const std::string why = descriptorNotBuilt(kind);
    EXPECT_NE(why.find("this build has no"), std::string::npos) << why;
    EXPECT_NE(why.find("reconfigure with -D" + option + "=ON"), std::string::npos) << why;
    EXPECT_EQ(why.find('\n'), std::string::npos) << why;
    try {
      makeDescriber(kind, {});
      ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(e.what(), descriptorName(kind) + ": " + why);
    }
    DescriptorConfig config;
    config.kind = descriptorName(kind);
    config.model = "missing.model";  // never read
    try {
      makeDescriber(config);
      ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(e.what(), "descriptor.kind " + config.kind + ": " + why);
    }
    EXPECT_THROW(requireDescriberBuilt(config), std::runtime_error);
  };
  if (SEMSEGMAP_WITH_PCL) {
    DescriptorConfig fpfh;
    fpfh.kind = "fpfh";
    EXPECT_EQ(makeDescriber(fpfh, 1)->kind(), DescriptorKind::kFpfh);
  } else {
    expectMissing(DescriptorKind::kFpfh, "SEMSEGMAP_WITH_PCL");
    EXPECT_NE(descriptorNotBuilt(DescriptorKind::kFpfh).find("no FPFH (built without PCL"),
              std::string::npos);
  }
  for (const DescriptorKind kind : {DescriptorKind::kSegMapCnn, DescriptorKind::kSemSegMapNet}) {
    if (SEMSEGMAP_WITH_TORCH) {
      EXPECT_THROW(makeDescriber(kind, {}), std::invalid_argument);  // needs a network
    } else {
      expectMissing(kind, "SEMSEGMAP_WITH_TORCH");
    }
  }
}

#if SEMSEGMAP_WITH_PCL
TEST(FpfhFeatures, BlocksSumToOne) {
  const Features33 f = fpfhFeatures(sphereShell(600, 1.0, 0.01, 10));
  ASSERT_TRUE(f.allFinite());
  EXPECT_TRUE((f.array() >= 0.0f).all());
  for (int b = 0; b < 3; ++b) EXPECT_NEAR(f.segment<11>(11 * b).sum(), 1.0, 1e-4) << "block " << b;
}

TEST(FpfhFeatures, TellsAPlaneFromASphere) {
  const Features33 plane_a = fpfhFeatures(planePatch(500, 2.0, 0.01, 11));
  const Features33 plane_b = fpfhFeatures(planePatch(500, 2.0, 0.01, 12));
  const Features33 sphere_a = fpfhFeatures(sphereShell(600, 1.0, 0.01, 13));
  const Features33 sphere_b = fpfhFeatures(sphereShell(600, 1.0, 0.01, 14));
  const double same = std::max(l1(plane_a, plane_b), l1(sphere_a, sphere_b));
  const double different = std::min(l1(plane_a, sphere_a), l1(plane_b, sphere_b));
  EXPECT_GT(different, 3.0 * same) << "same shape " << same << ", different shapes " << different;
  EXPECT_GT(different, 0.5);  // of at most 6 (three blocks summing to 1 each)
}

TEST(FpfhFeatures, InvariantToPointOrderAndRigidMotion) {
  // The bounds are far below the distance between two samplings of one shape (0.1 - 0.7).
  const Eigen::Isometry3d T = someRigidMotion();
  FpfhConfig whole;  // no subsampling
  whole.max_points = 1000;
  for (const EnrichedCloud& cloud :
       {sphereShell(400, 1.0, 0.02, 15), planePatch(300, 2.0, 0.02, 16)}) {
    const Features33 f = fpfhFeatures(cloud, whole);
    EXPECT_LT(l1(fpfhFeatures(shuffled(cloud, 17), whole), f), 1e-3);
    EXPECT_LT(l1(fpfhFeatures(transformed(cloud, T), whole), f), 0.02);
  }
  // Also when the segment is larger than max_points and is subsampled.
  const EnrichedCloud big = sphereShell(1500, 1.5, 0.02, 18);
  const Features33 f = fpfhFeatures(big);
  EXPECT_LT(l1(fpfhFeatures(shuffled(big, 19)), f), 1e-3);
  EXPECT_LT(l1(fpfhFeatures(transformed(big, T)), f), 0.05);
}

TEST(FpfhFeatures, DegenerateInputsAreFinite) {
  const Features33 zero = Features33::Zero();
  EXPECT_EQ(fpfhFeatures({}), zero);
  EXPECT_EQ(fpfhFeatures({point({1, 2, 3})}), zero);
  EXPECT_EQ(fpfhFeatures({point({1, 2, 3}), point({1, 2, 4})}), zero);
  EXPECT_EQ(fpfhFeatures(EnrichedCloud(200, point({512.0, 3.5, -2.0}))), zero);
  EXPECT_TRUE(fpfhFeatures({point({0, 0, 0}), point({1, 0, 0}), point({0, 1, 0})}).allFinite());
  EnrichedCloud collinear;
  for (int i = 0; i < 60; ++i) collinear.push_back(point({0.1 * i, 0.0, 0.0}));
  EXPECT_TRUE(fpfhFeatures(collinear).allFinite());
  EnrichedCloud bad = planePatch(50, 1.0, 0.01, 20);
  bad[7].z = std::numeric_limits<float>::infinity();
  EXPECT_THROW(fpfhFeatures(bad), std::invalid_argument);
}

TEST(FpfhDescriber, BatchEqualsOneAtATime) {
  FpfhDescriber d;
  EXPECT_EQ(d.kind(), DescriptorKind::kFpfh);
  EXPECT_EQ(d.dimension(), 33);
  EXPECT_EQ(d.fingerprint(), "fpfh-v1");
  std::vector<EnrichedCloud> clouds;
  for (int i = 0; i < 9; ++i)
    clouds.push_back(i % 3 == 0   ? planePatch(200 + 50 * i, 2.0, 0.01, 30 + i)
                     : i % 3 == 1 ? sphereShell(300 + 40 * i, 1.0, 0.01, 30 + i)
                                  : EnrichedCloud(i, point({1, 1, 1})));
  std::vector<DescriptorInput> batch;
  for (const EnrichedCloud& c : clouds) batch.push_back({&c});
  const Eigen::MatrixXf rows = d.describe(batch);
  ASSERT_EQ(rows.rows(), 9);
  ASSERT_EQ(rows.cols(), 33);
  for (int i = 0; i < 9; ++i) EXPECT_EQ(rows.row(i), fpfhFeatures(clouds[i]).transpose()) << i;
  FpfhConfig one_thread;
  one_thread.threads = 1;
  EXPECT_EQ(FpfhDescriber(one_thread).describe(batch), rows);
  EXPECT_EQ(d.describe({}).rows(), 0);
  batch[4].points = nullptr;
  EXPECT_THROW(d.describe(batch), std::invalid_argument);
}

TEST(FpfhDescriber, RejectsBadConfig) {
  FpfhConfig c;
  c.normal_k = 2;
  EXPECT_THROW(FpfhDescriber{c}, std::invalid_argument);
  c = {};
  c.max_points = 0;
  EXPECT_THROW(FpfhDescriber{c}, std::invalid_argument);
  c = {};
  c.radius_margin_m = -1.0;
  EXPECT_THROW(FpfhDescriber{c}, std::invalid_argument);
  c = {};
  c.threads = -1;
  EXPECT_THROW(FpfhDescriber{c}, std::invalid_argument);
}
#endif  // SEMSEGMAP_WITH_PCL
