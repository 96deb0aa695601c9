#include "strata/core/sim/simulation.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "strata/core/common/error.hpp"
#include "strata/core/fem/lumped_mass.hpp"
#include "strata/core/sim/newton_solver.hpp"
#include "strata/core/sim/problem.hpp"
#include "strata/core/sim/stable_time_step.hpp"
#include "strata/core/sim/steppers/time_stepper.hpp"

namespace strata {

namespace {

const MatrixX3i kNoFaces;  ///< the boundary of a scene without region loads: none needed

using Clock = std::chrono::steady_clock;

/// Seconds since `start`, and `start` moved to now.
double lap(Clock::time_point& start) {
  const Clock::time_point now = Clock::now();
  const double seconds = std::chrono::duration<double>(now - start).count();
  start = now;
  return seconds;
}

std::string format_number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.3g", value);
  return buffer;
}

}  // namespace

Simulation::Simulation(TetMesh mesh, ProblemSpec problem, const SolverSettings& settings,
                       SimulationOptions options)
    : m_mesh(std::move(mesh)),
      m_material(std::move(problem.material)),
      m_settings(settings),
      m_ground(std::move(problem.ground)) {
  const std::vector<DirichletSpec>& dirichlet = problem.dirichlet;
  const std::vector<RegionLoad>& loads = problem.loads;
  const Vector3d& gravity = problem.gravity;
  validate_material(m_material, "material");
  validate_solver_settings(m_settings, "solver");
  if (m_ground) validate_ground(*m_ground, "ground");
  if (!gravity.allFinite()) throw InputError("gravity: must be finite");
  if (options.first_step < 0) throw InputError("simulation: first_step must be >= 0");
  std::vector<char> referenced(m_mesh.vertices.rows(), 0);
  for (Index t = 0; t < m_mesh.tets.rows(); ++t)
    for (int k = 0; k < 4; ++k) {
      const int v = m_mesh.tets(t, k);
      if (v < 0 || v >= m_mesh.vertices.rows())
        throw InputError("mesh: tet " + std::to_string(t) + " references vertex " +
                         std::to_string(v) + " (mesh has " +
                         std::to_string(m_mesh.vertices.rows()) + " vertices)");
      referenced[v] = 1;
    }
  for (size_t v = 0; v < referenced.size(); ++v)
    if (!referenced[v])
      throw InputError("mesh: vertex " + std::to_string(v) + " belongs to no tet");
  m_stepper_traits = &find_stepper(m_settings);
  if (is_static() && dirichlet.empty())
    throw InputError(
        "dirichlet: static mode needs at least one Dirichlet group against rigid motion");

  Clock::time_point phase = Clock::now();
  m_model = std::make_unique<ElasticModel>(m_mesh.vertices, m_mesh.tets, m_material);
  m_build_seconds.elastic_model = lap(phase);
  if (options.dof_vertices.empty())
    m_embedded = std::make_unique<EmbeddedElasticModel>(*m_model);
  else
    m_embedded = std::make_unique<EmbeddedElasticModel>(
        *m_model, std::move(options.vertex_embedding), std::move(options.dof_vertices));
  m_build_seconds.reduced_model = lap(phase);
  const Index num_vertices = m_mesh.vertices.rows();
  const Index num_dof_vertices = m_embedded->num_dof_vertices();
  m_vertex_mass = lumped_vertex_mass(m_model->rest_data().rest_volume, m_mesh.tets, num_vertices,
                                     m_material.density);
  m_dof_vertex_mass = m_embedded->reduce_vertex_scalar(m_vertex_mass);
  m_dof_mass = per_dof_mass(m_dof_vertex_mass);

  const auto [lo, hi] = bounding_box(m_mesh.vertices);
  m_diagonal = (hi - lo).norm();
  const double tolerance = region_tolerance(m_mesh.vertices);
  const MatrixX3d dof_rest = unflatten(m_embedded->rest_positions());
  m_groups = resolve_dirichlet_groups(dirichlet, dof_rest, tolerance);
  m_constrained = dirichlet_dof_mask(m_groups, num_dof_vertices);
  ExternalLoads mesh_loads = external_loads(m_mesh.vertices, loads.empty() ? kNoFaces : boundary(),
                                            m_vertex_mass, gravity, loads, tolerance);
  VectorXd& mesh_external = mesh_loads.base;
  if (options.extra_mesh_forces.size() > 0) {
    if (options.extra_mesh_forces.size() != mesh_external.size() ||
        !options.extra_mesh_forces.allFinite())
      throw InputError("simulation: extra_mesh_forces must be 3·#V finite values");
    mesh_external += options.extra_mesh_forces;
  }
  m_external = m_embedded->reduce(mesh_external);
  // Finite inputs whose products or norms overflow (gravity 1e308 times a mass) would pass
  // every convergence test at once.
  if (!m_vertex_mass.allFinite() || !std::isfinite(m_external.squaredNorm()))
    throw InputError(
        "loads: the masses or the loads (gravity × mass, region forces) overflow a double; check "
        "gravity, density and the forces' magnitudes");
  for (TimedForces& timed : options.extra_timed_mesh_forces) {
    validate_amplitude(timed.amplitude, "simulation: extra_timed_mesh_forces");
    if (timed.amplitude.empty() || timed.forces.size() != mesh_external.size() ||
        !timed.forces.allFinite())
      throw InputError(
          "simulation: extra_timed_mesh_forces need an amplitude and 3·#V finite values");
    mesh_loads.timed.push_back(std::move(timed));
  }
  for (const TimedForces& timed : mesh_loads.timed)
    m_timed.push_back({timed.amplitude, m_embedded->reduce(timed.forces)});
  m_limits = default_divergence_limits(m_material, m_diagonal);
  if (m_ground)
    m_ground_stiffness =
        ground_penalty_stiffness(m_material.youngs_modulus, m_embedded->mean_edge_length(),
                                 m_settings.contact.ground_stiffness_factor);

  if (!(options.max_angular_frequency >= 0.0) || !std::isfinite(options.max_angular_frequency))
    throw InputError("simulation: max_angular_frequency must be finite and >= 0");
  m_max_angular_frequency = options.max_angular_frequency;
  m_first_step = options.first_step;
  m_steps = m_first_step;
  if (!options.nested_spaces.empty()) {
    if (options.nested_spaces.num_fine_vertices() != num_dof_vertices)
      throw InputError("simulation: nested_spaces must end on the " +
                       std::to_string(num_dof_vertices) + " DOF vertices");
    options.nested_spaces.check();
    m_nested = std::move(options.nested_spaces);
    m_smoother_seed = std::move(options.smoother_estimates);
    m_coarse_seed = std::move(options.coarse_levels);
  }
  if (m_material.plasticity) {
    m_plastic = PlasticState::identity(m_mesh.tets.rows());
    if (!options.plastic_state.empty()) set_plastic_state(std::move(options.plastic_state));
  } else if (!options.plastic_state.empty()) {
    throw InputError("simulation: plastic_state given for a material without plasticity");
  }
  if (options.surface_springs) {
    if (!m_embedded->is_identity())
      throw InputError("material.surface_springs: not supported on a mesh with hanging vertices");
    m_springs =
        std::make_unique<SurfaceSprings>(m_mesh.vertices, boundary(), *options.surface_springs);
  }
  ContactSettings contact;
  if (!problem.obstacles.empty()) {
    m_obstacles = std::move(problem.obstacles);
    for (const Obstacle& obstacle : m_obstacles)
      validate_obstacle(obstacle);
    // Contact points on the mesh: every boundary vertex (unless the options leave them out), then
    // the extra points; each carried to the DOFs through the embedding's rows (a hanging vertex by
    // its constraint).
    std::vector<ContactPoint> mesh_points;
    if (options.boundary_contact_points) {
      std::vector<char> on_boundary(num_vertices, 0);
      const MatrixX3i& faces = boundary();
      for (Index f = 0; f < faces.rows(); ++f)
        for (int k = 0; k < 3; ++k)
          on_boundary[faces(f, k)] = 1;
      for (Index v = 0; v < num_vertices; ++v)
        if (on_boundary[v]) mesh_points.push_back({{static_cast<int>(v)}, {1.0}});
    }
    for (const ContactPoint& point : options.contact_points) {
      if (point.vertices.empty() || point.vertices.size() != point.weights.size())
        throw InputError("simulation: a contact point needs one weight per vertex");
      for (int v : point.vertices)
        if (v < 0 || v >= num_vertices)
          throw InputError("simulation: contact point vertex " + std::to_string(v) +
                           " is not a mesh vertex");
      mesh_points.push_back(point);
    }
    m_extra_contact_points = static_cast<Index>(options.contact_points.size());
    m_contact_points = embed_points(mesh_points);
    m_mesh_contact_points = std::move(mesh_points);
    contact.distance =
        m_settings.contact.distance > 0.0 ? m_settings.contact.distance : 1e-3 * m_diagonal;
    if (!(options.contact_stiffness >= 0.0) || !std::isfinite(options.contact_stiffness))
      throw InputError("simulation: contact_stiffness must be finite and >= 0");
    contact.stiffness = options.contact_stiffness > 0.0
                            ? options.contact_stiffness
                            : m_material.youngs_modulus * m_embedded->mean_edge_length();
    contact.friction_slip = m_settings.contact.friction_slip > 0.0
                                ? m_settings.contact.friction_slip
                                : 1e-3 * contact.distance;
    m_contact = std::make_unique<ContactTerm>(m_obstacles, m_contact_points, contact);
  }
  m_x = m_embedded->rest_positions();
  m_v = VectorXd::Zero(m_x.size());
  const double ramp_time = m_settings.ramp_time > 0.0 ? m_settings.ramp_time : m_settings.duration;
  m_system.reset(new Problem{.model = *m_embedded,
                             .dof_mass = m_dof_mass,
                             .external_forces = m_external,
                             .groups = m_groups,
                             .constrained = m_constrained,
                             .mass_damping = m_material.mass_damping,
                             .stiffness_damping = m_material.stiffness_damping,
                             .ramp_time = ramp_time,
                             .diagonal = m_diagonal,
                             .ground = m_ground ? &*m_ground : nullptr,
                             .ground_stiffness = m_ground_stiffness,
                             .nested_spaces = m_nested.empty() ? nullptr : &m_nested,
                             .smoother_estimates = &m_smoother_seed,
                             .coarse_levels = &m_coarse_seed,
                             .timed_forces = &m_timed,
                             .springs = m_springs.get(),
                             .obstacles = &m_obstacles,
                             .contact_points = &m_contact_points,
                             .contact = contact});
  m_build_seconds.problem = lap(phase);
  m_stepper = m_stepper_traits->make(*m_system, m_settings);
  m_coarse_seed.reset();  // the solver holds them now, until its first setup
  m_build_seconds.stepper = lap(phase);
  if (is_static()) {
    if (m_steps > 0) apply_dirichlet(m_groups, m_x, load_factor(), load_factor(), 0.0, m_x, m_v);
    m_v.setZero();
  } else {
    m_system->apply_constraints(time(), m_x, m_v);
  }
  update_mesh_state();
  // A run that continues from an earlier step (first_step > 0) takes its state from set_state:
  // its rest state need not be feasible at the current time.
  if (m_contact && m_first_step == 0) {
    const double t = is_static() ? 0.0 : time();
    m_contact->set_step(m_x, t, t);
    m_contact->require_feasible(m_x, "contact point");
    m_contact->require_clear_inside(positions());
  }
}

