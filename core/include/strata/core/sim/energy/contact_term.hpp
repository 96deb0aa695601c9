#pragma once
/// \file contact_term.hpp
/// Contact with rigid obstacles (obstacle.hpp) as an energy term, the same in static load steps
/// and backward-Euler steps (after IPC: Li et al. 2020).
///
/// Normal contact: the log barrier of every tested vertex against every obstacle,
///   b(d) = −κ (d − d̂)² log(d / d̂) for 0 < d < d̂, 0 for d ≥ d̂, +∞ for d ≤ 0,
/// on d = φ(x) + d̂, with φ the obstacle's signed distance at the end of the step and d̂ the
/// contact tolerance: the barrier acts while a vertex is inside the obstacle (φ < 0) and grows
/// without bound as the depth approaches d̂. b is C² where it starts acting, and Newton's line
/// search (which backtracks from +∞) never accepts a state deeper than d̂: every tested vertex
/// stays within the tolerance, and a body may start exactly touching an obstacle. The Hessian uses
/// b''(d) ∇φ ∇φᵀ (φ's own curvature term is left out; exact for planes), which is PSD.
///
/// Friction: smoothed, lagged Coulomb. For each vertex–obstacle pair within d̂ at the start of the
/// step (φ(x₀) < 0), the normal force λ = −b'(d₀) and a tangent basis T ⊥ ∇φ(x₀) are frozen; the
/// tangential slip of the step u = Tᵀ(x − x₀ − v_o Δt) (v_o the obstacle's velocity) is resisted by
/// the potential μ λ f₀(‖u‖), f₀(y) = y²/ε − y³/(3ε²) + ε/3 below the slip tolerance ε and y above
/// it: full Coulomb force μλ once the slip exceeds ε, a stiff spring below (static friction, with
/// a creep of at most ε per step).
#include <string>
#include <vector>

#include "strata/core/sim/energy/energy_term.hpp"
#include "strata/core/sim/obstacle.hpp"

namespace strata {

/// A point tested for contact: a fixed linear combination Σ w_k q_{v_k} of DOF vertices (a DOF
/// vertex itself, a hanging vertex through its constraint row, or a fine-surface vertex through
/// its binding weights). Its forces reach the DOFs through the same weights.
struct ContactPoint {
  std::vector<int> vertices;  ///< DOF vertices
  std::vector<double> weights;
};

struct ContactSettings {
  double distance = 0.0;       ///< d̂ > 0 [m]: the tolerance, the largest possible depth
  double stiffness = 0.0;      ///< κ > 0 [N/m]
  double friction_slip = 0.0;  ///< ε > 0 [m]: slip per step below which friction sticks
};

class ContactTerm final : public EnergyTerm {
 public:
  /// `vertices`: the DOF vertices tested against every obstacle. `obstacles` must outlive the
  /// term.
  ContactTerm(const std::vector<Obstacle>& obstacles, const std::vector<int>& vertices,
              ContactSettings settings);
  /// `points`: weighted combinations of DOF vertices tested against every obstacle; the Hessian
  /// couples the vertices of a point, which must share a block of the pattern (vertices of one
  /// element, through the embedding).
  ContactTerm(const std::vector<Obstacle>& obstacles, std::vector<ContactPoint> points,
              ContactSettings settings);
  std::string_view name() const override { return "contact"; }

  /// The step from t0 (state q0, 3·#Q) to t1: obstacles are placed at t1, friction is lagged at
  /// q0. Static runs pass t0 = t1 = 0 and the previous load step's state.
  void set_step(ConstRef<VectorXd> q0, double t0, double t1);

  double value(ConstRef<VectorXd> q) const override;
  void add_gradient(ConstRef<VectorXd> q, VectorXd& gradient) const override;
  /// Barrier b'' ∇φ∇φᵀ and friction T M Tᵀ blocks on each contact vertex's diagonal: PSD, so
  /// exact and projected coincide.
  void add_hessian(ConstRef<VectorXd> q, SparseMatrixd& hessian, bool project_psd) const override;

