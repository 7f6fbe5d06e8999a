/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/pipeline.h>

#include <support/surfaces.h>

namespace cocone_test {

/** Sampling options of the test surfaces. */
inline SampleOptions
options(std::size_t n, double noise = 0.0, double density_ratio = 1.0, bool even = true)
{
  SampleOptions o;
  o.n = n;
  o.noise = noise;
  o.density_ratio = density_ratio;
  o.even = even;
  return o;
}

/** The paper's flatness test: a fixed rho, no spacing test, no half-disk test. */
inline pcl::cocone::Parameters
paper(double ratio = 1.5)
{
  pcl::cocone::Parameters p;
  p.ratio = ratio;
  p.spacing_factor = 0.0;
  p.gap_angle = 0.0;
  return p;
}

} // namespace cocone_test