const MatrixX3i& Simulation::boundary() const {
  std::call_once(m_boundary_once, [&] { m_boundary = boundary_faces(m_mesh.tets); });
  return m_boundary;
}

double Simulation::stable_dt_estimate() const {
  std::call_once(m_stable_dt_once, [&] {
    m_stable_dt = m_max_angular_frequency > 0.0
                      ? explicit_stability_interval(m_settings.integrator) / m_max_angular_frequency
                      : stable_time_step_estimate(m_mesh.vertices, m_mesh.tets, m_material,
                                                  m_settings.integrator);
  });
  return m_stable_dt;
}

const ContactSettings& Simulation::contact_settings() const {
  return m_system->contact;
}

void Simulation::update_mesh_state() {
  if (m_embedded->is_identity()) return;
  m_mesh_x = m_embedded->expand(m_x);
  m_mesh_v = m_embedded->expand(m_v);
}

Simulation::~Simulation() = default;

bool Simulation::is_static() const {
  return m_stepper_traits->mode == SimulationMode::static_equilibrium;
}

void Simulation::set_state(ConstRef<VectorXd> positions, ConstRef<VectorXd> velocities) {
  if (positions.size() != m_x.size() || velocities.size() != m_v.size())
    throw InputError("initial state: expected " + std::to_string(m_x.size()) +
                     " position and velocity entries");
  if (!positions.allFinite() || !velocities.allFinite())
    throw InputError("initial state: positions and velocities must be finite");
  m_x = positions;
  m_v = is_static() ? VectorXd::Zero(m_v.size()) : VectorXd(velocities);
  m_stepper->reset_history();
  clear_projection();
  if (is_static()) {
    apply_dirichlet(m_groups, m_embedded->rest_positions(), load_factor(), load_factor(), 0.0, m_x,
                    m_v);
    m_v.setZero();
  } else {
    m_system->apply_constraints(time(), m_x, m_v);
  }
  update_mesh_state();
}

