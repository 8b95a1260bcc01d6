#include "server/display_writer.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "common/mesh/write_vtu.h"
#include "common/model/shown_surface.h"
#include "common/util/atomic_file.h"
#include "common/util/error.h"

namespace cohaptic {

DisplayWriter::DisplayWriter(const Model& model, const ComplianceColumns& columns,
                             std::filesystem::path directory)
    : model_(model), directory_(std::move(directory)) {
  const ElasticBody& body = single_elastic_body(model);
  ShownSurface shown = shown_surface(body, columns.row_nodes());
  nodes_ = std::move(shown.nodes);
  triangles_ = std::move(shown.triangles);
  rest_.resize(3, static_cast<Eigen::Index>(nodes_.size()));
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    rest_.col(static_cast<Eigen::Index>(i)) =
        body.mesh.nodes.col(nodes_[i]) / model.scene.metres_per_unit;
    tags_.push_back(body.mesh.node_tags[static_cast<std::size_t>(nodes_[i])]);
  }
  std::filesystem::create_directories(directory_);
}

DisplayWriter::DisplayWriter(const Model& model, const HomeSpringBody& tissue,
                             std::filesystem::path directory)
    : model_(model),
      directory_(std::move(directory)),
      triangles_(tissue.surface.triangles),
      rest_(tissue.surface.vertices / model.scene.metres_per_unit) {
  for (int v = 0; v < tissue.surface.vertex_count(); ++v) {
    nodes_.push_back(v);
    tags_.push_back(v);
  }
  std::filesystem::create_directories(directory_);
}

DisplayWriter::~DisplayWriter() { stop(); }

void DisplayWriter::start() {
  thread_ = std::thread([this] { write_frames(); });
}

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
      write_surface_vtu(directory_ / name, rest_, triangles_, tags_,
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
    index.write(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n");
    for (const auto& [time, name] : written_)
      index.print("    <DataSet timestep=\"{:.6f}\" file=\"{}\"/>\n", time, name);
    index.write("  </Collection>\n</VTKFile>\n");
    index.commit();
    spdlog::info("{} display frames in {} (open surface.pvd in ParaView; lengths in {})",
                 written_.size(), directory_.string(), model_.scene.units);
  } catch (const Error& e) {
    spdlog::warn("display index not written: {}", e.what());
  }
}

}  // namespace cohaptic
