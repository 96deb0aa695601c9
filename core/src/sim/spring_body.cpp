#include "strata/core/sim/spring_body.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include "strata/core/common/error.hpp"
#include "strata/core/sim/dof_reduction.hpp"
#include "strata/core/sim/energy/external_work_term.hpp"
#include "strata/core/sim/energy/inertia_term.hpp"
#include "strata/core/sim/energy/spring_term.hpp"
#include "strata/core/sim/linear_solver.hpp"
#include "strata/core/sim/newton_solver.hpp"
#include "strata/core/sim/region.hpp"
#include "strata/core/sim/stable_time_step.hpp"

namespace strata {

void validate_spring_body_rule(const SpringBodyRule& rule, const std::string& where) {
  const auto check = [&](double value, const char* key) {
    if (!(value > 0.0) || !std::isfinite(value))
      throw InputError(where + "." + key + ": must be positive and finite");
  };
  check(rule.shell_ratio, "shell_ratio");
  check(rule.surface_scale, "surface_scale");
  check(rule.tie_scale, "tie_scale");
  check(rule.skeleton_scale, "skeleton_scale");
}

Index SpringBody::count(SpringKind kind) const {
  return static_cast<Index>(std::count(kinds.begin(), kinds.end(), kind));
}

SpringBody skeleton_spring_body(ConstRef<MatrixX3d> surface, ConstRef<MatrixX3i> triangles,
                                ConstRef<MatrixX3d> input_points,
                                const std::vector<std::array<int, 2>>& input_segments,
                                ConstRef<VectorXi> input_owner, const Material& material,
                                const SpringBodyRule& rule, const std::string& where) {
  validate_spring_body_rule(rule, where);
  const Index S = surface.rows(), K0 = input_points.rows();
  if (input_owner.size() != S) throw InputError(where + ": one skeleton vertex per surface vertex");
  for (Index i = 0; i < S; ++i)
    if (input_owner[i] < 0 || input_owner[i] >= K0)
      throw InputError(where + ": surface vertex " + std::to_string(i) + " has no skeleton vertex");
  for (Index f = 0; f < triangles.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (triangles(f, k) < 0 || triangles(f, k) >= S)
        throw InputError(where + ": triangle " + std::to_string(f) + " has a bad vertex index");
  for (const auto& [a, b] : input_segments)
    if (a < 0 || a >= K0 || b < 0 || b >= K0 || a == b)
      throw InputError(where + ": a skeleton segment has a bad vertex index");
  const double E = material.youngs_modulus;

  // Segments shorter than a quarter of the mean are collapsed (their stiff springs would only
  // spoil the conditioning): union–find over the short ones, points at their groups' means.
  std::vector<int> group(K0);
  for (Index k = 0; k < K0; ++k)
    group[k] = static_cast<int>(k);
  const auto find = [&](int k) {
    while (group[k] != k)
      k = group[k] = group[group[k]];
    return k;
  };
  double mean_segment = 0.0;
  for (const auto& [a, b] : input_segments)
    mean_segment += (input_points.row(a) - input_points.row(b)).norm();
  if (!input_segments.empty()) mean_segment /= static_cast<double>(input_segments.size());
  for (const auto& [a, b] : input_segments)
    if ((input_points.row(a) - input_points.row(b)).norm() < 0.25 * mean_segment)
      group[find(a)] = find(b);
  std::vector<int> merged(K0, -1);
  Index K = 0;
  for (Index k = 0; k < K0; ++k)
    if (find(static_cast<int>(k)) == k) merged[k] = static_cast<int>(K++);
  MatrixX3d skeleton_points = MatrixX3d::Zero(K, 3);
  VectorXd members = VectorXd::Zero(K);
  for (Index k = 0; k < K0; ++k) {
    const int m = merged[find(static_cast<int>(k))];
    skeleton_points.row(m) += input_points.row(k);
    members[m] += 1.0;
  }
  for (Index m = 0; m < K; ++m)
    skeleton_points.row(m) /= members[m];
  std::vector<std::array<int, 2>> segments;
  for (const auto& [a, b] : input_segments) {
    const int u = merged[find(a)], w = merged[find(b)];
    if (u != w) segments.push_back({std::min(u, w), std::max(u, w)});
  }
  std::sort(segments.begin(), segments.end());
  segments.erase(std::unique(segments.begin(), segments.end()), segments.end());
  VectorXi owner(S);
  for (Index i = 0; i < S; ++i)
    owner[i] = merged[find(input_owner[i])];

  SpringBody body;
  body.num_surface = S;
  body.triangles = triangles;
  body.rest.resize(S + K, 3);
  body.rest.topRows(S) = surface;
  body.rest.bottomRows(K) = skeleton_points;
  const auto tie_length = [&](Index i) {
    return (surface.row(i) - skeleton_points.row(owner[i])).norm();
  };
  // Per surface vertex: area share and thickness; per skeleton vertex: mean tie length.
  VectorXd area_share = VectorXd::Zero(S);
  std::vector<std::array<int, 2>> edges;
  std::vector<double> edge_area;
  for (Index f = 0; f < triangles.rows(); ++f) {
    const Vector3d a = surface.row(triangles(f, 0)).transpose();
    const double area = 0.5 * (surface.row(triangles(f, 1)).transpose() - a)
                                  .cross(surface.row(triangles(f, 2)).transpose() - a)
                                  .norm();
    for (int k = 0; k < 3; ++k) {
      area_share[triangles(f, k)] += area / 3.0;
      const int u = triangles(f, k), w = triangles(f, (k + 1) % 3);
      edges.push_back({std::min(u, w), std::max(u, w)});
      edge_area.push_back(area);
    }
  }
  std::vector<std::size_t> order(edges.size());
  for (std::size_t i = 0; i < order.size(); ++i)
    order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t i, std::size_t j) { return edges[i] < edges[j]; });
  VectorXd radius_sum = VectorXd::Zero(K), radius_count = VectorXd::Zero(K);
  double mean_tie = 0.0;
  for (Index i = 0; i < S; ++i) {
    radius_sum[owner[i]] += tie_length(i);
    radius_count[owner[i]] += 1.0;
    mean_tie += tie_length(i) / static_cast<double>(S);
  }
  const auto radius = [&](int k) {
    return radius_count[k] > 0.0 ? radius_sum[k] / radius_count[k] : mean_tie;
  };
  SpringSet& springs = body.springs;
  std::vector<double> rest, stiffness;
  const auto add = [&](int a, int b, double k, SpringKind kind) {
    const double length = (body.rest.row(a) - body.rest.row(b)).norm();
    if (!(length > 1e-12 * mean_tie) || !(k > 0.0)) return;
    springs.edges.push_back({a, b});
    rest.push_back(length);
    stiffness.push_back(k);
    body.kinds.push_back(kind);
  };
  for (std::size_t n = 0; n < order.size();) {
    const auto edge = edges[order[n]];
    double area = 0.0;
    for (; n < order.size() && edges[order[n]] == edge; ++n)
      area += edge_area[order[n]];
    const double length = (surface.row(edge[0]) - surface.row(edge[1])).norm();
    const double thickness = rule.shell_ratio * 0.5 * (tie_length(edge[0]) + tie_length(edge[1]));
    add(edge[0], edge[1], rule.surface_scale * E * thickness * area / (length * length),
        SpringKind::surface);
  }
  const auto tie = [&](Index i, Index k) {
    const double length = (surface.row(i) - skeleton_points.row(k)).norm();
    if (length > 0.0)
      add(static_cast<int>(i), static_cast<int>(S + k), rule.tie_scale * E * area_share[i] / length,
          SpringKind::tie);
  };
  std::vector<std::vector<Index>> owned(K);
  for (Index i = 0; i < S; ++i) {
    tie(i, owner[i]);
    owned[owner[i]].push_back(i);
  }
  // A skeleton vertex held by fewer ties could swing freely across them: it is also tied to the
  // nearest surface vertices it does not own, up to kMinTies.
  constexpr std::size_t kMinTies = 8;
  for (Index k = 0; k < K; ++k) {
    if (owned[k].size() >= kMinTies || static_cast<std::size_t>(S) <= owned[k].size()) continue;
    std::vector<std::pair<double, Index>> nearest;
    for (Index i = 0; i < S; ++i)
      if (owner[i] != k)
        nearest.push_back({(surface.row(i) - skeleton_points.row(k)).squaredNorm(), i});
    const std::size_t extra = std::min(kMinTies - owned[k].size(), nearest.size());
    std::partial_sort(nearest.begin(), nearest.begin() + static_cast<std::ptrdiff_t>(extra),
                      nearest.end());
    for (std::size_t n = 0; n < extra; ++n)
      tie(nearest[n].second, k);
  }
  for (const auto& [a, b] : segments) {
    const double r = 0.5 * (radius(a) + radius(b));
    const double length = (skeleton_points.row(a) - skeleton_points.row(b)).norm();
    add(static_cast<int>(S + a), static_cast<int>(S + b),
        rule.skeleton_scale * E * 0.5 * std::numbers::pi * r * r / length, SpringKind::skeleton);
    body.skeleton_segments.push_back({static_cast<int>(S + a), static_cast<int>(S + b)});
  }
  springs.rest = Eigen::Map<const VectorXd>(rest.data(), static_cast<Index>(rest.size()));
  springs.stiffness =
      Eigen::Map<const VectorXd>(stiffness.data(), static_cast<Index>(stiffness.size()));

