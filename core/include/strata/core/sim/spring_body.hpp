#pragma once
/// \file spring_body.hpp
/// The lecture's cheap volume without a tet mesh: a body of springs on its surface and to a curve
/// skeleton inside it (skeleton from meshing/curve_skeleton.hpp).
///
/// Vertices: the surface vertices, then the skeleton vertices. Springs (SpringSet), k = E A / L₀
/// for a bar of cross-section A, with A from this rule:
///   - surface edges: the surface as a membrane of thickness t, k = E t̄ Σ_T A_T / L₀² over the one
///     or two triangles T beside the edge (a triangle lattice of such springs has the in-plane
///     modulus E t for equilateral triangles), t̄ the mean of the edge's vertex thicknesses, and a
///     vertex's thickness t = shell_ratio · ℓ with ℓ its tie length: a thin tube of radius r and
///     thickness r/4 bends like a solid circular section of radius r (I = π r³ t = π r⁴/4);
///   - ties, each surface vertex to the skeleton vertex it collapsed to: a column of material,
///     A = the vertex's area share (a third of its triangles); a skeleton vertex with fewer than 8
///     ties is also tied to its nearest other surface vertices up to 8 (so it cannot swing
///     across its ties);
///   - skeleton segments: the rest of the section's axial stiffness, A = ½ π r̄² (the tube carries
///     the other half of a solid circle's π r²), r̄ the mean tie length at the segment's ends.
/// Skeleton segments shorter than a quarter of the mean segment length are collapsed first (their
/// points merged at their mean).
/// The body's mass is ρ × the enclosed volume, lumped: each surface triangle's wedge to its
/// vertices' skeleton points (volume V_T) gives ¼ V_T to each of its corners and ¼ V_T to those
/// skeleton points; every vertex keeps at least 1 % of the mean vertex mass, and the masses are
/// scaled to ρ V. ν is not represented (a spring network has its own, about ⅓).
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "strata/core/common/types.hpp"
#include "strata/core/fem/material.hpp"
#include "strata/core/sim/dirichlet.hpp"
#include "strata/core/sim/dof_reduction.hpp"
#include "strata/core/sim/ground_contact.hpp"
#include "strata/core/sim/linear_solver.hpp"
#include "strata/core/sim/loads.hpp"
#include "strata/core/sim/newton_solver.hpp"
#include "strata/core/sim/problem_spec.hpp"
#include "strata/core/sim/simulation.hpp"
#include "strata/core/sim/solver_settings.hpp"
#include "strata/core/sim/spring_set.hpp"

namespace strata {

/// Scene "body" of model skeleton_springs: the stiffness rule's factors (defaults: the rule).
struct SpringBodyRule {
  double shell_ratio = 0.25;    ///< t = shell_ratio × tie length
  double surface_scale = 1.0;   ///< × the surface springs' k
  double tie_scale = 1.0;       ///< × the ties' k
  double skeleton_scale = 1.0;  ///< × the skeleton segments' k
};

/// Throws InputError naming `where` unless every factor is positive and finite.
void validate_spring_body_rule(const SpringBodyRule& rule, const std::string& where);

/// Which part of the body a spring belongs to.
enum class SpringKind : std::uint8_t { surface, tie, skeleton };

struct SpringBody {
  MatrixX3d rest;                                     ///< #S surface + #K skeleton vertices [m]
  Index num_surface = 0;                              ///< #S
  MatrixX3i triangles;                                ///< the surface (surface vertex ids)
  std::vector<std::array<int, 2>> skeleton_segments;  ///< body vertex ids
  SpringSet springs;
  std::vector<SpringKind> kinds;  ///< per spring
  VectorXd vertex_mass;           ///< #V [kg]
  double volume = 0.0;            ///< enclosed by the surface [m³]
  Index count(SpringKind kind) const;
};

/// The body of a closed surface (#S × 3, triangles outward) and its skeleton: points (#K × 3),
/// segments (pairs of skeleton indices) and the skeleton vertex of each surface vertex (#S).
/// Throws InputError naming `where` for inconsistent sizes or indices.
SpringBody skeleton_spring_body(ConstRef<MatrixX3d> surface, ConstRef<MatrixX3i> triangles,
                                ConstRef<MatrixX3d> skeleton_points,
                                const std::vector<std::array<int, 2>>& segments,
                                ConstRef<VectorXi> owner, const Material& material,
                                const SpringBodyRule& rule, const std::string& where);

/// Runs a SpringBody with the dynamic integrators (implicit Euler by Newton on the incremental
/// potential, symplectic Euler, RK4), gravity, region loads (on the surface triangles), Dirichlet
/// groups (any body vertex in the region), Rayleigh mass damping α, the ground (projection after
/// each step, as core's GroundPlane) and obstacles: the surface vertices contact them as a tet
/// mesh's boundary vertices do (energy/contact_term.hpp: the barrier and lagged friction in
/// implicit steps, d̂ = solver.contact_distance or 1e-3 × the bounding-box diagonal, κ = E × the
/// mean surface edge length; the projection after explicit steps). An implicit step whose Newton
/// solve fails is retried from its start as 2, 4, 8 or 16 substeps (outputs stay on the scene's
/// time grid). Static mode and stiffness damping are not offered: a spring body has floppy modes no
/// static solve can pin down.
class SpringBodySimulation {
 public:
  /// Throws InputError for static mode, stiffness damping, invalid regions or loads.
  SpringBodySimulation(SpringBody body, ProblemSpec problem, const SolverSettings& settings);

