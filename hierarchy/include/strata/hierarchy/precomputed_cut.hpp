#pragma once
/// \file precomputed_cut.hpp
/// A cut chosen from precomputed runs: where earlier runs of a tree refined, recorded per tree
/// node over time, and played back as a static cut or a schedule of cuts with no run-time
/// criteria (hierarchy mode "precomputed").
///
/// Nodes are named by their path from the root, stable across runs and trees over the same coarse
/// mesh: root r and the child slots k₁ k₂ … (0..7, Bey's T_k) down to the node. A cut is stored as
/// its set of refined nodes (every strict ancestor of an active node); that set is closed under
/// taking parents, and the cut is its leaves. The union of refined sets is again such a set — the
/// finest cut that contains every recorded cut — which is what a window of the schedule holds.
///
/// Lifecycle: CutRecorder::record(cut, t) after every accepted step of one or more runs →
/// `schedule(windows, t_end)` → (written / read as cut.json by the CLI) → AdaptiveSimulation with
/// HierarchySettings::precomputed plays it back, switching cuts at window starts.
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "strata/hierarchy/active_cut.hpp"

namespace strata {

/// A node by its path: the root and the child slots below it (empty: the root itself).
struct NodePath {
  int root = 0;
  std::vector<std::int8_t> slots;
  int level() const { return static_cast<int>(slots.size()); }
  bool operator==(const NodePath& other) const = default;
};

/// "r" for a root, "r.k1k2…" below it (slots as digits 0..7), e.g. "12.305".
std::string to_string(const NodePath& path);
/// Parses `to_string`'s form; throws InputError naming `where` for anything else.
NodePath parse_node_path(const std::string& text, const std::string& where);

/// The path of live node `n` of `tree`.
NodePath node_path(const TetTree& tree, NodeId n);

/// One window of a schedule: the refined nodes of the cut used for start ≤ t < end.
struct CutWindow {
  double start = 0.0;  ///< simulated time or load factor
  double end = 0.0;
  std::vector<NodePath> refined;  ///< closed under parents, by level then path
};

/// A schedule of cuts over time, for one coarse mesh.
struct PrecomputedCut {
  Index coarse_vertices = 0;  ///< the coarse mesh it was made for
  Index coarse_tets = 0;
  Vector3d coarse_centroid = Vector3d::Zero();  ///< mean of the coarse vertices [m]
  int levels = 0;                               ///< the tree's levels when recorded
  double tolerance = 0.0;                       ///< hierarchy.tolerance of the recorded runs
  std::vector<std::string> sources;             ///< the runs recorded (scene names)
  std::string name;                ///< where it was read from (a file name), for reports
  std::vector<CutWindow> windows;  ///< consecutive, covering [0, end of the last)

  /// Deepest level of any refined node + 1 (0: the roots).
  int finest_level() const;
  /// The window for time t: the last whose start ≤ t (the first for t before it).
  std::size_t window_at(double t) const;
};

/// Throws InputError naming `where` unless the cut was made for `coarse` (vertex and tet counts,
/// centroid within 1e-9 of the bounding-box diagonal), every path names a root of it and lies
/// above `levels`, and the windows are consecutive with non-decreasing times.
void validate_precomputed_cut(const PrecomputedCut& cut, const TetMesh& coarse, int levels,
                              const std::string& where);

/// The active nodes of the cut `refined` describes on `tree`, refining the tree where needed.
/// Paths deeper than the tree's max level are cut off there.
std::vector<NodeId> cut_nodes(TetTree& tree, const std::vector<NodePath>& refined);

/// Whether active node `n`'s path is in `refined` (as a hash set, see RefinedSet).
class RefinedSet {
 public:
  explicit RefinedSet(const std::vector<NodePath>& refined);
  bool contains(const TetTree& tree, NodeId n) const;
  bool contains(const NodePath& path) const;

 private:
  std::unordered_map<std::uint64_t, char> m_keys;
};

/// Records the refined nodes of the cuts of one or more runs over time.
class CutRecorder {
 public:
  /// Every strict ancestor of an active node of `cut` is refined at `time`.
  void record(const ActiveCut& cut, double time);
  /// Starts the next run (its times count from 0 again; nodes are merged by path).
  void add_source(std::string name) { m_sources.push_back(std::move(name)); }
  const std::vector<std::string>& sources() const { return m_sources; }
  /// Nodes refined at some recorded time.
  Index num_refined() const { return static_cast<Index>(m_spans.size()); }
  /// Latest recorded time.
  double end_time() const { return m_end; }

  /// `windows` equal windows over [0, end] (end = end_time() if ≤ 0), each holding every node
  /// refined at some recorded time inside it (a node's recorded times are kept as the span from
  /// its first to its last, so a node refined twice counts as refined in between). The last window
  /// extends to infinity in playback. Throws InputError for windows < 1 or nothing recorded.
  PrecomputedCut schedule(int windows, const TetMesh& coarse, int levels, double tolerance,
                          double end = 0.0) const;

 private:
  struct Span {
    double first = 0.0, last = 0.0;
  };
  std::unordered_map<std::uint64_t, Span> m_spans;
  std::vector<std::string> m_sources;
  double m_end = 0.0;
};

/// A node's path packed into 64 bits (root: 32 bits, level: 8, slots: 3 bits each).
std::uint64_t node_key(const NodePath& path);
/// node_key(node_path(tree, n)) without building the path.
std::uint64_t node_key(const TetTree& tree, NodeId n);
NodePath key_path(std::uint64_t key);

}  // namespace strata