double Simulation::time() const {
  if (is_static()) return load_factor();
  return static_cast<double>(m_steps) * m_settings.dt;
}

double Simulation::load_factor() const {
  if (is_static()) return static_cast<double>(m_steps) / static_cast<double>(m_settings.load_steps);
  return m_system->ramp(time());
}

bool Simulation::finished() const {
  return m_steps >= planned_steps(m_settings);
}

void Simulation::advance() {
  STRATA_VERIFY(!finished(), "Simulation::advance called after the run finished");
  const double t0 = time();
  const double t1 = is_static() ? static_cast<double>(m_steps + 1) / m_settings.load_steps
                                : static_cast<double>(m_steps + 1) * m_settings.dt;
  const double h = is_static() ? t1 - t0 : m_settings.dt;
  VectorXd q_start, v_start;
  if ((is_plastic() && !m_stepper_traits->is_explicit) || has_obstacles()) {
    q_start = m_x;
    v_start = m_v;
  }
  const NewtonResult result = m_stepper->step(t0, t1, h, m_x, m_v);
  record_newton(result);
  if (!result.converged) throw_newton_failure(std::string(m_stepper_traits->name), result);
  if (m_ground && !is_static()) project_ground_contact(*m_ground, m_x, m_v, m_constrained);
  if (has_obstacles() && m_stepper_traits->is_explicit) {
    const VectorXd v_before = m_v;
    m_projected_contacts =
        project_obstacle_contact(m_obstacles, t1, m_x, m_v, m_constrained, &m_projection_depth);
    m_projection_forces = m_dof_mass.cwiseProduct(m_v - v_before) / h;
  }
  update_mesh_state();
  if (is_plastic()) update_plastic_state(t0, t1, h, q_start, v_start);
  if (has_obstacles()) record_contact(q_start, is_static() ? 0.0 : t0, is_static() ? 0.0 : t1);
  if (m_springs) m_springs->yield(m_x);
  ++m_steps;
  if (has_obstacles()) m_contact_step = m_steps;
  // Where the next step starts with the forces at this state, the stepper computes them now and
  // the inversion check comes from the same pass over the tets.
  std::optional<std::pair<double, Index>> volume_ratio;
  if (m_limits.check_inversion && !finished()) volume_ratio = m_stepper->prepare_next_step(m_x);
  check_divergence(*m_model, positions(), is_static() ? VectorXd() : velocities(), m_limits,
                   m_steps, time(), std::string(m_stepper_traits->name),
                   volume_ratio ? &*volume_ratio : nullptr);
}