  // Masses: the wedges of the surface triangles to their skeleton points.
  VectorXd mass = VectorXd::Zero(S + K);
  double volume = 0.0;
  for (Index f = 0; f < triangles.rows(); ++f) {
    const Vector3d a = surface.row(triangles(f, 0)).transpose();
    const Vector3d b = surface.row(triangles(f, 1)).transpose();
    const Vector3d c = surface.row(triangles(f, 2)).transpose();
    volume += a.dot(b.cross(c)) / 6.0;
    Vector3d centre = Vector3d::Zero();
    for (int k = 0; k < 3; ++k)
      centre += skeleton_points.row(owner[triangles(f, k)]).transpose() / 3.0;
    const double wedge = std::abs((a - centre).dot((b - centre).cross(c - centre))) / 6.0;
    for (int k = 0; k < 3; ++k) {
      mass[triangles(f, k)] += 0.25 * wedge;
      mass[S + owner[triangles(f, k)]] += wedge / 12.0;
    }
  }
  body.volume = std::abs(volume);
  if (!(body.volume > 0.0)) throw InputError(where + ": the surface encloses no volume");
  const double floor = 0.01 * mass.sum() / static_cast<double>(S + K);
  mass = mass.cwiseMax(floor);
  body.vertex_mass = mass * (material.density * body.volume / mass.sum());
  return body;
}