  /// One time step. Throws DivergenceError naming the step for a non-finite state or a failed
  /// Newton solve.
  void advance();
  bool finished() const;
  double time() const { return m_steps * m_settings.dt; }
  long step_count() const { return m_steps; }

  const SpringBody& body() const { return m_body; }
  const VectorXd& positions() const { return m_x; }   ///< 3·#V [m]
  const VectorXd& velocities() const { return m_v; }  ///< 3·#V [m/s]
  double kinetic_energy() const;
  double elastic_energy() const { return m_body.springs.energy(m_x); }
  /// −f_ext(t)ᵀ (x − X) [J].
  double external_potential_energy() const;
  /// Largest stable step of the explicit integrators (Gershgorin bound of M⁻¹K at rest) [s].
  double stable_dt_estimate() const { return m_stable_dt; }
  long newton_iterations() const { return m_newton_iterations; }
  /// Implicit steps whose Newton solve failed and that were taken as substeps instead.
  long substepped_steps() const { return m_substepped_steps; }
  const std::vector<DirichletGroup>& dirichlet_groups() const { return m_groups; }
  /// Per Dirichlet group, the force the constraint exerts on the body, R = −Σ f over its
  /// prescribed DOFs (f: springs, loads and damping now; the prescribed acceleration of a linear
  /// ramp is zero), and its moment about the group's moment center.
  std::vector<GroupReaction> reactions() const;
  /// Obstacles: the contact settings, the largest depth of a surface vertex inside an obstacle
  /// after any step [m], and the vertex–obstacle pairs in contact after each step.
  bool has_obstacles() const { return !m_obstacles.empty(); }
  const ContactSettings& contact_settings() const { return m_contact_settings; }
  double max_penetration() const { return m_max_penetration; }
  const std::vector<Index>& contact_counts() const { return m_contact_counts; }

 private:
  VectorXd forces(const VectorXd& x, const VectorXd& v, double t) const;
  void step_implicit(double t1);
  /// One backward-Euler step of length h ending at t1; false (state unchanged) if Newton fails.
  bool try_implicit(double t1, double h);
  long m_substepped_steps = 0;
  void step_explicit(double t1);
  void apply_constraints(double t, VectorXd& x, VectorXd& v) const;

  SpringBody m_body;
  Material m_material;
  SolverSettings m_settings;
  std::optional<GroundPlane> m_ground;
  std::vector<DirichletGroup> m_groups;
  std::vector<char> m_constrained;
  ExternalLoads m_loads;
  VectorXd m_mass;  ///< 3·#V
  VectorXd m_rest;  ///< 3·#V
  VectorXd m_x, m_v;
  long m_steps = 0;
  double m_stable_dt = 0.0;
  long m_newton_iterations = 0;
  NewtonFailure m_last_failure = NewtonFailure::none;  ///< of the last solve that failed
  SparseMatrixd m_pattern;
  /// Implicit steps: the free-DOF reduction and the solver, kept so that the symbolic
  /// factorisation is done once.
  std::unique_ptr<DofReduction> m_reduction;
  std::unique_ptr<SpdSolver> m_solver;
  std::vector<Obstacle> m_obstacles;
  std::vector<int> m_surface_points;  ///< the contact points: surface vertices 0..#S−1
  ContactSettings m_contact_settings;
  std::unique_ptr<ContactTerm> m_contact;  ///< on the surface vertices, lagged at the last step
  double m_max_penetration = 0.0;
  std::vector<Index> m_contact_counts;
};

}  // namespace strata