std::vector<ContactPoint> Simulation::embed_points(const std::vector<ContactPoint>& points) const {
  if (m_embedded->is_identity()) return points;
  const Eigen::SparseMatrix<double, Eigen::RowMajor> C = m_embedded->vertex_embedding();
  std::vector<ContactPoint> embedded;
  embedded.reserve(points.size());
  for (const ContactPoint& point : points) {
    std::vector<std::pair<int, double>> terms;
    for (size_t k = 0; k < point.vertices.size(); ++k)
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(C, point.vertices[k]); it;
           ++it)
        terms.emplace_back(static_cast<int>(it.col()), point.weights[k] * it.value());
    std::sort(terms.begin(), terms.end());
    ContactPoint result;
    for (const auto& [q, w] : terms) {
      if (!result.vertices.empty() && result.vertices.back() == q) {
        result.weights.back() += w;
      } else {
        result.vertices.push_back(q);
        result.weights.push_back(w);
      }
    }
    embedded.push_back(std::move(result));
  }
  return embedded;
}

void Simulation::record_contact(const VectorXd& q_start, double t0, double t1) {
  m_contact->set_step(q_start, t0, t1);
  if (m_stepper_traits->is_explicit) {
    // The projection has moved every vertex out: what it found is the step's contact.
    m_last_penetration = m_projection_depth;
    m_max_penetration = std::max(m_max_penetration, m_last_penetration);
    m_contact_counts.push_back(m_projected_contacts);
    return;
  }
  m_last_penetration = -m_contact->min_distance(m_x);
  m_max_penetration = std::max(m_max_penetration, m_last_penetration);
  VectorXd unused = VectorXd::Zero(m_x.size());
  m_contact_counts.push_back(m_contact->add_normal_forces(m_x, unused));
}