SpringBodySimulation::SpringBodySimulation(SpringBody body, ProblemSpec problem,
                                           const SolverSettings& settings)
    : m_body(std::move(body)),
      m_material(std::move(problem.material)),
      m_settings(settings),
      m_ground(std::move(problem.ground)),
      m_obstacles(std::move(problem.obstacles)) {
  const std::vector<DirichletSpec>& dirichlet = problem.dirichlet;
  const std::vector<RegionLoad>& loads = problem.loads;
  const Vector3d& gravity = problem.gravity;
  validate_material(m_material, "material");
  validate_solver_settings(m_settings, "solver");
  if (m_settings.mode != SimulationMode::dynamic)
    throw InputError(
        "solver.mode: a skeleton-spring body runs dynamic only (its floppy modes "
        "leave a static solve undetermined)");
  if (m_material.stiffness_damping > 0.0)
    throw InputError(
        "material.damping.stiffness: not available for a skeleton-spring body "
        "(use mass damping)");
  if (m_ground) validate_ground(*m_ground, "ground");
  const Index V = m_body.rest.rows();
  const double tolerance = region_tolerance(m_body.rest);
  m_groups = resolve_dirichlet_groups(dirichlet, m_body.rest, tolerance);
  m_constrained = dirichlet_dof_mask(m_groups, V);
  m_loads =
      external_loads(m_body.rest, m_body.triangles, m_body.vertex_mass, gravity, loads, tolerance);
  m_mass.resize(3 * V);
  m_rest.resize(3 * V);
  for (Index i = 0; i < V; ++i) {
    m_mass.segment<3>(3 * i).setConstant(m_body.vertex_mass[i]);
    m_rest.segment<3>(3 * i) = m_body.rest.row(i).transpose();
  }
  m_x = m_rest;
  m_v = VectorXd::Zero(3 * V);
  // Gershgorin: λ_max(M⁻¹K) ≤ max_i 2 Σ_{springs at i} k / m_i.
  VectorXd stiffness_sum = VectorXd::Zero(V);
  for (Index s = 0; s < m_body.springs.size(); ++s)
    for (int i : m_body.springs.edges[s])
      stiffness_sum[i] += 2.0 * m_body.springs.stiffness[s];
  const double omega2 = stiffness_sum.cwiseQuotient(m_body.vertex_mass).maxCoeff();
  m_stable_dt = explicit_stability_interval(m_settings.integrator) / std::sqrt(omega2);
  std::vector<Eigen::Triplet<double>> triplets;
  m_body.springs.add_pattern(triplets);
  for (Index i = 0; i < 3 * V; ++i)
    triplets.emplace_back(i, i, 0.0);
  if (!m_obstacles.empty())  // the contact Hessian's 3 × 3 block on each surface vertex
    for (Index i = 0; i < m_body.num_surface; ++i)
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          triplets.emplace_back(3 * i + a, 3 * i + b, 0.0);
  m_pattern.resize(3 * V, 3 * V);
  m_pattern.setFromTriplets(triplets.begin(), triplets.end());
  m_pattern.makeCompressed();
  apply_constraints(0.0, m_x, m_v);
  if (!m_obstacles.empty()) {
    for (const Obstacle& obstacle : m_obstacles)
      validate_obstacle(obstacle);
    const double diagonal =
        (m_body.rest.colwise().maxCoeff() - m_body.rest.colwise().minCoeff()).norm();
    const double mean_edge = mean_triangle_edge_length(m_body.rest, m_body.triangles);
    m_contact_settings.distance =
        m_settings.contact.distance > 0.0 ? m_settings.contact.distance : 1e-3 * diagonal;
    m_contact_settings.stiffness = m_material.youngs_modulus * mean_edge;
    m_contact_settings.friction_slip = m_settings.contact.friction_slip > 0.0
                                           ? m_settings.contact.friction_slip
                                           : 1e-3 * m_contact_settings.distance;
    m_surface_points.resize(static_cast<std::size_t>(m_body.num_surface));
    for (Index i = 0; i < m_body.num_surface; ++i)
      m_surface_points[i] = static_cast<int>(i);
    m_contact = std::make_unique<ContactTerm>(m_obstacles, m_surface_points, m_contact_settings);
    m_contact->set_step(m_x, 0.0, 0.0);
    m_contact->require_feasible(m_x, "surface vertex");
  }
}

