// DisplayWriter: the deformation for display (--display DIR). The simulation thread
// offers frames (the displacement of the shown surface nodes at a time); the writer's own
// thread writes each as DIR/surface-NNNNNN.vtu, and DIR/surface.pvd (the ParaView
// collection of them all) when it stops. Shown, for a linear elastic object: the surface
// triangles whose nodes all have compliance rows (common/model/shown_surface.h); for a
// home-spring tissue: its whole surface, vertex i its node i, dented by its display
// deformation (HomeSpringSimulation::displayed). Its queue holds at most kMaxQueuedDisplayFrames: a
// frame offered while the writer is that far behind is dropped, so the simulation is never held up.
// Units: offered in m and s; written in the scene's units.
#pragma once

#include <Eigen/Core>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "common/fem/compliance.h"
#include "common/model/model.h"

namespace cohaptic {

/// Frames waiting to be written: at the default 10 frames a second, over a second and a
/// half of a slow disk before frames are dropped.
inline constexpr std::size_t kMaxQueuedDisplayFrames = 16;

class DisplayWriter {
 public:
  /// Chooses the shown nodes and triangles of the scene's only object, linear elastic, and
  /// creates `directory`. `model` must outlive it.
  DisplayWriter(const Model& model, const ComplianceColumns& columns,
                std::filesystem::path directory);
  /// The same for a scene whose only object is a home-spring tissue: its whole surface.
  DisplayWriter(const Model& model, const HomeSpringBody& tissue, std::filesystem::path directory);
  ~DisplayWriter();  ///< stop()
  DisplayWriter(const DisplayWriter&) = delete;
  DisplayWriter& operator=(const DisplayWriter&) = delete;

  /// The nodes shown (row nodes), in the order offer() expects their displacements.
  const std::vector<int>& nodes() const { return nodes_; }

  /// Starts the writing thread.
  void start();
  /// Queues a frame: `displacement` [m] of nodes() at `time` [s]. False if it was dropped
  /// (the queue is full). Called by the simulation thread.
  bool offer(double time, Eigen::Matrix3Xd displacement);
  /// Writes what is queued and the index, then ends the thread. Idempotent.
  void stop();

 private:
  struct Frame {
    double time = 0;
    Eigen::Matrix3Xd displacement;
  };
  void write_frames();
  void write_index() const;

  const Model& model_;
  std::filesystem::path directory_;
  std::vector<int> nodes_;           // nodes shown: FEM row nodes, or every tissue vertex
  std::vector<Triangle> triangles_;  // in nodes_ numbering
  Eigen::Matrix3Xd rest_;            // of nodes_, in the scene's units
  std::vector<std::int64_t> tags_;   // of nodes_: the mesh's node ids, or the vertex indices
  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<Frame> queue_;
  bool stopping_ = false;
  std::thread thread_;
  std::vector<std::pair<double, std::string>>
      written_;  // (time, file) for the index; writer thread
};

}  // namespace cohaptic