VectorXd Simulation::mesh_contact_forces() const {
  VectorXd f = VectorXd::Zero(3 * m_mesh.vertices.rows());
  if (!m_contact) return f;
  if (m_stepper_traits->is_explicit) return m_embedded->at_dof_vertices(contact_forces());
  const std::vector<Vector3d> point_forces = m_contact->point_forces(m_x, false);
  for (size_t p = 0; p < point_forces.size(); ++p) {
    if (point_forces[p].isZero()) continue;
    const ContactPoint& point = m_mesh_contact_points[p];
    for (size_t k = 0; k < point.vertices.size(); ++k)
      f.segment<3>(3 * point.vertices[k]) += point.weights[k] * point_forces[p];
  }
  return f;
}

std::vector<Vector3d> Simulation::surface_contact_forces() const {
  if (!m_contact) return {};
  std::vector<Vector3d> forces = m_contact->point_forces(m_x, true);
  forces.erase(forces.begin(), forces.end() - m_extra_contact_points);
  return forces;
}

double Simulation::push_out_of_obstacles(double depth, double to_depth) {
  if (!m_contact) return 0.0;
  const double t = is_static() ? 0.0 : time();
  m_contact->set_step(m_x, t, t);
  const double largest = m_contact->push_out(m_x, m_constrained, depth, to_depth);
  if (largest > 0.0) {
    clear_projection();
    update_mesh_state();
    m_stepper->reset_history();  // forces kept for the next step were at the old positions
  }
  return largest;
}

void Simulation::clear_projection() {
  m_projected_contacts = 0;
  m_projection_depth = 0.0;
  m_projection_forces.resize(0);
}

VectorXd Simulation::contact_forces() const {
  if (m_contact && m_stepper_traits->is_explicit)
    return m_projection_forces.size() == m_x.size() ? m_projection_forces
                                                    : VectorXd::Zero(m_x.size());
  VectorXd gradient = VectorXd::Zero(m_x.size());
  if (m_contact) m_contact->add_gradient(m_x, gradient);
  return -gradient;
}

void Simulation::set_plastic_state(PlasticState state) {
  if (!is_plastic())
    throw InputError("simulation: plastic state for a material without plasticity");
  if (state.num_tets() != m_mesh.tets.rows() ||
      static_cast<Index>(state.plastic_inverse.size()) != m_mesh.tets.rows())
    throw InputError("simulation: plastic state must hold " + std::to_string(m_mesh.tets.rows()) +
                     " tets");
  m_plastic = std::move(state);
  m_model->set_plastic_inverse(m_plastic.plastic_inverse);
  if (m_stepper) m_stepper->reset_history();  // the constructor sets it before the stepper exists
}

