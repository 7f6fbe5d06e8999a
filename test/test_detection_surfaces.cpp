/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Undersampling detection (stages 1-3) on surfaces with a known boundary.
 */

#include <pcl/surface/cocone/pipeline.h>

#include <gtest/gtest.h>

#include <support/cases.h>
#include <support/metrics.h>
#include <support/surfaces.h>

#include <cstdio>
#include <functional>
#include <ostream>

using cocone_test::options;
using cocone_test::paper;
using cocone_test::Sample;
using cocone_test::SampleOptions;

namespace {

/** The library's default: automatic rho and the spacing test. */
const pcl::cocone::Parameters AUTOMATIC;

cocone_test::BoundaryScore
detect(const Sample& s, const pcl::cocone::Parameters& parameters = paper())
{
  const auto r =
      pcl::cocone::run(s.points, parameters, pcl::cocone::Stages::BOUNDARY_DETECTION);
  EXPECT_TRUE(r.error.empty()) << r.error;
  const auto score = cocone_test::scoreBoundary(s, r.boundary_indices);
  std::printf("[ measured ] %-22s %s rho %.2f: %s\n",
              s.name.c_str(),
              parameters.ratio > 0.0 ? "paper" : "auto ",
              r.ratio,
              score.str().c_str());
  return score;
}

using Generator = std::function<Sample(const SampleOptions&)>;

/** An open surface and the recall the paper's fixed rho = 1.5 reaches on it (clean,
 * 5 % noise, density 1:4). The target is 0.95. Where a floor is lower, the fixed
 * ratio misses part of the border, and the floor is the measured value less a
 * margin, kept so that a regression shows: on the gently curved sheet (radius of
 * curvature about 3, 140 spacings) the rim cells are 60 spacings wide yet only a
 * quarter as wide as they are high, so they pass as flat; the same cells fail the
 * spacing-aware test of the automatic mode. The reference implementation
 * (shared/reference/boundary.py) labels the same points on these clouds. */
struct OpenCase {
  const char* name;
  Generator make;
  double recall_clean, recall_noisy, recall_uneven;
};

void
PrintTo(const OpenCase& c, std::ostream* os)
{
  *os << c.name;
}

const OpenCase OPEN_SURFACES[] = {
    {"hemisphere",
     [](const SampleOptions& o) { return cocone_test::hemisphere(o); },
     0.95,
     0.95,
     0.95},
    {"monkey_saddle",
     [](const SampleOptions& o) { return cocone_test::monkeySaddle(o); },
     0.95,
     0.95,
     0.95},
    {"open_cylinder",
     [](const SampleOptions& o) { return cocone_test::openCylinder(o); },
     0.95,
     0.95,
     0.95},
    {"curved_sheet",
     [](const SampleOptions& o) { return cocone_test::curvedSheet(o); },
     0.70,
     0.92,
     0.72},
    {"scan_line_sheet",
     [](const SampleOptions& o) { return cocone_test::scanLineSheet(o); },
     0.95,
     0.95,
     0.92},
    {"three_components", // contains the curved sheet
     [](const SampleOptions& o) { return cocone_test::threeComponents(o); },
     0.90,
     0.94,
     0.90},
};

class OpenSurface : public ::testing::TestWithParam<OpenCase> {};

} // namespace

TEST(ClosedSurface, AlmostNoFalseBoundary)
{
  const Sample surfaces[] = {cocone_test::sphere(options(10000)),
                             cocone_test::ellipsoid(options(10000)),
                             cocone_test::torus(options(10000))};
  for (const auto& s : surfaces) {
    EXPECT_LE(detect(s).reported_share, 0.005) << s.name;
    EXPECT_LE(detect(s, AUTOMATIC).reported_share, 0.005) << s.name;
  }
}

TEST_P(OpenSurface, FindsTheBoundary)
{
  const auto s = GetParam().make(options(10000));
  const auto score = detect(s);
  EXPECT_GE(score.recall, GetParam().recall_clean) << s.name;
  EXPECT_GE(score.precision, 0.90) << s.name;
}

TEST_P(OpenSurface, MildNoise)
{
  const auto s = GetParam().make(options(10000, 0.05));
  const auto score = detect(s);
  EXPECT_GE(score.recall, GetParam().recall_noisy) << s.name;
  EXPECT_GE(score.precision, 0.90) << s.name;
}

TEST_P(OpenSurface, UnevenDensity)
{
  const auto s = GetParam().make(options(10000, 0.0, 4.0));
  const auto score = detect(s);
  EXPECT_GE(score.recall, GetParam().recall_uneven) << s.name;
  EXPECT_GE(score.precision, 0.90) << s.name;
}

TEST_P(OpenSurface, AutomaticModeFindsTheBoundary)
{
  for (const auto& o :
       {options(10000), options(10000, 0.05), options(10000, 0.0, 4.0)}) {
    const auto s = GetParam().make(o);
    const auto score = detect(s, AUTOMATIC);
    EXPECT_GE(score.recall, 0.95)
        << s.name << " noise " << o.noise << " density 1:" << o.density_ratio;
    EXPECT_GE(score.precision, 0.90) << s.name;
  }
}

INSTANTIATE_TEST_SUITE_P(Detection,
                         OpenSurface,
                         ::testing::ValuesIn(OPEN_SURFACES),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(SphereWithHoles, FixedRatioMissesSmallHoles)
{
  // Three holes of 28.6 deg angular radius. The ratio test is scale-free: at a rim the
  // width is about the hole radius and the height about the local feature size, so
  // at rho = 1.5 the rims look flat (the paper's limitation); at rho = 2.5 they do not.
  const auto s = cocone_test::sphereWithHoles(options(10000), 3, 0.5);
  const auto at15 = detect(s, paper(1.5));
  EXPECT_LT(at15.recall, 0.5) << "rho 1.5 was expected to miss the holes";
  // At 2.5 every rim is found (the reconstruction opens all three holes), 90 % of
  // the rim curve lies within 2.5 spacings of a reported point.
  const auto at25 = detect(s, paper(2.5));
  EXPECT_GE(at25.recall, 0.88);
  EXPECT_GE(at25.precision, 0.90);
  // The automatic mode needs no rho to find them.
  const auto automatic = detect(s, AUTOMATIC);
  EXPECT_GE(automatic.recall, 0.95);
  EXPECT_GE(automatic.precision, 0.90);
}

TEST(NoisyClosedSurface, FalseBoundaryShare)
{
  // Noise of 15 % of the spacing brings the negative pole close: some false
  // boundary points appear. Record the share; fail if it grows markedly.
  // Measured: 5.1 % (the reference prototype reported 6.8 % on its torus).
  const auto s = cocone_test::torus(options(10000, 0.15));
  const auto score = detect(s);
  EXPECT_LE(score.reported_share, 0.07);
  RecordProperty("automatic_share",
                 std::to_string(detect(s, AUTOMATIC).reported_share));
}
