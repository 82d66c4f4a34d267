// Closest points of point–triangle and edge–edge pairs and their conservative-advancement CCD
// (see narrow_phase.hpp for the conventions, the algorithm and its no-miss argument).
#include "sim/contact/narrow_phase.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace clothsim::contact {

namespace {

using Vec3 = Eigen::Vector3d;

// Below this distance [m] the direction between the closest points is meaningless: use the
// documented fallback normal instead.
constexpr double kTinyDistance = 1e-300;
// A triangle (or a pair of edge directions) is degenerate (parallel) when its doubled area
// |e1 × e2| is at most this fraction of |e1| |e2| (or of the longest squared edge).
constexpr double kDegenerate = 1e-14;
// Below this fraction the interior solution of two segments is ill-conditioned: compare it with
// the boundary candidates and keep the nearest.
constexpr double kThin = 1e-2;

// CCD rounding allowance: relative part (of distances) and absolute part (of the coordinate
// scale S [m]); see narrow_phase.hpp, step 4.
constexpr double kRelativeMargin = 1e-12;
constexpr double kAbsoluteMargin = 1e-13;
// Fraction of the proven collision-free interval that one CCD step advances.
constexpr double kStepFraction = 0.9;

// (1 − t) a + t b, which is exactly a at t = 0 and exactly b at t = 1.
Vec3 lerp(const Vec3& a, const Vec3& b, double t) { return (1.0 - t) * a + t * b; }

// Parameter in [0, 1] of the point of the closed segment a→b nearest to p (0 for a zero-length
// segment).
double segment_parameter(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 e = b - a;
  const double ee = e.squaredNorm();
  if (!(ee > 0.0)) return 0.0;
  return std::clamp((p - a).dot(e) / ee, 0.0, 1.0);
}

// A unit vector perpendicular to u: u × e_k normalised, with e_k the axis of the smallest
// |component| of u (then |u × e_k| ≥ √(2/3) |u|, well conditioned). +z when u is zero.
Vec3 any_perpendicular(const Vec3& u) {
  const double scale = u.cwiseAbs().maxCoeff();
  if (!(scale > 0.0)) return Vec3::UnitZ();
  const Vec3 v = u / scale;  // avoid underflow of tiny vectors
  Eigen::Index k = 0;
  v.cwiseAbs().minCoeff(&k);
  return v.cross(Vec3::Unit(k)).normalized();
}

}  // namespace

PointTriangleProximity point_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const std::array<const Vec3*, 3> v = {&a, &b, &c};
  // Frame on the longest edge A→B with C the third vertex, (A, B, C) a cyclic permutation of
  // (a, b, c) so that t × w below is the orientation of (b − a) × (c − a).
  int ia = 0;
  double longest2 = (b - a).squaredNorm();
  if ((c - b).squaredNorm() > longest2) {
    ia = 1;
    longest2 = (c - b).squaredNorm();
  }
  if ((a - c).squaredNorm() > longest2) {
    ia = 2;
    longest2 = (a - c).squaredNorm();
  }
  const int ib = (ia + 1) % 3, ic = (ia + 2) % 3;
  const Vec3& A = *v[ia];
  const Vec3 edge = *v[ib] - A;
  const double length = std::sqrt(longest2);

  PointTriangleProximity best;
  best.distance = std::numeric_limits<double>::infinity();
  Vec3 best_point = a;
  bool degenerate = true;
  Vec3 face_normal = Vec3::UnitZ();

  if (length > 0.0) {
    // Orthonormal in-plane frame (tangent along the longest edge, w towards C) and normal.
    // Gram–Schmidt on the longest edge is backward stable for slivers: the computed frame is
    // exact for C moved by a few rounding units, so the height of p over the face is accurate
    // even when the direction of a thin triangle's normal is not.
    const Vec3 tangent = edge / length;
    const Vec3 u = *v[ic] - A;
    const double c_along = u.dot(tangent);
    Vec3 across = u - c_along * tangent;
    // A second projection removes the tangential residue that the rounding of c_along leaves in
    // `across` (relative size ε |u| / width), which would otherwise tilt the frame of a sliver
    // with the lever arm of p along the edge.
    across -= across.dot(tangent) * tangent;
    const double width = across.norm();  // height of C over the longest edge [m]
    degenerate = !(width > kDegenerate * length);
    if (!degenerate) {
      const Vec3 w = across / width;
      face_normal = tangent.cross(w);
      // In-plane coordinates of p and the barycentric weights of its projection.
      const Vec3 r = p - A;
      const double alpha = r.dot(tangent), beta = r.dot(w);
      const double weight_c = beta / width;
      const double weight_b = (alpha - weight_c * c_along) / length;
      const double weight_a = 1.0 - weight_b - weight_c;
      if (weight_a >= 0.0 && weight_b >= 0.0 && weight_c >= 0.0) {
        best.weights[ia] = weight_a;
        best.weights[ib] = weight_b;
        best.weights[ic] = weight_c;
        best_point = best.weights[0] * a + best.weights[1] * b + best.weights[2] * c;
        best.distance = (p - best_point).norm();
        // The projection lies in the closed face, so it is the closest point. Its normal is the
        // face normal oriented towards p: what (p − q) / |p − q| equals without the in-plane
        // rounding of q (and the face normal itself when p is on the face).
        best.normal = (best.distance < kTinyDistance || r.dot(face_normal) >= 0.0) ? face_normal : Vec3(-face_normal);
        return best;
      }
    }
  }

  // Boundary: the nearest of the three closed edges (every vertex and edge region, and the whole
  // triangle when it is degenerate).
  const auto consider_edge = [&](int i_from, int i_to) {
    const Vec3& from = *v[i_from];
    const Vec3& to = *v[i_to];
    const double t = segment_parameter(p, from, to);
    const Vec3 q = lerp(from, to, t);
    const double dist = (p - q).norm();
    if (dist < best.distance) {
      best.distance = dist;
      best.weights.setZero();
      best.weights[i_from] = 1.0 - t;
      best.weights[i_to] = t;
      best_point = q;
    }
  };
  consider_edge(0, 1);
  consider_edge(1, 2);
  consider_edge(2, 0);

  if (best.distance >= kTinyDistance) {
    best.normal = (p - best_point) / best.distance;
  } else if (!degenerate) {
    best.normal = face_normal;
  } else {
    best.normal = any_perpendicular(edge);
  }
  return best;
}