void SpringBodySimulation::apply_constraints(double t, VectorXd& x, VectorXd& v) const {
  const double T = m_settings.ramp_time > 0.0 ? m_settings.ramp_time : m_settings.duration;
  const double s = std::min(t / T, 1.0);
  apply_dirichlet(m_groups, m_rest, t, s, t < T ? 1.0 / T : 0.0, x, v);
}

VectorXd SpringBodySimulation::forces(const VectorXd& x, const VectorXd& v, double t) const {
  VectorXd f = m_loads.base;
  for (const TimedForces& timed : m_loads.timed)
    f += timed.amplitude.value(t) * timed.forces;
  m_body.springs.add_forces(x, f);
  if (m_material.mass_damping > 0.0) f -= m_material.mass_damping * m_mass.cwiseProduct(v);
  return f;
}

bool SpringBodySimulation::finished() const {
  return m_steps >= planned_steps(m_settings);
}

double SpringBodySimulation::kinetic_energy() const {
  return 0.5 * m_v.dot(m_mass.cwiseProduct(m_v));
}

double SpringBodySimulation::external_potential_energy() const {
  VectorXd f = m_loads.base;
  for (const TimedForces& timed : m_loads.timed)
    f += timed.amplitude.value(time()) * timed.forces;
  return -f.dot(m_x - m_rest);
}

