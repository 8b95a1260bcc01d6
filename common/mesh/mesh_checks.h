// Checks a tetrahedral mesh before it is used, naming the offending element or node.
//
// Errors (thrown as MeshError): a mix of positively and negatively oriented tetrahedra
// (tangled or inverted elements), zero-volume elements. (A face shared by more than two
// tetrahedra is caught by extract_boundary_surface, which runs next.) Findings that still give a
// usable model are returned as warnings: coincident (duplicate) nodes, disconnected parts,
// non-manifold surface edges or vertices, sliver elements (smallest dihedral angle below a
// threshold). A mesh whose elements are all negatively oriented is a convention, not an error: it
// is reoriented.
#pragma once

#include <string>
#include <vector>

#include "common/mesh/boundary_surface.h"
#include "common/mesh/tet_mesh.h"
#include "common/mesh/triangle_surface.h"

namespace cohaptic {

struct MeshCheckOptions {
  double sliver_angle_deg = 1.0;           ///< warn below this smallest dihedral angle
  double duplicate_tolerance = 1e-9;       ///< relative to the bounding-box diagonal
  double degenerate_volume_ratio = 1e-12;  ///< |V| / (longest edge)^3 below this is zero volume
};

struct MeshCheckReport {
  std::vector<std::string> warnings;  ///< each names the element(s) or node(s) concerned
  std::vector<std::string> notes;     ///< changes made (reorientation)
  int parts = 1;                      ///< face-connected components
  double min_dihedral_deg = 0;        ///< smallest dihedral angle of any element
};

/// Validates and, where harmless, repairs orientation in place. Throws MeshError.
MeshCheckReport check_tet_mesh(TetMesh& mesh, const MeshCheckOptions& options = {});

/// Surface findings of the boundary of a tet mesh (non-manifold edges and vertices).
std::vector<std::string> check_boundary_surface(const TetMesh& mesh,
                                                const BoundarySurface& surface);

/// Findings for a standalone surface (open or non-manifold edges), e.g. an obstacle.
std::vector<std::string> check_triangle_surface(const TriangleSurface& surface,
                                                const std::string& name);

/// Smallest dihedral angle of tetrahedron t, in degrees.
double min_dihedral_angle_deg(const TetMesh& mesh, int t);

}  // namespace cohaptic
