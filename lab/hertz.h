// `cohaptic-lab hertz`: the sphere contact model against Hertz's solution, mesh by mesh.
//
// A rigid frictionless sphere of radius R pressed to depth d into an elastic half-space
// takes F = (4/3) E / (1 - nu^2) sqrt(R) d^(3/2) (Hertz; d << R). The half-space here is a
// block 40 R wide and 20 R deep, fixed at its bottom; one quarter of it is meshed (20 R
// on every side) with the sphere pressing at the corner where its two symmetry planes
// meet: each plane holds the axis normal to it, and the force on the whole block is four
// times the quarter's. The box mesh is fine under the sphere and coarse in the far field
// (box_mesher.h): with n cells per side, half of them are equal and fill a core of side
// `core` R at the corner (it holds every node a sphere at d/R <= 0.1 passes), and the
// other half grow geometrically from there to the block's far sides. The growth ratio r
// solves the fill; as n grows, r^(n/2) tends to a constant, so every mesh of the study
// refines the same map of the block. A tensor-product grading spends most of its nodes on
// fine columns far from the contact; the default is a quarter block meshed by gmsh with a
// size field around the contact point (scenes/hertz/quarter_block.geo, its element size at
// the contact given in R), or any quarter block's mesh file.
//
// At each depth the sphere model's force is the full sparse solve of its unilateral
// problem (sphere_contact_reference.h); beside it the paper's node translation model's
// force at the same tool position (the sphere's contact triangle moved with the tool,
// static_contact.h), whose stiffness grows without bound as the mesh is refined (a
// load on one triangle has no finite stiffness in 3-D elasticity). Units: SI.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "common/fem/linear_elastic_material.h"
#include "common/mesh/mesh_with_gmsh.h"
#include "lab/lab_command.h"

namespace cohaptic {

/// The quarter block and its mesh.
struct HertzBlock {
  double radius = 0.01;  ///< R [m]
  LinearElasticMaterial material{1.0e5, 0.3, ElementFormulation::linear_tet};
  int divisions = 16;  ///< cells along each side of the quarter block (>= 2)
  double core = 0.5;   ///< side of the uniformly meshed core under the sphere, in R (0 < core < 10)
  /// If set, the quarter block's mesh instead of the box: a .msh of [0, s]^2 x [-s, 0] with
  /// s >= 20 R, in millimetres, the contact point at the origin (scenes/hertz/quarter_block.geo).
  std::filesystem::path mesh;
  /// If set (and no `mesh`), the script gmsh meshes into that file (mesh_with_gmsh.h).
  std::optional<GmshScript> gmsh;
};

/// The growth ratio of the cells outside the core along a side of `block`'s quarter.
double hertz_cell_growth(const HertzBlock& block);

/// The block as scene text (units mm; its sphere tool `A` of radius R, contact model sphere).
/// Throws Error if `block.mesh` does not span the quarter block of `block.radius`.
std::string hertz_block_yaml(const HertzBlock& block);

/// Hertz's force [N] for a rigid sphere of radius `radius` [m] at depth `depth` [m] in a
/// half-space of `material`.
double hertz_force(const LinearElasticMaterial& material, double radius, double depth);

/// One mesh of the study: forces on the whole block (four quarters) at each depth.
struct HertzMesh {
  std::string name;  ///< "16 cells", "gmsh 0.05 R" or the mesh file's name
  double side = 0;   ///< the quarter block's side, over R (20 for box meshes)
  int nodes = 0, tets = 0;
  /// Under the sphere, over R: the core's cell side for a box mesh; the mean edge of the
  /// tetrahedra within 0.3 R of the contact point for a mesh file.
  double contact_cell = 0;
  std::vector<double> sphere_force;       ///< [N] per depth, the sphere model
  std::vector<int> contact_nodes;         ///< per depth: nodes the sphere pushes (in the quarter)
  std::vector<double> translation_force;  ///< [N] per depth, node translation
};

/// Solves `block` at each depth d = ratio R of `depth_ratios`. Throws Error if a ratio is
/// not in (0, 0.5].
HertzMesh measure_hertz(const HertzBlock& block, const std::vector<double>& depth_ratios);

/// The gmsh quarter block (scenes/hertz/quarter_block.geo) with element size `fine` R at
/// the contact, growing by `kHertzGmshGrowth` per unit distance.
constexpr double kHertzGmshGrowth = 0.07;
GmshScript hertz_quarter_block_script(const std::filesystem::path& geo, double fine);

struct HertzOptions {
  HertzBlock block;
  /// Where the meshes come from: the gmsh quarter block at each element size `gmsh_fine`
  /// (in R) by default; box meshes with these `divisions`; or these mesh files.
  enum class Meshes { gmsh, boxes, files } meshes_from = Meshes::gmsh;
  std::filesystem::path geo = "scenes/hertz/quarter_block.geo";
  std::vector<double> gmsh_fine = {0.05, 0.025};
  std::vector<int> divisions = {8, 12, 16, 24};
  std::vector<std::filesystem::path> meshes;
  std::vector<double> depth_ratios = {0.05, 0.1};
  std::filesystem::path out;  ///< empty: the table on stdout only; else also hertz.md, hertz.svg
};

/// The study's table (markdown): F / F_Hertz and the nodes in contact per mesh and depth
/// for both models, the change between the two finest meshes, and where the meshes come from.
std::string hertz_table(const HertzOptions& options, const std::vector<HertzMesh>& meshes);

/// Measures every mesh, prints the table, writes the files. Returns the exit code.
int run_hertz(const HertzOptions& options);

/// `cohaptic-lab hertz [--poisson-ratio NU] [--element E] [--gmsh-fine F... | --divisions N... |
/// --mesh FILE...]
/// [--depths D...] [--out DIR]`.
LabCommand add_hertz_command(CLI::App& lab);

}  // namespace cohaptic