void SpringBodySimulation::step_explicit(double t1) {
  const double h = m_settings.dt, t0 = t1 - h;
  const auto acceleration = [&](const VectorXd& x, const VectorXd& v, double t) {
    VectorXd a = forces(x, v, t).cwiseQuotient(m_mass);
    for (Index i = 0; i < a.size(); ++i)
      if (m_constrained[i]) a[i] = 0.0;
    return a;
  };
  if (m_settings.integrator == Integrator::symplectic_euler) {
    m_v += h * acceleration(m_x, m_v, t0);
    m_x += h * m_v;
  } else {  // RK4
    const VectorXd k1v = acceleration(m_x, m_v, t0), k1x = m_v;
    const VectorXd k2v = acceleration(m_x + 0.5 * h * k1x, m_v + 0.5 * h * k1v, t0 + 0.5 * h);
    const VectorXd k2x = m_v + 0.5 * h * k1v;
    const VectorXd k3v = acceleration(m_x + 0.5 * h * k2x, m_v + 0.5 * h * k2v, t0 + 0.5 * h);
    const VectorXd k3x = m_v + 0.5 * h * k2v;
    const VectorXd k4v = acceleration(m_x + h * k3x, m_v + h * k3v, t1);
    const VectorXd k4x = m_v + h * k3v;
    m_x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
    m_v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
  }
  apply_constraints(t1, m_x, m_v);
}

void SpringBodySimulation::step_implicit(double t1) {
  // A step whose Newton solve fails is retried as 2, 4, 8, 16 substeps from its start.
  if (try_implicit(t1, m_settings.dt)) return;
  const VectorXd x0 = m_x, v0 = m_v;
  for (int n = 2; n <= 16; n *= 2) {
    bool ok = true;
    for (int k = 1; k <= n && ok; ++k)
      ok = try_implicit(t1 - m_settings.dt + k * m_settings.dt / n, m_settings.dt / n);
    if (ok) {
      ++m_substepped_steps;
      return;
    }
    m_x = x0;
    m_v = v0;
  }
  throw DivergenceError("step " + std::to_string(m_steps + 1) + " (t = " + std::to_string(t1) +
                            " s): Newton did not converge, nor in 16 substeps (the last stopped "
                            "at " +
                            describe(m_last_failure) + ")",
                        m_steps + 1, t1);
}

