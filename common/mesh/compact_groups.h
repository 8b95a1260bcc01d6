// Ordering points so that every run of `group_size` consecutive points is spatially compact.
//
// Compliance columns are solved in fixed groups of consecutive row nodes (compliance.h):
// a node asked for costs its whole group's solve. Ordered in compact groups, the nodes a
// contact patch or an approaching tool needs fall into a few groups instead of one group
// each. The order is a recursive bisection: the points are split across the longest side
// of their bounding box, at the multiple of `group_size` nearest half the count, until
// each part holds one group. Which ids share a group does not depend on the order they
// are given in: ties in a coordinate go by id.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace cohaptic {

/// `ids` reordered; `positions` holds the point of id k in column k.
std::vector<int> order_in_compact_groups(const Eigen::Matrix3Xd& positions, std::vector<int> ids,
                                         int group_size);

}  // namespace cohaptic
