// `cohaptic-lab objects-push`: the several-objects paper's three-condition experiment
// (Sec. 3.2, Figs. 6-8) on its two boxes (scenes/objects/push.yaml): the front object A
// (57.5 x 98.9 x 57.5 mm, a lattice of springs of 100 N/m along its tetrahedra's edges,
// its bottom fixed) pushed at the centre of its front face towards B, 1 to 15 mm deep,
// with its back face free, fixed, or resting on B (86.5 x 130.8 x 108.7 mm, linear FEM,
// E = 1.0 MPa, nu = 0.216, its bottom and far face fixed); then on B with E_B 1.0 / 1.5 /
// 2.0 MPa (Fig. 7) and nu_B 0.108 / 0.162 / 0.216 (Fig. 8). Quasi-statically
// (common/interaction/push_conditions.h), and with --in-time also in time, through the
// server's simulation (lab/push_in_time.h). Writes objects_push.csv (every curve),
// objects_push.md (the forces at 5, 10, 15 mm) and objects_push_{conditions,youngs,
// poisson}.svg (the figures) into --out; in time also objects_push_in_time.csv (every
// server step), objects_push_in_time.md (in time beside quasi-static at 5, 10, 15 mm) and
// objects_push_in_time.svg. paired_boxes_scene_yaml is the two boxes as FEM bodies, for
// the interaction's tests and benchmarks. Units: SI inside; the scenes in mm.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "common/interaction/push_conditions.h"
#include "common/model/model.h"
#include "common/scene/scene.h"
#include "lab/lab_command.h"

namespace CLI {
class App;
}

namespace cohaptic {

struct PairedBoxesOptions {
  Eigen::Vector3i behind_divisions{4, 6, 5};
  Eigen::Vector3i front_divisions{3, 5, 3};
  double behind_youngs_modulus = 1.0e6;  ///< [Pa]
  double behind_poisson_ratio = 0.216;
  double gap_mm = 1;
};

std::string paired_boxes_scene_yaml(const PairedBoxesOptions& options = {});

/// A condition of the pushing test and B's material, applied to the test's scene.
struct PushVariation {
  BackCondition condition = BackCondition::on_behind;
  double behind_youngs_modulus = 1.0e6;  ///< [Pa]
  double behind_poisson_ratio = 0.216;
};

/// The test's scene (scenes/objects/push.yaml): exactly one interaction, its front object a
/// `lattice:` mass-spring object (A) and its behind object a box-meshed linear elastic one
/// (B), A in front of B along the axis joining their centres most. Throws Error otherwise.
struct PushLayout {
  int front = -1, behind = -1;  ///< object indices
  int axis = 0;                 ///< A is pushed along + this axis, towards B
  double back = 0;              ///< A's back face (towards B) on that axis [m]
};
PushLayout push_layout(const Scene& scene);

/// `scene` varied: B's material set; free: without the interaction; fixed: without it and
/// with A's back face held.
Scene push_scene(Scene scene, const PushVariation& variation);

/// The test's scene compiled (condition 3 with `variation`'s material), A as a spring
/// network pushed at its front face's centre, B's compliance over its surface.
struct PushRig {
  std::unique_ptr<Model> model;
  PushLayout layout;
  PushedFront front;
  SurfaceAdjacency behind_surface;
  std::unique_ptr<ComplianceColumns> behind_columns;
  PushRig(const Scene& scene, const PushVariation& variation);
  const ElasticBody& behind() const;
  BehindBody behind_body() { return {behind(), behind_surface, *behind_columns}; }
};

/// 1, 2, ..., 15 mm [m].
std::vector<double> paper_push_depths();

/// The point the tool pushes: the centre of A's front face [m].
Eigen::Vector3d push_point(const Scene& scene, const PushLayout& layout);

/// The tool's force at each of `depths` [N], quasi-statically.
std::vector<double> push_forces(PushRig& rig, BackCondition condition,
                                const std::vector<double>& depths);

struct ObjectsPushOptions {
  std::filesystem::path scene = "scenes/objects/push.yaml";
  std::filesystem::path out;
  bool in_time = false;  ///< also push in time through the server's simulation (push_in_time.h)
};

int run_objects_push(const ObjectsPushOptions& options);

LabCommand add_objects_push_command(CLI::App& lab);

}  // namespace cohaptic