bool SpringBodySimulation::try_implicit(double t1, double h) {
  // Backward Euler with mass damping: (1 + αh)/h² M (q − q̃) = f(q), q̃ = x + h v/(1 + αh).
  const double alpha = m_material.mass_damping;
  const VectorXd mass = (1.0 + alpha * h) * m_mass;
  const VectorXd predicted = m_x + h / (1.0 + alpha * h) * m_v;
  VectorXd f_ext = m_loads.base;
  for (const TimedForces& timed : m_loads.timed)
    f_ext += timed.amplitude.value(t1) * timed.forces;
  EnergySum energy(m_pattern);
  energy.emplace<InertiaTerm>(mass).set_step(predicted, h);
  energy.emplace<SpringTerm>(m_body.springs);
  energy.emplace<ExternalWorkTerm>(f_ext).set_load_factor(1.0);
  ContactTerm* contact = nullptr;
  if (m_contact) {
    contact = &energy.emplace<ContactTerm>(m_obstacles, m_surface_points, m_contact_settings);
    contact->set_step(m_x, t1 - h, t1);
  }
  if (!m_reduction) {
    m_reduction = std::make_unique<DofReduction>(m_pattern, m_constrained);
    m_solver = std::make_unique<SpdSolver>(LinearSolverKind::cholmod);
  }
  VectorXd q = predicted;
  VectorXd v_end = m_v;
  apply_constraints(t1, q, v_end);
  if (contact != nullptr && !std::isfinite(contact->value(q))) {
    // Newton needs a start inside the barrier's domain: the step's start, lifted out of an
    // obstacle that moved into it.
    q = m_x;
    apply_constraints(t1, q, v_end);
    if (!std::isfinite(contact->value(q))) contact->push_out(q, m_constrained, 0.5);
  }
  VectorXd f_int = VectorXd::Zero(q.size());
  m_body.springs.add_forces(q, f_int);
  NewtonSettings settings;
  settings.max_iterations = newton_iteration_limit(m_settings, m_contact != nullptr);
  settings.tolerance = m_settings.newton.tolerance;
  settings.exact_hessian = m_settings.newton.exact_hessian;
  settings.force_scale = f_int.norm() + f_ext.norm() + m_mass.cwiseProduct(m_v).norm() / h +
                         mass.cwiseProduct(q - predicted).norm() / (h * h);
  const double size = (m_body.rest.colwise().maxCoeff() - m_body.rest.colwise().minCoeff()).norm();
  settings.step_tolerance = 1e-13 * size;
  // Round-off of the spring forces: ε k L₀ per spring, accumulated over the DOFs.
  settings.residual_floor = 1e3 * std::numeric_limits<double>::epsilon() *
                            m_body.springs.stiffness.cwiseProduct(m_body.springs.rest).maxCoeff() *
                            std::sqrt(static_cast<double>(q.size()));
  settings.rest_positions = &m_rest;
  settings.energy_scale = m_body.springs.stiffness.sum() * size * size * 1e-6 +
                          std::abs(f_ext.dot(q)) + m_mass.sum() * size * size / (h * h) * 1e-6;
  const NewtonResult result = newton_minimize(energy, *m_reduction, *m_solver, settings, q);
  m_newton_iterations += result.iterations;
  if (!result.converged) {
    m_last_failure = result.failure;
    return false;
  }
  m_v = (q - m_x) / h;
  m_x = q;
  apply_constraints(t1, m_x, m_v);
  return true;
}

std::vector<GroupReaction> SpringBodySimulation::reactions() const {
  VectorXd f = forces(m_x, m_v, time());
  if (m_contact) {
    VectorXd gradient = VectorXd::Zero(f.size());
    m_contact->add_gradient(m_x, gradient);
    f -= gradient;
  }
  std::vector<GroupReaction> result;
  for (const DirichletGroup& group : m_groups) {
    GroupReaction reaction;
    reaction.name = group.spec.name;
    reaction.moment_center = group.moment_center;
    for (int i : group.vertices) {
      Vector3d r = Vector3d::Zero();
      for (int c = 0; c < 3; ++c)
        if (group.spec.components[c]) r[c] = -f[3 * i + c];
      reaction.force += r;
      reaction.moment += (m_x.segment<3>(3 * i) - group.moment_center).cross(r);
    }
    result.push_back(reaction);
  }
  return result;
}

void SpringBodySimulation::advance() {
  if (finished()) throw std::logic_error("SpringBodySimulation::advance: finished");
  const double t1 = (m_steps + 1) * m_settings.dt;
  const VectorXd x_start = m_x;
  if (m_settings.integrator == Integrator::implicit_euler) {
    step_implicit(t1);
  } else {
    step_explicit(t1);
    if (m_contact) project_obstacle_contact(m_obstacles, t1, m_x, m_v, m_constrained);
  }
  if (m_ground) project_ground_contact(*m_ground, m_x, m_v, m_constrained);
  if (m_contact) {
    m_contact->set_step(x_start, t1 - m_settings.dt, t1);
    m_max_penetration = std::max(m_max_penetration, -m_contact->min_distance(m_x));
    VectorXd unused = VectorXd::Zero(m_x.size());
    m_contact_counts.push_back(m_contact->add_normal_forces(m_x, unused));
  }
  ++m_steps;
  if (!m_x.allFinite() || !m_v.allFinite())
    throw DivergenceError("step " + std::to_string(m_steps) + " (t = " + std::to_string(t1) +
                              " s): the state is no longer finite (reduce solver.dt or use "
                              "implicit_euler; stable estimate " +
                              std::to_string(m_stable_dt) + " s)",
                          m_steps, t1);
}

}  // namespace strata
