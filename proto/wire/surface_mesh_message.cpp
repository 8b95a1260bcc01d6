#include "proto/wire/surface_mesh_message.h"

#include <cmath>

#include "common/util/error.h"

namespace cohaptic::wire {

SurfaceMesh surface_mesh_message(const ElasticBody& body) {
  const std::vector<int>& nodes = body.surface.nodes;
  std::vector<int> compact(static_cast<std::size_t>(body.mesh.node_count()), -1);
  SurfaceMesh message;
  message.mutable_vertices()->Reserve(3 * static_cast<int>(nodes.size()));
  message.mutable_node_ids()->Reserve(static_cast<int>(nodes.size()));
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const auto node = static_cast<std::size_t>(nodes[i]);
    compact[node] = static_cast<int>(i);
    for (int axis = 0; axis < 3; ++axis) message.add_vertices(body.mesh.nodes(axis, nodes[i]));
    message.add_node_ids(body.mesh.node_tags[node]);
  }
  message.mutable_triangles()->Reserve(3 * body.surface.triangle_count());
  for (const Triangle& tri : body.surface.triangles)
    for (int corner : tri) {
      const auto node = static_cast<std::size_t>(corner);
      if (compact[node] < 0)
        throw cohaptic::Error(fmt::format("surface mesh: triangle node {} is not a surface node",
                                          body.mesh.node_tags[node]));
      message.add_triangles(static_cast<std::uint32_t>(compact[node]));
    }
  return message;
}

SurfaceMesh surface_mesh_message(const MassSpringModel& body) {
  const MassSpringNetwork& network = body.network;
  std::vector<int> compact(static_cast<std::size_t>(network.node_count()), -1);
  SurfaceMesh message;
  for (std::size_t i = 0; i < network.surface_nodes.size(); ++i) {
    const int node = network.surface_nodes[i];
    compact[static_cast<std::size_t>(node)] = static_cast<int>(i);
    for (int axis = 0; axis < 3; ++axis) message.add_vertices(network.rest_positions(axis, node));
    message.add_node_ids(node);
  }
  for (const auto& triangle : network.triangles)
    for (int corner : triangle)
      message.add_triangles(static_cast<std::uint32_t>(compact[static_cast<std::size_t>(corner)]));
  return message;
}

namespace {

// A surface whose vertex i is point i of `vertices`, its node id i.
SurfaceMesh indexed_surface_message(const Eigen::Matrix3Xd& vertices,
                                    const std::vector<Triangle>& triangles) {
  SurfaceMesh message;
  for (int v = 0; v < static_cast<int>(vertices.cols()); ++v) {
    for (int axis = 0; axis < 3; ++axis) message.add_vertices(vertices(axis, v));
    message.add_node_ids(v);
  }
  for (const Triangle& triangle : triangles)
    for (int corner : triangle) message.add_triangles(static_cast<std::uint32_t>(corner));
  return message;
}

}  // namespace

SurfaceMesh surface_mesh_message(const HomeSpringBody& body) {
  return indexed_surface_message(body.surface.vertices, body.surface.triangles);
}

SurfaceMesh surface_mesh_message(const SeparationModel& body) {
  return indexed_surface_message(body.patch->positions, body.patch->triangles);
}

SurfaceMesh surface_mesh_message(const BodyModel& body) {
  return std::visit([](const auto& kind) { return surface_mesh_message(kind); }, body);
}

ReceivedSurface from_wire(const SurfaceMesh& mesh) {
  const auto fail = [](const std::string& what) { throw cohaptic::Error("surface mesh: " + what); };
  if (mesh.vertices_size() % 3 != 0)
    fail(fmt::format("{} vertex coordinates, not a multiple of 3", mesh.vertices_size()));
  const int vertices = mesh.vertices_size() / 3;
  if (mesh.node_ids_size() != vertices)
    fail(fmt::format("{} node ids for {} vertices", mesh.node_ids_size(), vertices));
  if (mesh.triangles_size() % 3 != 0)
    fail(fmt::format("{} triangle indices, not a multiple of 3", mesh.triangles_size()));
  ReceivedSurface received;
  received.surface.vertices.resize(3, vertices);
  for (int i = 0; i < mesh.vertices_size(); ++i) {
    if (!std::isfinite(mesh.vertices(i)))
      fail(fmt::format("vertex {} has a non-finite coordinate", i / 3));
    received.surface.vertices.data()[i] = mesh.vertices(i);
  }
  received.node_ids.assign(mesh.node_ids().begin(), mesh.node_ids().end());
  received.surface.triangles.resize(static_cast<std::size_t>(mesh.triangles_size() / 3));
  for (int i = 0; i < mesh.triangles_size(); ++i) {
    const std::uint32_t v = mesh.triangles(i);
    if (v >= static_cast<std::uint32_t>(vertices))
      fail(fmt::format("triangle {} refers to vertex {}, there are {}", i / 3, v, vertices));
    received.surface.triangles[static_cast<std::size_t>(i / 3)][static_cast<std::size_t>(i % 3)] =
        static_cast<int>(v);
  }
  return received;
}

}  // namespace cohaptic::wire
