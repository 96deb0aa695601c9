#include "strata/hierarchy/refinement_controller.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "strata/core/common/error.hpp"
#include "strata/hierarchy/cut_balance.hpp"
#include "strata/hierarchy/refinement_force_indicator.hpp"

namespace strata {
namespace {

bool positive(double x) {
  return x > 0.0 && std::isfinite(x);
}

}  // namespace

void validate_refinement_settings(const RefinementSettings& s, const std::string& where) {
  const auto fail = [&](const std::string& key, const std::string& rule) {
    throw InputError(where + "." + key + ": " + rule);
  };
  if (!positive(s.refine_threshold)) fail("refine_threshold", "must be a positive number");
  if (!positive(s.coarsen_indicator_fraction) || s.coarsen_indicator_fraction > 1.0)
    fail("coarsen_indicator_fraction", "must be in (0, 1]");
  if (!positive(s.coarsen_tolerance)) fail("coarsen_tolerance", "must be a positive number");
  if (!positive(s.stress_floor)) fail("stress_floor", "must be a positive number");
  if (s.min_steps_between_changes < 0) fail("min_steps_between_changes", "must be >= 0");
  if (s.max_active_elements < 0) fail("max_active_elements", "must be >= 0 (0: no budget)");
  if (s.max_level < -1) fail("max_level", "must be >= 0 (or -1: the tree's)");
}

RefinementController::RefinementController(const RefinementSettings& settings,
                                           std::unique_ptr<RefinementIndicator> indicator)
    : m_settings(settings), m_indicator(std::move(indicator)) {
  validate_refinement_settings(settings, "refinement");
  if (!m_indicator) m_indicator = std::make_unique<ForceIndicator>(settings.stress_floor);
}

void RefinementController::set_refinement_veto(std::function<bool(NodeId)> may_refine) {
  m_may_refine = std::move(may_refine);
}

void RefinementController::set_coarsening_veto(std::function<bool(NodeId)> may_coarsen) {
  m_may_coarsen = std::move(may_coarsen);
}

void RefinementController::set_merge_filter(MergeFilter filter) {
  m_merge_filter = std::move(filter);
}

long RefinementController::last_change_step(NodeId n) const {
  return n >= 0 && static_cast<std::size_t>(n) < m_last_change.size() ? m_last_change[n] : kNever;
}

int RefinementController::change_count(NodeId n) const {
  return n >= 0 && static_cast<std::size_t>(n) < m_change_count.size() ? m_change_count[n] : 0;
}

void RefinementController::record_change(NodeId n, long step) {
  if (static_cast<std::size_t>(n) >= m_last_change.size()) {
    const std::size_t size = std::max(static_cast<std::size_t>(n) + 1, m_last_change.size() * 2);
    m_last_change.resize(size, kNever);
    m_change_count.resize(size, 0);
  }
  m_last_change[n] = step;
  ++m_change_count[n];
}

void RefinementController::reset_children(const TetTree& tree, NodeId n) {
  const NodeId first = tree.child(n, 0);
  for (NodeId c = first; c < first + 8 && static_cast<std::size_t>(c) < m_last_change.size(); ++c) {
    m_last_change[c] = kNever;
    m_change_count[c] = 0;
  }
}

CutChanges RefinementController::decide(const CutState& state, const ActiveCut& cut) const {
  const TetTree& tree = state.tree;
  const FlatTreeMesh& flat = state.flat;
  const Index num_tets = flat.mesh.tets.rows();
  STRATA_VERIFY(&cut.tree() == &tree && cut.size() == num_tets,
                "RefinementController::decide: the state is not a flattening of the cut");
  CutChanges changes;
  m_indicator->evaluate(state, changes.eta);
  STRATA_VERIFY(changes.eta.size() == num_tets,
                "RefinementController::decide: the indicator returned the wrong size");

  const long step = state.step;
  const auto settled = [&](NodeId n) {
    const long last = last_change_step(n);
    return last == kNever || step - last >= m_settings.min_steps_between_changes;
  };
  const int max_level = m_settings.max_level < 0 ? tree.max_level()
                                                 : std::min(m_settings.max_level, tree.max_level());

  // Refinement candidates, largest η first.
  std::vector<std::pair<double, NodeId>> candidates;
  for (Index t = 0; t < num_tets; ++t) {
    if (!(changes.eta[t] > m_settings.refine_threshold)) continue;
    ++changes.over_threshold;
    const NodeId n = flat.tet_nodes[t];
    if (tree.level(n) >= max_level || !settled(n) || (m_may_refine && !m_may_refine(n))) continue;
    candidates.emplace_back(changes.eta[t], n);
  }
  std::sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second < b.second;
  });

  // Coarsening: siblings that all stay well below the threshold and whose stresses agree.
  std::vector<int> node_tet(static_cast<std::size_t>(tree.pool_size()), -1);
  for (Index t = 0; t < num_tets; ++t)
    node_tet[flat.tet_nodes[t]] = static_cast<int>(t);
  std::vector<int> finest;  // per flat vertex, with planned refinements one level deeper
  if (m_settings.balance) {
    finest.assign(static_cast<std::size_t>(flat.mesh.vertices.rows()), 0);
    std::vector<char> planned(static_cast<std::size_t>(num_tets), 0);
    for (const auto& c : candidates)
      planned[node_tet[c.second]] = 1;
    for (Index t = 0; t < num_tets; ++t) {
      const int level = tree.level(flat.tet_nodes[t]) + planned[t];
      for (int i = 0; i < 4; ++i)
        finest[flat.mesh.tets(t, i)] = std::max(finest[flat.mesh.tets(t, i)], level);
    }
  }
  const double coarsen_bound = m_settings.coarsen_indicator_fraction * m_settings.refine_threshold;
  const double floor = m_settings.stress_floor * state.material.youngs_modulus;
  for (Index t = 0; t < num_tets; ++t) {
    const NodeId n = flat.tet_nodes[t];
    if (tree.node(n).child_slot != 0) continue;  // visit each sibling block once
    const NodeId parent = tree.parent(n);
    if (!settled(parent)) continue;
    if (m_may_coarsen && !m_may_coarsen(parent)) continue;
    bool mergeable = true;
    Vector6d mean = Vector6d::Zero();
    for (int k = 0; k < 8 && mergeable; ++k) {
      const int child_tet = node_tet[tree.child(parent, k)];
      mergeable = child_tet >= 0 && changes.eta[child_tet] < coarsen_bound;
      if (mergeable) mean += state.fields.cauchy_stress.row(child_tet).transpose() / 8.0;
    }
    if (!mergeable) continue;
    // The children's stresses agree, or the indicator says the merged parent stays below the
    // coarsening bound.
    std::array<int, 8> children{};
    for (int k = 0; k < 8; ++k)
      children[k] = node_tet[tree.child(parent, k)];
    const double limit = m_settings.coarsen_tolerance * (voigt_frobenius_norm(mean) + floor);
    for (int k = 0; k < 8 && mergeable; ++k) {
      const Vector6d diff = state.fields.cauchy_stress.row(children[k]).transpose() - mean;
      mergeable = voigt_frobenius_norm(diff) < limit;
    }
    if (!mergeable)
      mergeable = m_indicator->merge_indicator(state, children, tree.level(parent)) < coarsen_bound;
    for (int k = 0; k < 8 && mergeable && m_settings.balance; ++k)
      for (int i = 0; i < 4 && mergeable; ++i)
        mergeable = finest[flat.mesh.tets(children[k], i)] <= tree.level(parent) + 1;
    if (mergeable) changes.coarsen.push_back(parent);
  }
  std::sort(changes.coarsen.begin(), changes.coarsen.end());
  if (m_merge_filter && !changes.coarsen.empty())
    changes.coarsen = m_merge_filter(state, changes.coarsen);

  // Budget: refine in order of η while the cut (after coarsening) stays within it.
  Index size = cut.size() - 7 * static_cast<Index>(changes.coarsen.size());
  for (const auto& c : candidates) {
    if (m_settings.max_active_elements > 0 && size + 7 > m_settings.max_active_elements) break;
    changes.refine.push_back(c.second);
    size += 7;
  }
  changes.refused = changes.over_threshold - static_cast<Index>(changes.refine.size());
  return changes;
}

CutChangeCounts RefinementController::apply(ActiveCut& cut, const CutChanges& changes, long step) {
  CutChangeCounts counts;
  TetTree& tree = cut.tree();
  for (const NodeId parent : changes.coarsen) {
    if (!cut.can_coarsen(parent)) continue;
    cut.coarsen(parent);
    record_change(parent, step);
    ++counts.coarsened;
  }
  for (const NodeId n : changes.refine) {
    if (!cut.is_active(n) || !tree.can_refine(n)) continue;
    cut.refine(n);
    record_change(n, step);
    reset_children(tree, n);
    ++counts.refined;
  }
  if (m_settings.balance) {
    const std::vector<NodeId> before = cut.nodes();
    counts.balance_refined = balance_cut(cut);
    for (const NodeId n : before)
      if (!cut.is_active(n)) {
        record_change(n, step);
        reset_children(tree, n);
      }
  }
  return counts;
}

}  // namespace strata
