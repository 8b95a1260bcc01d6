#include "server/display_writer.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "common/mesh/write_vtu.h"
#include "common/model/shown_surface.h"
#include "common/util/atomic_file.h"
#include "common/util/error.h"

namespace cohaptic {

DisplayWriter::DisplayWriter(const Model& model, const ComplianceColumns& columns, std::filesystem::path directory)
    : model_(model), body_(single_elastic_body(model)), directory_(std::move(directory)) {
  ShownSurface shown = shown_surface(body_, columns.row_nodes());
  nodes_ = std::move(shown.nodes);
  triangles_ = std::move(shown.triangles);
  std::filesystem::create_directories(directory_);
}

DisplayWriter::~DisplayWriter() { stop(); }

void DisplayWriter::start() { thread_ = std::thread([this] { write_frames(); }); }

bool DisplayWriter::offer(double time, Eigen::Matrix3Xd displacement) {
  std::lock_guard lock(mutex_);
  if (queue_.size() >= kMaxQueuedDisplayFrames) return false;
  queue_.push_back({time, std::move(displacement)});
  ready_.notify_one();
  return true;
}

void DisplayWriter::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  ready_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void DisplayWriter::write_frames() {
  const double unit = model_.scene.metres_per_unit;
  Eigen::Matrix3Xd rest(3, static_cast<Eigen::Index>(nodes_.size()));
  std::vector<std::int64_t> tags;
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    rest.col(static_cast<Eigen::Index>(i)) = body_.mesh.nodes.col(nodes_[i]) / unit;
    tags.push_back(body_.mesh.node_tags[static_cast<std::size_t>(nodes_[i])]);
  }
  for (;;) {
    Frame frame;
    {
      std::unique_lock lock(mutex_);
      ready_.wait(lock, [this] { return !queue_.empty() || stopping_; });
      if (queue_.empty()) break;
      frame = std::move(queue_.front());
      queue_.pop_front();
    }
    const std::string name = fmt::format("surface-{:06d}.vtu", written_.size());
    try {
      write_surface_vtu(directory_ / name, rest, triangles_, tags,
                        {{"displacement", Eigen::MatrixXd(frame.displacement / unit)}});
      written_.emplace_back(frame.time, name);
    } catch (const Error& e) {
      spdlog::warn("display frame not written: {}", e.what());
    }
  }
  write_index();
}

// The ParaView collection: open surface.pvd to play the deformation over time.
void DisplayWriter::write_index() const {
  try {
    AtomicFile index(directory_ / "surface.pvd");
    index.write("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n");
    for (const auto& [time, name] : written_) index.print("    <DataSet timestep=\"{:.6f}\" file=\"{}\"/>\n", time, name);
    index.write("  </Collection>\n</VTKFile>\n");
    index.commit();
    spdlog::info("{} display frames in {} (open surface.pvd in ParaView; lengths in {})", written_.size(),
                 directory_.string(), model_.scene.units);
  } catch (const Error& e) {
    spdlog::warn("display index not written: {}", e.what());
  }
}

}  // namespace cohaptic
