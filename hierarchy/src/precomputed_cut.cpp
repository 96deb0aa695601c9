#include "strata/hierarchy/precomputed_cut.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "strata/core/common/error.hpp"

namespace strata {

std::string to_string(const NodePath& path) {
  std::string text = std::to_string(path.root);
  if (!path.slots.empty()) text += '.';
  for (std::int8_t slot : path.slots)
    text += static_cast<char>('0' + slot);
  return text;
}

NodePath parse_node_path(const std::string& text, const std::string& where) {
  const auto bad = [&]() {
    return InputError(where + ": \"" + text +
                      "\" is not a node path (root index, then '.' and child slots 0-7, e.g. "
                      "\"12.305\")");
  };
  NodePath path;
  const std::size_t dot = text.find('.');
  const std::string root = text.substr(0, dot);
  if (root.empty() || root.size() > 9 ||
      !std::all_of(root.begin(), root.end(), [](char c) { return c >= '0' && c <= '9'; }))
    throw bad();
  path.root = std::stoi(root);
  if (dot != std::string::npos) {
    const std::string slots = text.substr(dot + 1);
    if (slots.empty() || slots.size() > static_cast<std::size_t>(TetTree::kMaxSupportedLevel))
      throw bad();
    for (char c : slots) {
      if (c < '0' || c > '7') throw bad();
      path.slots.push_back(static_cast<std::int8_t>(c - '0'));
    }
  }
  return path;
}

NodePath node_path(const TetTree& tree, NodeId n) {
  NodePath path;
  path.root = tree.node(n).root;
  for (NodeId m = n; tree.parent(m) != kNoNode; m = tree.parent(m))
    path.slots.push_back(tree.node(m).child_slot);
  std::reverse(path.slots.begin(), path.slots.end());
  return path;
}

std::uint64_t node_key(const NodePath& path) {
  std::uint64_t key = static_cast<std::uint64_t>(static_cast<std::uint32_t>(path.root)) << 32;
  key |= static_cast<std::uint64_t>(path.slots.size()) << 24;
  for (std::size_t i = 0; i < path.slots.size() && i < 8; ++i)
    key |= static_cast<std::uint64_t>(path.slots[i]) << (3 * i);
  return key;
}

std::uint64_t node_key(const TetTree& tree, NodeId n) {
  const int level = tree.level(n);
  std::uint64_t key = static_cast<std::uint64_t>(static_cast<std::uint32_t>(tree.node(n).root))
                      << 32;
  key |= static_cast<std::uint64_t>(level) << 24;
  for (NodeId m = n; tree.parent(m) != kNoNode; m = tree.parent(m))
    if (tree.level(m) <= 8)
      key |= static_cast<std::uint64_t>(tree.node(m).child_slot) << (3 * (tree.level(m) - 1));
  return key;
}

NodePath key_path(std::uint64_t key) {
  NodePath path;
  path.root = static_cast<int>(key >> 32);
  const int level = static_cast<int>((key >> 24) & 0xff);
  for (int i = 0; i < level; ++i)
    path.slots.push_back(static_cast<std::int8_t>((key >> (3 * i)) & 7));
  return path;
}

int PrecomputedCut::finest_level() const {
  int level = 0;
  for (const CutWindow& window : windows)
    for (const NodePath& path : window.refined)
      level = std::max(level, path.level() + 1);
  return level;
}

std::size_t PrecomputedCut::window_at(double t) const {
  std::size_t w = 0;
  const double slack = 1e-9 * std::max(1e-300, windows.empty() ? 0.0 : windows.front().end);
  for (std::size_t i = 1; i < windows.size(); ++i)
    if (windows[i].start <= t + slack) w = i;
  return w;
}

void validate_precomputed_cut(const PrecomputedCut& cut, const TetMesh& coarse, int levels,
                              const std::string& where) {
  if (cut.coarse_vertices != coarse.vertices.rows() || cut.coarse_tets != coarse.tets.rows())
    throw InputError(where + ": made for a coarse mesh of " + std::to_string(cut.coarse_vertices) +
                     " vertices and " + std::to_string(cut.coarse_tets) +
                     " tets; this scene's has " + std::to_string(coarse.vertices.rows()) + " and " +
                     std::to_string(coarse.tets.rows()));
  const Vector3d lo = coarse.vertices.colwise().minCoeff().transpose();
  const Vector3d hi = coarse.vertices.colwise().maxCoeff().transpose();
  const Vector3d centroid = coarse.vertices.colwise().mean().transpose();
  if ((centroid - cut.coarse_centroid).norm() > 1e-9 * (hi - lo).norm())
    throw InputError(where + ": made for another coarse mesh (its vertices' centroid differs)");
  if (cut.windows.empty()) throw InputError(where + ".windows: empty");
  for (std::size_t w = 0; w < cut.windows.size(); ++w) {
    const CutWindow& window = cut.windows[w];
    const std::string at = where + ".windows." + std::to_string(w);
    if (!(std::isfinite(window.start) && window.end >= window.start))
      throw InputError(at + ": needs start <= end");
    if (w > 0 && std::abs(window.start - cut.windows[w - 1].end) >
                     1e-9 * std::max(1.0, std::abs(window.start)))
      throw InputError(at + ".start: must equal the previous window's end");
    RefinedSet set(window.refined);
    for (const NodePath& path : window.refined) {
      if (path.root < 0 || path.root >= coarse.tets.rows())
        throw InputError(at + ".refined: \"" + to_string(path) + "\" names root " +
                         std::to_string(path.root) + " of a mesh with " +
                         std::to_string(coarse.tets.rows()) + " tets");
      if (path.level() >= levels)
        throw InputError(at + ".refined: \"" + to_string(path) + "\" refines level " +
                         std::to_string(path.level()) +
                         ", deeper than hierarchy.levels = " + std::to_string(levels) + " allows");
      if (!path.slots.empty()) {
        NodePath parent = path;
        parent.slots.pop_back();
        if (!set.contains(parent))
          throw InputError(at + ".refined: \"" + to_string(path) + "\" without its parent \"" +
                           to_string(parent) + "\"");
      }
    }
  }
}

RefinedSet::RefinedSet(const std::vector<NodePath>& refined) {
  m_keys.reserve(refined.size());
  for (const NodePath& path : refined)
    m_keys.emplace(node_key(path), 1);
}

bool RefinedSet::contains(const NodePath& path) const {
  return m_keys.count(node_key(path)) > 0;
}

bool RefinedSet::contains(const TetTree& tree, NodeId n) const {
  return m_keys.count(node_key(tree, n)) > 0;
}

std::vector<NodeId> cut_nodes(TetTree& tree, const std::vector<NodePath>& refined) {
  const RefinedSet set(refined);
  std::vector<NodeId> result;
  std::vector<std::pair<NodeId, NodePath>> stack;
  for (NodeId r = static_cast<NodeId>(tree.num_roots()) - 1; r >= 0; --r)
    stack.push_back({r, NodePath{r, {}}});
  while (!stack.empty()) {
    auto [n, path] = std::move(stack.back());
    stack.pop_back();
    if (path.level() < tree.max_level() && set.contains(path)) {
      const NodeId first = tree.refine(n);
      for (int k = 7; k >= 0; --k) {
        NodePath child = path;
        child.slots.push_back(static_cast<std::int8_t>(k));
        stack.push_back({first + k, std::move(child)});
      }
    } else {
      result.push_back(n);
    }
  }
  return result;
}

void CutRecorder::record(const ActiveCut& cut, double time) {
  const TetTree& tree = cut.tree();
  m_end = std::max(m_end, time);
  for (NodeId n : cut.nodes()) {
    for (NodeId p = tree.parent(n); p != kNoNode; p = tree.parent(p)) {
      auto [it, inserted] = m_spans.try_emplace(node_key(tree, p), Span{time, time});
      if (!inserted) {
        if (it->second.last == time) break;  // touched at this time: its ancestors were too
        it->second.first = std::min(it->second.first, time);
        it->second.last = std::max(it->second.last, time);
      }
    }
  }
}

PrecomputedCut CutRecorder::schedule(int windows, const TetMesh& coarse, int levels,
                                     double tolerance, double end) const {
  if (windows < 1) throw InputError("precompute: windows must be >= 1");
  PrecomputedCut cut;
  cut.coarse_vertices = coarse.vertices.rows();
  cut.coarse_tets = coarse.tets.rows();
  cut.coarse_centroid = coarse.vertices.colwise().mean().transpose();
  cut.levels = levels;
  cut.tolerance = tolerance;
  cut.sources = m_sources;
  const double span = end > 0.0 ? end : m_end;
  for (int w = 0; w < windows; ++w) {
    CutWindow window;
    window.start = span * w / windows;
    window.end = span * (w + 1) / windows;
    std::vector<std::uint64_t> keys;
    for (const auto& [key, times] : m_spans) {
      const bool first = w == 0, last = w + 1 == windows;
      if ((last || times.first <= window.end) && (first || times.last >= window.start))
        keys.push_back(key);
    }
    std::sort(keys.begin(), keys.end(), [](std::uint64_t a, std::uint64_t b) {
      const std::uint64_t la = (a >> 24) & 0xff, lb = (b >> 24) & 0xff;
      return la != lb ? la < lb : a < b;
    });
    for (std::uint64_t key : keys)
      window.refined.push_back(key_path(key));
    cut.windows.push_back(std::move(window));
  }
  return cut;
}

}  // namespace strata
