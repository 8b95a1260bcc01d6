#include "common/mesh/compact_groups.h"

#include <algorithm>
#include <fmt/format.h>

#include "common/util/error.h"

namespace cohaptic {
namespace {

void bisect(const Eigen::Matrix3Xd& positions, std::vector<int>::iterator begin,
            std::vector<int>::iterator end, int group_size) {
  const auto count = end - begin;
  if (count <= group_size) return;
  Eigen::Vector3d lo = positions.col(*begin), hi = lo;
  for (auto it = begin; it != end; ++it) {
    lo = lo.cwiseMin(positions.col(*it));
    hi = hi.cwiseMax(positions.col(*it));
  }
  int axis = 0;
  (hi - lo).maxCoeff(&axis);
  const auto groups = (count + group_size - 1) / group_size;
  const auto middle = begin + (groups / 2) * group_size;
  std::nth_element(begin, middle, end, [&](int a, int b) {
    const double pa = positions(axis, a), pb = positions(axis, b);
    return pa < pb || (pa == pb && a < b);
  });
  bisect(positions, begin, middle, group_size);
  bisect(positions, middle, end, group_size);
}

}  // namespace

std::vector<int> order_in_compact_groups(const Eigen::Matrix3Xd& positions, std::vector<int> ids,
                                         int group_size) {
  if (group_size < 1)
    throw Error(fmt::format("order_in_compact_groups: group size {} is not positive", group_size));
  for (int id : ids)
    if (id < 0 || id >= positions.cols())
      throw Error(fmt::format("order_in_compact_groups: id {} out of range (0 to {})", id,
                              positions.cols() - 1));
  bisect(positions, ids.begin(), ids.end(), group_size);
  return ids;
}

}  // namespace cohaptic