EdgeEdgeProximity edge_edge(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  const Vec3 dp = p1 - p0, dq = q1 - q0, r = p0 - q0;
  const double len_p = dp.norm(), len_q = dq.norm();
  const Vec3 cross = dp.cross(dq);
  const double cross_norm = cross.norm();
  const bool parallel = !(cross_norm > kDegenerate * len_p * len_q);

  EdgeEdgeProximity best;
  best.distance = std::numeric_limits<double>::infinity();
  Vec3 best_p = p0, best_q = q0;
  const auto consider = [&](double s, double t) {
    const Vec3 x = lerp(p0, p1, s), y = lerp(q0, q1, t);
    const double dist = (x - y).norm();
    if (dist < best.distance) {
      best.distance = dist;
      best.s = s;
      best.t = t;
      best_p = x;
      best_q = y;
    }
  };

  bool interior_found = false;
  if (!parallel) {
    // Stationary point of |r + s dp − t dq|²: a s − b t = −c and b s − e t = −f with
    // a = |dp|², b = dp·dq, c = dp·r, e = |dq|², f = dq·r; determinant a e − b² = |dp × dq|².
    const double aa = dp.squaredNorm(), bb = dp.dot(dq), cc = dp.dot(r), ee = dq.squaredNorm(), ff = dq.dot(r);
    const double det = cross_norm * cross_norm;
    const double s = (bb * ff - cc * ee) / det;
    const double t = (aa * ff - bb * cc) / det;
    if (s >= 0.0 && s <= 1.0 && t >= 0.0 && t <= 1.0) {
      consider(s, t);
      interior_found = cross_norm > kThin * len_p * len_q;
    }
  }
  if (!interior_found) {
    // Boundary of the parameter square: an end point against the other segment.
    consider(0.0, segment_parameter(p0, q0, q1));
    consider(1.0, segment_parameter(p1, q0, q1));
    consider(segment_parameter(q0, p0, p1), 0.0);
    consider(segment_parameter(q1, p0, p1), 1.0);
  }

  if (best.distance >= kTinyDistance) {
    best.normal = (best_p - best_q) / best.distance;
  } else if (!parallel) {
    best.normal = cross / cross_norm;
  } else {
    best.normal = any_perpendicular(len_p >= len_q ? dp : dq);
  }
  return best;
}

