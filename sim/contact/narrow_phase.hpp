// Narrow-phase contact geometry: exact closest points of a point and a triangle and of two
// segments, and continuous collision detection (CCD) of those pairs over one time step by
// conservative (additive) advancement on the distance (Mirtich 1996; Li, Kaufman & Jiang 2021,
// "Codimensional incremental potential contact", §4 additive CCD). Lengths are in metres [m];
// the CCD time τ is the fraction of the step, dimensionless, in [0, 1].
//
// Conventions of the proximity queries:
//  - Both primitives are closed and solid: a triangle includes its edges, vertices and interior;
//    a segment includes its end points.
//  - `distance` is always |p − q| of the two reported closest points (rebuilt from the reported
//    weights or parameters), so it never falls below the true distance by more than rounding.
//  - Degenerate input is allowed: a triangle whose vertices are collinear or coincident is treated
//    as the union of its three edges (the segment or the point it has collapsed to); a zero-length
//    segment is treated as a point. A triangle counts as degenerate when its doubled area
//    |(b − a) × (c − a)| is ≤ 1e-14 times its longest squared edge length (dropping the interior of
//    such a sliver moves the distance by at most its width, ≤ 1e-14 × its longest edge).
//  - `normal` is a unit vector. When the distance is ≥ 1e-300 m it points from the closest point
//    of the second primitive (triangle, segment q) towards the first (point p, segment p). When it
//    is below that, it is a fallback documented with each function.
#pragma once

#include <Eigen/Core>

#include <array>

namespace clothsim::contact {

struct PointTriangleProximity {
  double distance = 0.0;                                  // [m]
  Eigen::Vector3d weights = Eigen::Vector3d::Zero();      // barycentric (w_a, w_b, w_c) of the closest point, each in [0, 1], sum 1
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();      // unit, from the closest point towards p
};

struct EdgeEdgeProximity {
  double distance = 0.0;                                  // [m]
  double s = 0.0;                                         // closest point on p: (1 − s) p0 + s p1, s in [0, 1]
  double t = 0.0;                                         // closest point on q: (1 − t) q0 + t q1, t in [0, 1]
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();      // unit, from the point on q towards the point on p
};

// Closest point of the closed triangle (a, b, c) to p. Face region: the orthogonal projection of
// p, computed in an orthonormal frame built on the longest edge (tangent, in-plane direction
// towards the third vertex by Gram–Schmidt, normal), when all three barycentric weights of the
// projection are ≥ 0; otherwise the nearest of the three edges (which covers every edge and vertex
// region). The frame is backward stable, so the distance stays within a few rounding units of the
// coordinates even for slivers (checked against quadruple precision for triangles of width
// 1e-14 … 1 times their longest edge).
// Normal when the distance is < 1e-300 m: the unit normal (b − a) × (c − a) / |…| of a
// non-degenerate triangle; for a degenerate one, the unit vector (longest edge) × e_k normalised,
// with e_k the coordinate axis along which the longest edge has its smallest component (so it is
// perpendicular to that edge); if all three vertices coincide, +z.
PointTriangleProximity point_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                      const Eigen::Vector3d& c);

// Closest points of the closed segments p0→p1 and q0→q1. When the lines are not (nearly)
// parallel and their closest points lie inside both segments, those; otherwise the minimum of the
// four end-point-to-segment distances (for a convex quadratic whose unconstrained minimiser lies
// outside the square [0, 1]², the constrained minimiser lies on its boundary, where s or t is 0
// or 1). Nearly parallel pairs (|d_p × d_q| < 1e-2 |d_p||d_q|) evaluate all five candidates and
// keep the nearest, which keeps the distance within a few rounding units of the coordinates
// (checked against quadruple precision down to exactly parallel pairs).
// Normal when the distance is < 1e-300 m: (p1 − p0) × (q1 − q0) normalised when the edges are not
// parallel (|d_p × d_q| > 1e-14 |d_p||d_q|); otherwise a unit vector perpendicular to the longer
// edge chosen as in point_triangle; +z if both segments have zero length.
EdgeEdgeProximity edge_edge(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& q0,
                            const Eigen::Vector3d& q1);

struct CcdResult {
  bool hit = false;        // the distance may fall to `separation` or below during the step
  double toi = 1.0;        // hit: a time no later than the first time the distance is ≤ separation; no hit: 1
  double distance = 0.0;   // hit: the distance at toi [m]; no hit: the smallest distance evaluated [m]
  int iterations = 0;      // distance evaluations made
};