namespace {

/// A plastic state as one vector: ε̄ₚ of every tet, then the 9 entries of every Fₚ⁻¹.
VectorXd pack(const PlasticState& state) {
  const Index n = state.num_tets();
  VectorXd z(10 * n);
  z.head(n) = state.equivalent_strain;
  for (Index t = 0; t < n; ++t)
    z.segment<9>(n + 9 * t) = Eigen::Map<const Vector9d>(state.plastic_inverse[t].data());
  return z;
}

/// The inverse of pack, with each Fₚ⁻¹ scaled back to det 1 and ε̄ₚ kept at or above `floor`.
void unpack(ConstRef<VectorXd> z, const VectorXd& floor, PlasticState& state) {
  const Index n = state.num_tets();
  state.equivalent_strain = z.head(n).cwiseMax(floor);
  for (Index t = 0; t < n; ++t) {
    Matrix3d inverse = Eigen::Map<const Matrix3d>(z.data() + n + 9 * t);
    const double det = inverse.determinant();
    if (det > 0.0) inverse /= std::cbrt(det);
    state.plastic_inverse[t] = inverse;
  }
}

}  // namespace

void Simulation::update_plastic_state(double t0, double t1, double h, const VectorXd& q_start,
                                      const VectorXd& v_start) {
  // Fixed point of "solve with the plastic state, return-map from the start-of-step state": each
  // solve sees the elastic stiffness, so plain iteration contracts only by 1 − E_t/E per pass
  // (E_t the elastoplastic tangent). Aitken's dynamic relaxation (Irons & Tuck 1969) of the
  // state update makes it a few passes; the accepted state is always a plain return mapping.
  const Plasticity& plasticity = *m_material.plasticity;
  const PlasticState start = m_plastic;
  const double tolerance =
      m_settings.plasticity.tolerance * plasticity.yield_stress / m_material.youngs_modulus;
  const Index num_tets = start.num_tets();
  VectorXd used = pack(start);  // the state the last solve used
  VectorXd previous_residual;
  double relaxation = 1.0;
  for (int pass = 1;; ++pass) {
    Index yielded = 0;
    PlasticState mapped = return_map(*m_model, positions(), start, plasticity, &yielded);
    ++m_newton.plastic_passes;
    m_newton.yielded_tets = yielded;
    const VectorXd image = pack(mapped);
    const VectorXd residual = image - used;
    const double change = num_tets == 0 ? 0.0 : residual.head(num_tets).cwiseAbs().maxCoeff();
    const bool last = m_stepper_traits->is_explicit || change <= tolerance ||
                      pass >= m_settings.plasticity.max_passes;
    if (last) {
      if (!(m_stepper_traits->is_explicit || change <= tolerance))
        ++m_newton.plastic_unconverged_steps;
      m_plastic = std::move(mapped);
      m_model->set_plastic_inverse(m_plastic.plastic_inverse);
      return;
    }
    if (previous_residual.size() > 0) {
      const VectorXd difference = residual - previous_residual;
      const double denominator = difference.squaredNorm();
      if (denominator > 0.0)
        relaxation =
            std::clamp(-relaxation * previous_residual.dot(difference) / denominator, 0.1, 100.0);
    }
    previous_residual = residual;
    used += relaxation * residual;
    unpack(used, start.equivalent_strain, m_plastic);
    used = pack(m_plastic);
    m_model->set_plastic_inverse(m_plastic.plastic_inverse);
    // The step again, with the relaxed plastic state.
    NewtonResult result;
    if (is_static()) {
      result = m_stepper->resolve(t1, m_x, m_v, VectorXd());
    } else {
      m_x = q_start;
      m_v = v_start;
      result = m_stepper->step(t0, t1, h, m_x, m_v);
    }
    record_newton(result);
    if (!result.converged)
      throw_newton_failure(
          std::string(m_stepper_traits->name) + " (plastic pass " + std::to_string(pass + 1) + ")",
          result);
    if (m_ground && !is_static()) project_ground_contact(*m_ground, m_x, m_v, m_constrained);
    update_mesh_state();
  }
}

void Simulation::throw_newton_failure(const std::string& context,
                                      const NewtonResult& result) const {
  const long step = m_steps + 1;
  const double t = is_static() ? static_cast<double>(step) / m_settings.load_steps
                               : static_cast<double>(step) * m_settings.dt;
  throw DivergenceError(context + ": Newton did not converge at step " + std::to_string(step) +
                            (is_static() ? ", load factor " : ", t = ") + std::to_string(t) +
                            newton_failure_detail(result, t),
                        step, t);
}