namespace {

// Conservative advancement shared by both pairs. Vertices [0, first_count) form the first
// primitive, [first_count, 4) the second. `distance(x, normal)` returns the distance of the
// primitives with vertices x and writes the unit normal pointing from the second to the first.
template <class DistanceFunction>
CcdResult advance(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end, int first_count,
                  double separation, int max_iterations, DistanceFunction distance) {
  // Coordinate scale of the input [m], for the absolute rounding allowance.
  double scale = 0.0;
  for (int i = 0; i < 4; ++i) {
    scale = std::max({scale, start[i].cwiseAbs().maxCoeff(), end[i].cwiseAbs().maxCoeff()});
  }
  const double absolute_margin = kAbsoluteMargin * scale;

  // Frame moving with the mean displacement, centred on the mean start position.
  std::array<Vec3, 4> displacement;
  Vec3 mean_displacement = Vec3::Zero(), mean_start = Vec3::Zero();
  for (int i = 0; i < 4; ++i) {
    displacement[i] = end[i] - start[i];
    mean_displacement += 0.25 * displacement[i];
    mean_start += 0.25 * start[i];
  }
  std::array<Vec3, 4> local_start, local_velocity;
  for (int i = 0; i < 4; ++i) {
    local_start[i] = start[i] - mean_start;
    local_velocity[i] = displacement[i] - mean_displacement;
  }

  // Bound L on |dd/dτ| [m per unit τ]: the largest relative displacement of a vertex pair.
  double rate = 0.0;
  for (int i = 0; i < first_count; ++i) {
    for (int j = first_count; j < 4; ++j) rate = std::max(rate, (displacement[i] - displacement[j]).norm());
  }
  const double rate_bound = rate * (1.0 + kRelativeMargin) + absolute_margin;
  const double rate_margin = kRelativeMargin * rate + absolute_margin;

  const int limit = std::max(1, max_iterations);
  CcdResult result;
  result.distance = std::numeric_limits<double>::infinity();
  double tau = 0.0;
  std::array<Vec3, 4> x;
  Vec3 normal;
  for (int iteration = 1;; ++iteration) {
    for (int i = 0; i < 4; ++i) x[i] = local_start[i] + tau * local_velocity[i];
    const double d = distance(x, normal);
    result.iterations = iteration;
    // Hit band: one allowance for rounding, one for the advancement to land in (header, step 4).
    const double margin = kRelativeMargin * (d + separation) + absolute_margin;
    if (d - 2.0 * margin <= separation) {
      result.hit = true;
      result.toi = tau;
      result.distance = d;
      return result;
    }
    result.distance = std::min(result.distance, d);
    if (rate == 0.0) break;  // no relative motion: the distance stays d > separation

    // Lipschitz bound: d(τ + h) ≥ (d − m) − L h > separation for h < h_L.
    const double gap = d - margin - separation;
    double h = gap / rate_bound;
    // Separating-plane bound: each term n·(x_i − x_j) + h n·(Δ_i − Δ_j), lowered by the rounding
    // allowance, stays above separation until its own crossing time.
    double h_plane = std::numeric_limits<double>::infinity();
    for (int i = 0; i < first_count && h_plane > 0.0; ++i) {
      for (int j = first_count; j < 4; ++j) {
        const double offset = normal.dot(x[i] - x[j]) - margin;
        if (offset <= separation) {
          h_plane = 0.0;
          break;
        }
        const double approach = normal.dot(local_velocity[i] - local_velocity[j]) - rate_margin;
        if (approach < 0.0) h_plane = std::min(h_plane, (offset - separation) / -approach);
      }
    }
    h = std::max(h, h_plane);
    if (h > 1.0 - tau) break;  // [τ, 1] is proven free of contact
    if (iteration >= limit) {
      // Undecided: report the current time, before which every time is proven free.
      result.hit = true;
      result.toi = tau;
      result.distance = d;
      return result;
    }
    tau += kStepFraction * h;
  }
  result.hit = false;
  result.toi = 1.0;
  return result;
}

}  // namespace

CcdResult point_triangle_ccd(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end, double separation,
                             int max_iterations) {
  return advance(start, end, 1, separation, max_iterations, [](const std::array<Vec3, 4>& x, Vec3& normal) {
    const PointTriangleProximity proximity = point_triangle(x[0], x[1], x[2], x[3]);
    normal = proximity.normal;
    return proximity.distance;
  });
}

CcdResult edge_edge_ccd(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end, double separation,
                        int max_iterations) {
  return advance(start, end, 2, separation, max_iterations, [](const std::array<Vec3, 4>& x, Vec3& normal) {
    const EdgeEdgeProximity proximity = edge_edge(x[0], x[1], x[2], x[3]);
    normal = proximity.normal;
    return proximity.distance;
  });
}

}  // namespace clothsim::contact