  /// Step filter: about the largest α ≤ 1 at which no point has closed its room r = φ + d̂ (to
  /// the depth d̂) to less than a tenth of its start (at least a twentieth is kept). φ is
  /// 1-Lipschitz, so a point moving by ‖αΔx‖ ≤ 0.9 r₀ cannot, and only the others are followed
  /// along their path: a point moving straight in stops at 0.9 r₀ / ‖Δx‖ as before, a point
  /// sliding along the surface is not held back by its small room. Samples near the surface are
  /// d̂ apart: an obstacle part less than about 3 d̂ thick across the path may be crossed in one
  /// step (the end of a step is always checked: the line search refuses an infeasible one).
  double max_step(ConstRef<VectorXd> q, ConstRef<VectorXd> step) const override;
  /// Adds the barrier's (normal) contact forces −∂b/∂q at the end-of-step placement into `f`;
  /// returns the vertex–obstacle pairs in contact (φ < 0).
  Index add_normal_forces(ConstRef<VectorXd> q, VectorXd& f) const;
  /// Moves the free DOFs of `q` (`constrained`: 3·#Q mask, as Problem::constrained) so that no
  /// point lies deeper than `depth` × d̂ inside an obstacle at the end-of-step placement: each
  /// deeper point is lifted along ∇φ to `to_depth` × d̂ inside (0: to the surface; at most
  /// `depth`) by the least-norm move of its free vertices, the moves of points that share a
  /// vertex averaged there, repeated up to 20 times. Returns the largest move of a vertex [m] (0
  /// when q was feasible). For a start that the barrier's domain excludes: an obstacle that moved
  /// into the body within a step, or a state carried over from another mesh.
  double push_out(VectorXd& q, const std::vector<char>& constrained, double depth,
                  double to_depth = 0.0) const;
  /// Throws InputError "<obstacle>: <point_name> p starts D m inside the obstacle (more than the
  /// contact tolerance d̂ m)" for the first point deeper than d̂ at the end-of-step placement: a
  /// start the barrier cannot take.
  void require_feasible(ConstRef<VectorXd> q, const std::string& point_name) const;
  /// Throws InputError "<obstacle>: mesh vertex v starts D m inside the obstacle: …" for the
  /// first of the mesh positions `x` (3·#V) deeper than d̂ at the end-of-step placement: only
  /// the contact points are tested for contact, so an obstacle that reaches the body's inside
  /// without meeting one (a sphere wholly inside the body) could never act.
  void require_clear_inside(ConstRef<VectorXd> x) const;
  /// The contact force on each point (num_points() entries, summed over the obstacles; zero
  /// where none acts): the barrier's, and with `friction` the lagged friction's too.
  std::vector<Vector3d> point_forces(ConstRef<VectorXd> q, bool friction) const;
  Index num_points() const { return static_cast<Index>(m_points.size()); }
  /// Position of point p at DOF state q.
  Vector3d position(ConstRef<VectorXd> q, Index p) const;
  /// Smallest φ over the tested vertices and the obstacles at the end-of-step placement (+∞
  /// without obstacles).
  double min_distance(ConstRef<VectorXd> q) const;
  const ContactSettings& settings() const { return m_settings; }

  /// b(d), b'(d), b''(d) of d = φ + d̂ for 0 < d < d̂ (0 beyond).
  double barrier(double d) const;
  double barrier_derivative(double d) const;
  double barrier_second_derivative(double d) const;

 private:
  struct FrictionPair {
    int point;
    int obstacle;
    double weight;  ///< μ λ [N]
    Eigen::Matrix<double, 3, 2> basis;
    Vector3d reference;  ///< x₀ + v_o Δt
  };
  /// visit(p, ∂E/∂x_p) for the barrier of every point within d̂ of an obstacle, then (with
  /// `friction`) for every friction pair; a point may be visited more than once.
  template <class Visit>
  void visit_gradients(ConstRef<VectorXd> q, bool friction, Visit&& visit) const;
  const std::vector<Obstacle>& m_obstacles;
  std::vector<ContactPoint> m_points;
  ContactSettings m_settings;
  double m_time = 0.0;
  std::vector<FrictionPair> m_friction;
};

}  // namespace strata
