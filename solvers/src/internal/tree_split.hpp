// The split of an elimination tree into subtree sets of about equal work and a top, for two-core sweeps over it.
#pragma once

#include <vector>

namespace dynid::detail {

/// The number of subtree sets (one per core of the two-core paths: pair.hpp).
constexpr int kTreeBins = 2;

/// Each node's set (0 .. kTreeBins - 1) or -1 for the top, for a tree given by parent[] (parent after child, -1 at
/// a root) and each node's own work. Starting from the roots, the heaviest subtree among the candidates is moved to
/// the top (its root, then its children become candidates) until the candidates' subtrees pack into the sets
/// (largest first, each into the lightest set) within 3 % of an even share, or until half the work is in the top;
/// of the splits met on the way, the one with the least (largest set + top_share x top) work is kept (top_share:
/// 1 where the top runs on one core, 1/2 where its work is shared by both). Every ancestor of a top node is in the
/// top; the split depends on the tree and the work alone.
std::vector<int> split_tree(const std::vector<int>& parent, const std::vector<double>& work, double top_share = 1);

}  // namespace dynid::detail