// Continuous collision detection over a step in which every vertex moves linearly,
// x(τ) = x_start + τ (x_end − x_start), τ in [0, 1]. `separation` > 0 [m] is the distance that
// counts as contact (a thickness or a minimum gap).
//
// Algorithm (conservative advancement on the exact distance; no polynomial root finding):
//  1. Work in a frame that moves with the mean displacement Δ̄ of the four vertices and is centred
//     on their mean start position: x̃_i(τ) = (x_i,start − c) + τ (Δ_i − Δ̄). A common translation
//     does not change the distance.
//  2. Lipschitz bound. Every point of the first primitive is a convex combination Σ α_i x̃_i and
//     every point of the second Σ β_j x̃_j, so their relative velocity is
//     Σ_i Σ_j α_i β_j (Δ_i − Δ_j) and the distance d(τ) changes at most at the rate
//         L = max over i in the first primitive, j in the second of |Δ_i − Δ_j|.
//     This is never larger than the ACCD bound max_i |Δ_i − Δ̄| + max_j |Δ_j − Δ̄| (triangle
//     inequality) and is also valid. Hence d(τ + h) ≥ d(τ) − L h.
//  3. Separating-plane bound. With n the unit normal at τ (pointing from the second primitive to
//     the first), |x − y| ≥ n · (x − y) for any points x, y, and the extreme values of n · x over a
//     moving convex hull are attained at its vertices, so
//         d(τ + h) ≥ min over i, j of [ n · (x̃_i(τ) − x̃_j(τ)) + h n · (Δ_i − Δ_j) ],
//     a lower bound that equals d(τ) at h = 0 (projection theorem) and is exact for a point
//     approaching a face along a straight line; it lets sliding contact (motion perpendicular to
//     n) finish in one step.
//  4. At the current τ evaluate d with point_triangle / edge_edge. Rounding allowance:
//         m = 1e-12 (d + separation) + 1e-13 S,
//     S the largest absolute coordinate of the eight input positions [m]. The computed distance
//     is taken to be within m of the true one (m ≥ ~450 rounding units of S; both distance
//     functions stay within a few, slivers and nearly parallel edges included). Hit at τ if
//         d ≤ separation + 2 m.
//     One m covers rounding, so a true distance ≤ separation is always caught; the second m is
//     the band the advancement must land in to stop (the steps below approach separation + m
//     from above, so without that band an approach would only end at max_iterations). A hit can
//     therefore be reported for a minimum distance up to separation + 3 m, never missed.
//  5. Otherwise both bounds, applied to d − m, give a time h > 0 such that the true distance stays
//     > separation on [τ, τ + h): h_L = (d − m − separation) / L_up with
//     L_up = L (1 + 1e-12) + 1e-13 S, and h_n = the first h at which one of the linear terms of 3
//     (each reduced by m, its rate reduced by 1e-12 L + 1e-13 S) reaches separation. With
//     h = max(h_L, h_n): if h > 1 − τ there is no hit in the step; else τ ← τ + 0.9 h.
//     Stepping 0.9 h rather than h keeps τ strictly inside the proven collision-free interval,
//     with a 10 % slack that absorbs the rounding of h and of τ + h, so a step can never pass a
//     time at which the distance is ≤ separation. When a bound is tight (a head-on approach, a
//     point approaching a face, two edges closing along their common normal) the gap d − m −
//     separation shrinks tenfold per step, so about 15 + log10(gap / m) steps reach the hit band
//     of 4; a loose bound (fast rotation, near-tangential approach) shrinks it more slowly.
//  6. If L == 0 there is no relative motion: the distance is constant and the answer is decided
//     at τ = 0. If `max_iterations` distance evaluations pass without a decision, a hit is reported
//     at the current τ (conservative; every earlier time is proven free).
//
// Why no collision is missed in the hard cases: the method never solves for the instant at which
// the four points become coplanar (the cubic of Provot/Bridson CCD), which is where those methods
// fail: coplanar motion makes the cubic vanish identically, parallel and degenerate primitives
// make it ill-conditioned, and grazing contacts give double roots lost to rounding. Here every
// decision rests on the exact closed-primitive distance, which is well defined and continuous for
// coplanar, parallel, collinear, zero-length and zero-area input, and on bounds that hold for any
// motion. A "no hit" answer is only returned after the whole interval [0, 1] has been covered by
// intervals on which the distance is proven to stay above separation; grazing at exactly
// separation is reported as a hit because the rounding allowance only enlarges the hit set.
// The price is that contacts that graze just above separation (within the allowance) are
// reported as hits, and near-tangential approaches may use many iterations before they are
// decided (or reported conservatively at max_iterations).
//
// Vertex order: point_triangle_ccd: point, a, b, c (the first primitive is the point);
// edge_edge_ccd: p0, p1, q0, q1 (the first primitive is segment p).
CcdResult point_triangle_ccd(const std::array<Eigen::Vector3d, 4>& start, const std::array<Eigen::Vector3d, 4>& end,
                             double separation, int max_iterations = 1000);
CcdResult edge_edge_ccd(const std::array<Eigen::Vector3d, 4>& start, const std::array<Eigen::Vector3d, 4>& end,
                        double separation, int max_iterations = 1000);

}  // namespace clothsim::contact