std::string Simulation::newton_failure_detail(const NewtonResult& result, double t) const {
  std::string reason = describe(result.failure);
  if (!reason.empty()) reason = ", stopped at " + reason;
  return " after " + std::to_string(result.iterations) + " iterations (gradient norm " +
         format_number(result.residual) + " N)" + reason + held_contact(t);
}

std::string Simulation::held_contact(double t) const {
  if (!has_obstacles()) return "";
  // The held DOFs where the failed solve put them: their targets at t (the load factor in static
  // runs, whose obstacles stand still).
  VectorXd x = m_x, v = m_v;
  if (is_static())
    apply_dirichlet(m_groups, m_embedded->rest_positions(), t, t, 0.0, x, v);
  else
    m_system->apply_constraints(t, x, v);
  const double obstacle_time = is_static() ? 0.0 : t;
  // The barrier is infinite where a point is d̂ deep (energy/contact_term.hpp): no step moves a
  // point whose weighted DOF vertices are all held.
  const double depth = contact_settings().distance;
  for (const ContactPoint& point : m_contact_points) {
    bool held = true;
    int holder = -1;  // a DOF vertex of the point with a weight
    Vector3d p = Vector3d::Zero();
    for (std::size_t k = 0; k < point.vertices.size(); ++k) {
      const Index q = point.vertices[k];
      p += point.weights[k] * x.segment<3>(3 * q);
      if (std::abs(point.weights[k]) < 1e-9) continue;  // a point on the face opposite q
      held = held && m_constrained[3 * q] && m_constrained[3 * q + 1] && m_constrained[3 * q + 2];
      holder = point.vertices[k];
    }
    if (!held || holder < 0) continue;
    for (const Obstacle& obstacle : m_obstacles) {
      Vector3d gradient;
      if (!(obstacle.distance_at(p, obstacle_time, gradient) + depth <= 0.0)) continue;
      std::string group = "a Dirichlet group";
      for (const DirichletGroup& g : m_groups)
        if (std::binary_search(g.vertices.begin(), g.vertices.end(), holder)) {
          group = g.spec.name;
          break;
        }
      return "; " + obstacle.name + " has reached a point held by " + group + " at (" +
             format_number(p.x()) + ", " + format_number(p.y()) + ", " + format_number(p.z()) +
             ") deeper than its contact distance (" + format_number(depth) +
             " m), which the point cannot give way to";
    }
  }
  return "";
}

void Simulation::resolve_static(const VectorXd& contact_reference) {
  STRATA_VERIFY(is_static() && m_steps > 0,
                "Simulation::resolve_static needs static mode after a load step");
  const double lambda = load_factor();
  const NewtonResult result = m_stepper->resolve(lambda, m_x, m_v, contact_reference);
  record_newton(result);
  if (!result.converged)
    throw DivergenceError("static: Newton did not converge re-solving load step " +
                              std::to_string(m_steps) + ", load factor " + std::to_string(lambda) +
                              newton_failure_detail(result, lambda),
                          m_steps, lambda);
  update_mesh_state();
  // Plastic flow from the carried state, with further passes until it settles.
  if (is_plastic()) update_plastic_state(lambda, lambda, 0.0, m_x, m_v);
  if (has_obstacles()) {
    // The re-solved state replaces this load step's contact record (a rebuilt Simulation has
    // none yet).
    const VectorXd q_start = m_x;
    if (m_contact_step == m_steps && !m_contact_counts.empty()) m_contact_counts.pop_back();
    record_contact(q_start, 0.0, 0.0);
    m_contact_step = m_steps;
  }
  check_divergence(*m_model, positions(), VectorXd(), m_limits, m_steps, lambda, "static");
}

