#include "server/compliance_prefetch.h"

#include <spdlog/spdlog.h>

#include <algorithm>

namespace cohaptic {

CompliancePrefetch::CompliancePrefetch(const ElasticBody& body, const std::vector<int>& row_nodes)
    : solver_(body.free_factor, body.dofs, row_nodes),
      row_positions_(body.mesh.nodes(Eigen::all, row_nodes)),
      taken_(static_cast<std::size_t>(
                 ComplianceColumns::group_of(static_cast<int>(row_nodes.size()) - 1) + 1),
             0),
      distance_(taken_.size(), kNotQueued),
      worker_([this] { work(); }) {}

CompliancePrefetch::~CompliancePrefetch() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  worker_.join();
}

void CompliancePrefetch::request(std::span<const NodeDistance> nodes) {
  bool queued = false;
  {
    std::lock_guard lock(mutex_);
    for (const NodeDistance& request : nodes) {
      const int position = solver_.row_position(request.node);
      if (position < 0) continue;
      const auto group = static_cast<std::size_t>(ComplianceColumns::group_of(position));
      if (taken_[group] || !(request.distance < distance_[group])) continue;
      distance_[group] = request.distance;
      queued = true;
    }
  }
  if (queued) wake_.notify_one();
}

void CompliancePrefetch::request_near(const Eigen::Vector3d& tool,
                                      const ComplianceColumns& columns) {
  near_.clear();
  const std::vector<int>& rows = solver_.row_nodes();
  for (Eigen::Index r = 0; r < row_positions_.cols(); ++r) {
    const double distance = (row_positions_.col(r) - tool).norm();
    const int node = rows[static_cast<std::size_t>(r)];
    if (distance < kToolReach && !columns.has_column(node))
      near_.push_back({node, distance - kPatchRadius});
  }
  request(near_);
}

std::size_t CompliancePrefetch::deliver(ComplianceColumns& columns) {
  std::unordered_map<int, ComplianceColumn> ready;
  {
    std::lock_guard lock(mutex_);
    if (finished_.empty()) return 0;
    ready.swap(finished_);
  }
  std::size_t moved = 0;
  for (auto& [node, column] : ready)
    if (!columns.has_column(node)) {
      columns.insert_column(node, std::move(column));
      ++moved;
    }
  return moved;
}

void CompliancePrefetch::work() {
  const std::vector<int>& rows = solver_.row_nodes();
  std::vector<int> group_nodes;
  for (;;) {
    std::size_t group = 0;
    {
      std::unique_lock lock(mutex_);
      // The nearest group queued (ties: the lowest index), the worker's from now on.
      const auto nearest = [this] {
        return static_cast<std::size_t>(std::min_element(distance_.begin(), distance_.end()) -
                                        distance_.begin());
      };
      wake_.wait(lock, [&] { return stopping_ || distance_[nearest()] < kNotQueued; });
      if (stopping_) return;
      group = nearest();
      taken_[group] = 1;
      distance_[group] = kNotQueued;
    }
    const std::size_t first = group * ComplianceColumns::kGroupSize;
    const std::size_t end = std::min(rows.size(), first + ComplianceColumns::kGroupSize);
    group_nodes.assign(rows.begin() + static_cast<std::ptrdiff_t>(first),
                       rows.begin() + static_cast<std::ptrdiff_t>(end));
    try {
      solver_.compute_columns(group_nodes);
    } catch (const std::exception& e) {
      // The simulation thread solves these columns itself when it needs them, and meets
      // the error there.
      spdlog::warn("compliance prefetch: rows {} to {} not solved: {}", first, end - 1, e.what());
      continue;
    }
    std::unordered_map<int, ComplianceColumn> solved = solver_.take_columns();
    std::lock_guard lock(mutex_);
    finished_.merge(solved);
  }
}

}  // namespace cohaptic
