// CompliancePrefetch: compliance columns solved ahead of need on a thread of their own, so
// that the simulation thread seldom stops for a solve. On the brain a solve group costs
// 13 ms of CPU (30-100 ms of wall time on a loaded 2-core machine), and a cold first
// contact needs dozens: the patches under the tools and every node the skull starts to hold.
//
// The simulation thread asks for the nodes it will soon need, each with an estimate of how
// far it is from needing it [m]: the row nodes near each tool (request_near), and the nodes
// about to reach an obstacle (Simulation::nodes_near_obstacles). The worker solves the
// nearest group queued first. At the start of each step the simulation thread collects
// what is finished (deliver) into its own ComplianceColumns. Neither call waits for a
// solve: the worker holds the lock only to take a group or to hand its columns over. A node
// needed before the worker got to it is solved on the simulation thread, as without
// prefetching.
//
// The worker solves whole groups, the very solve the simulation thread would have made
// (ComplianceColumns::compute_columns, own CHOLMOD workspace, the factor shared read-only),
// so a column's bits do not depend on which thread solved it, and a recorded session
// replays bit for bit. Memory: the columns it solves stay in the simulation's cache (98 kB
// a node on the brain; about 330 nodes, 32 MB, in `make demo`, against 9 MB solved on
// demand alone and 134 MB for the whole surface).
#pragma once

#include <Eigen/Core>
#include <condition_variable>
#include <cstddef>
#include <limits>
#include <mutex>
#include <span>
#include <thread>
#include <unordered_map>
#include <vector>

#include "common/fem/compliance.h"
#include "common/model/elastic_body.h"
#include "common/sim/simulation.h"

namespace cohaptic {

class CompliancePrefetch {
 public:
  /// Row nodes within this distance of a tool are asked for [m] ...
  static constexpr double kToolReach = 0.020;
  /// ... those within this one first: about the extent of a one-ring patch [m].
  static constexpr double kPatchRadius = 0.010;

  /// `body` (its factor, dofs and rest positions) must outlive it; `row_nodes` as the
  /// simulation's columns have them.
  CompliancePrefetch(const ElasticBody& body, const std::vector<int>& row_nodes);
  /// Stops the worker (after the group it is solving) and joins it.
  ~CompliancePrefetch();
  CompliancePrefetch(const CompliancePrefetch&) = delete;
  CompliancePrefetch& operator=(const CompliancePrefetch&) = delete;

  /// Queues the solve groups of `nodes` (row nodes; others are ignored) that the worker has
  /// not taken yet, each with the least distance it has been given.
  void request(std::span<const NodeDistance> nodes);
  /// Asks for the row nodes within kToolReach of a tool at `tool` that `columns` lacks, at
  /// their distance from it less kPatchRadius.
  void request_near(const Eigen::Vector3d& tool, const ComplianceColumns& columns);
  /// Moves every column solved since the last call into `columns`, but those it already
  /// has. Returns how many it moved.
  std::size_t deliver(ComplianceColumns& columns);

 private:
  static constexpr double kNotQueued = std::numeric_limits<double>::infinity();
  void work();

  ComplianceColumns solver_;        // the worker's own: its CHOLMOD workspace, and the row layout
  Eigen::Matrix3Xd row_positions_;  // of the row nodes, in their order
  std::vector<NodeDistance> near_;  // request_near's scratch (the simulation thread's)
  std::mutex mutex_;
  std::condition_variable wake_;
  std::vector<char> taken_;       // per group: the worker took it (solved, or failed)
  std::vector<double> distance_;  // per group: the least distance it is queued with, or kNotQueued
  std::unordered_map<int, ComplianceColumn> finished_;
  bool stopping_ = false;
  std::thread worker_;  // last: starts once everything above is ready
};

}  // namespace cohaptic
