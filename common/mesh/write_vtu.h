// Writer for VTK XML UnstructuredGrid files (.vtu) of a TetMesh (or a triangle surface)
// and fields on its nodes, for looking at meshes and results in ParaView.
//
// Data arrays are ASCII with 17 significant digits (exact doubles); cells are VTK_TETRA
// (type 10) in the mesh's node order. Besides the caller's point fields the file always
// holds a point field "node_tag" and a cell field "element_tag" (Int64), the ids of the
// source file (index + 1 where the mesh has none). Units are the mesh's (metres inside
// cohaptic). The file is written to "<path>.tmp" and renamed: a failed write leaves no file.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "common/mesh/tet_mesh.h"

namespace cohaptic {

/// A field on the nodes: one row per component (1 for a scalar, 3 for a vector),
/// one column per node, in mesh node order.
struct VtuPointField {
  std::string name;
  Eigen::MatrixXd values;
};

/// Writes `mesh` with `point_fields` to `path`. Throws Error naming the field if a field
/// has not mesh.node_count() columns, has no rows, a non-finite value, an empty or
/// repeated name, or the reserved name "node_tag"; throws Error naming the path and the
/// system's reason if the file cannot be written.
void write_vtu(const std::filesystem::path& path, const TetMesh& mesh,
               const std::vector<VtuPointField>& point_fields);

/// The same for a triangle surface (VTK_TRIANGLE cells, no element tags): e.g. a deformed
/// boundary surface for display.
void write_surface_vtu(const std::filesystem::path& path, const Eigen::Matrix3Xd& vertices,
                       const std::vector<Triangle>& triangles,
                       const std::vector<std::int64_t>& vertex_tags,
                       const std::vector<VtuPointField>& point_fields);

}  // namespace cohaptic