std::vector<GroupReaction> Simulation::reactions() const {
  VectorXd f_int;
  m_embedded->forces(m_x, f_int);
  VectorXd f = f_int;
  if (m_springs) m_springs->add_forces(m_x, f);
  if (m_contact) f += contact_forces();
  VectorXd mass_times_acceleration = VectorXd::Zero(m_x.size());
  if (is_static()) {
    f += current_external_forces();
    if (m_ground) {
      VectorXd penalty_gradient = VectorXd::Zero(m_x.size());
      add_ground_penalty_gradient(*m_ground, m_ground_stiffness, m_x, penalty_gradient);
      f -= penalty_gradient;
    }
  } else {
    f += current_external_forces();
    m_system->add_damping_forces(m_x, m_v, f_int, f);
    m_system->accelerations(time(), m_x, m_v, mass_times_acceleration);
    mass_times_acceleration.array() *= m_dof_mass.array();
  }
  std::vector<GroupReaction> reactions;
  for (const DirichletGroup& group : m_groups) {
    GroupReaction reaction;
    reaction.name = group.spec.name;
    reaction.moment_center = group.moment_center;
    for (int v : group.vertices) {
      Vector3d r = mass_times_acceleration.segment<3>(3 * v) - f.segment<3>(3 * v);
      for (int c = 0; c < 3; ++c)
        if (!group.spec.components[c]) r[c] = 0.0;  // free coordinates carry no reaction
      reaction.force += r;
      reaction.moment += (m_x.segment<3>(3 * v) - group.moment_center).cross(r);
    }
    reactions.push_back(reaction);
  }
  return reactions;
}

double Simulation::kinetic_energy() const {
  return 0.5 * m_v.dot(m_dof_mass.cwiseProduct(m_v));
}

double Simulation::elastic_energy() const {
  return m_embedded->energy(m_x) + (m_springs ? m_springs->energy(m_x) : 0.0);
}

double Simulation::external_potential_energy() const {
  if (m_timed.empty()) {
    const double scale = is_static() ? load_factor() : 1.0;
    return -scale * m_external.dot(m_x - m_embedded->rest_positions());
  }
  return -current_external_forces().dot(m_x - m_embedded->rest_positions());
}

VectorXd Simulation::current_external_forces() const {
  VectorXd f;
  if (is_static())
    m_system->external_forces_at(load_factor(), load_factor(), f);
  else
    m_system->external_forces_at(time(), 1.0, f);
  return f;
}

void Simulation::record_newton(const NewtonResult& result) {
  m_newton.newton_iterations += result.iterations;
  m_newton.exact_hessian_iterations += result.exact_hessian_iterations;
  m_newton.shifted_hessian_iterations += result.shifted_hessian_iterations;
  m_newton.projected_hessian_iterations += result.projected_hessian_iterations;
  if (!result.converged) return;
  if (result.criterion == NewtonCriterion::increment) ++m_newton.increment_converged_steps;
  if (result.criterion == NewtonCriterion::stall) ++m_newton.stalled_steps;
  if (result.residual_target > 0.0)
    m_newton.max_residual_ratio =
        std::max(m_newton.max_residual_ratio, result.residual / result.residual_target);
}

std::vector<SmootherEstimate> Simulation::smoother_estimates() const {
  const SpdSolver* solver = m_stepper->linear_solver();
  return solver != nullptr ? solver->smoother_estimates() : std::vector<SmootherEstimate>{};
}

std::shared_ptr<MultigridCoarseLevels> Simulation::release_coarse_levels() {
  SpdSolver* solver = m_stepper->linear_solver();
  return solver != nullptr ? solver->release_coarse_levels() : nullptr;
}

SimulationCounters Simulation::counters() const {
  SimulationCounters counters = m_newton;
  counters.steps = m_steps - m_first_step;
  counters.element_evaluations = m_model->element_evaluations();
  const SpdSolver* solver = m_stepper->linear_solver();
  if (solver != nullptr) {
    counters.factorizations = solver->factorizations();
    counters.linear_iterations = solver->cg_iterations();
    counters.reused_factor_solves = solver->reused_factor_solves();
    counters.multigrid_setups = solver->multigrid_setups();
    counters.multigrid_carried_setups = solver->carried_setups();
    counters.multigrid_setup_seconds = solver->multigrid_setup_seconds();
    counters.multigrid_direct_fallbacks = solver->direct_fallbacks();
    counters.linear_solver = solver->kind();
  }
  return counters;
}

}  // namespace strata
