// The Cusick drape test's two numbers from a draped surface (ISO 9073-9 / BS 5058; docs/fabric_test.md):
// the drape coefficient DC = (A_shadow − A_support) / (A_specimen − A_support), A_shadow the area
// of the surface's vertical projection (its shadow from a light straight above), and the number
// of nodes (folds) of the shadow's outline. The projection is along −up onto the plane normal to
// `up`; the shadow is the union of the projected triangles and of the support disc (opaque, under
// the specimen: a clamped specimen's mesh may leave its middle out), rasterised on a square grid.
#pragma once

#include <Eigen/Core>

#include <array>
#include <vector>

namespace clothsim {

struct DrapeMeasureSettings {
  double support_radius = 0.09;    // R0 [m] (ISO 9073-9: 18 cm support disc)
  double specimen_radius = 0.15;   // R1 [m] (30 cm specimen)
  double cell = 0.0005;            // raster cell H [m]
  double prominence = 0.005;       // a node is an outline maximum standing out by this much [m]
  int smoothing = 5;               // moving-average width of the outline radius [angular bins]
  int angles = 720;                // angular bins of the outline
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();  // the projection direction is −up
  Eigen::Vector3d support_center = Eigen::Vector3d::Zero();  // a point on the support's axis [m]
};

struct DrapeMeasure {
  double shadow_area = 0.0;        // A_shadow [m²]
  double area_bound = 0.0;         // ± half the boundary cells' area [m²] (the raster's resolution)
  double drape_coefficient = 0.0;  // DC [-]
  int nodes = 0;                   // outline maxima with at least the prominence
  std::vector<double> outline;     // smoothed outline radius per angular bin [m], about the shadow's centroid
  std::vector<int> node_bins;      // the bins of the counted maxima (find_profile_peaks, sim/study/fold_count.hpp)
};

// Measures the surface (vertices #V × 3 [m], triangles). Throws std::invalid_argument for an
// empty surface, a bad setting (cell, radii, prominence, smoothing, angles) or a shadow too large
// for the raster (more than 10^8 cells).
DrapeMeasure measure_drape(const Eigen::MatrixX3d& vertices, const std::vector<std::array<int, 3>>& triangles,
                           const DrapeMeasureSettings& settings = {});

}  // namespace clothsim
