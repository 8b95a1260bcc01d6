// `cohaptic-lab objects-push`: the several-objects paper's three-condition experiment
// (Sec. 3.2, Figs. 6-8) on its two boxes, quasi-statically (common/interaction/
// push_conditions.h): the front object A (57.5 x 98.9 x 57.5 mm, springs of 100 N/m
// along its tetrahedra's edges, its bottom fixed) pushed at the centre of its front face
// towards B, 1 to 15 mm deep, with its back face free, fixed, or resting on B (86.5 x
// 130.8 x 108.7 mm, linear FEM, E = 1.0 MPa, nu = 0.216, its bottom and far face fixed);
// then on B with E_B 1.0 / 1.5 / 2.0 MPa (Fig. 7) and nu_B 0.108 / 0.162 / 0.216 (Fig. 8).
// Writes objects_push.csv (every curve), objects_push.md (the forces at 5, 10, 15 mm) and
// objects_push_{conditions,youngs,poisson}.svg (the figures) into --out.
// The boxes' scene: A is the scene's object `front` (only its tetrahedra and its fixed
// bottom are used; its springs replace its material), B the object `behind`, A's back
// face `gap` in front of B's near face x = 0. Units: SI inside; the scene in mm.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "common/interaction/push_conditions.h"
#include "common/model/model.h"
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

struct PushRigOptions {
  /// The paper's sizes: A 60 nodes (its 69), B 1,950 (its 1,906); A touching B.
  PairedBoxesOptions boxes{{9, 14, 12}, {3, 4, 2}, 1.0e6, 0.216, 0};
  double spring_stiffness = 100;  ///< [N/m]
  double spring_damping = 0.10;   ///< [N s/m] (no force at equilibrium)
};

/// The two boxes compiled, A as a spring network pushed at its front face's centre along
/// +x, B's compliance over its surface.
struct PushRig {
  std::unique_ptr<Model> model;
  PushedFront front;
  SurfaceAdjacency behind_surface;
  std::unique_ptr<ComplianceColumns> behind_columns;
  explicit PushRig(const PushRigOptions& options = {});
  const ElasticBody& behind() const;
  BehindBody behind_body() { return {behind(), behind_surface, *behind_columns}; }
};

/// 1, 2, ..., 15 mm [m].
std::vector<double> paper_push_depths();

/// The tool's force at each of `depths` [N].
std::vector<double> push_forces(PushRig& rig, BackCondition condition, const std::vector<double>& depths);

struct ObjectsPushOptions {
  std::filesystem::path out;
};

int run_objects_push(const ObjectsPushOptions& options);

LabCommand add_objects_push_command(CLI::App& lab);

}  // namespace cohaptic
