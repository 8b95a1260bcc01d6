// The several-objects paper's two boxes (Sec. 3.1) as FEM bodies, for the interaction's
// tests and benchmarks: the behind object B (86.5 x 130.8 x 108.7 mm, x from 0, its bottom
// z = 0 and its far face x = 86.5 mm fixed, E = 1.0 MPa, nu = 0.216 unless told) and a
// front object A (57.5 x 98.9 x 57.5 mm, centred on B's near face in y, standing on the
// same floor, its bottom fixed) `gap` in front of B's near face x = 0.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "common/fem/compliance.h"
#include "common/interaction/surface_adjacency.h"
#include "common/model/model.h"
#include "lab/objects_push.h"

namespace cohaptic::testing {

using cohaptic::paired_boxes_scene_yaml;
using cohaptic::PairedBoxesOptions;

/// Both bodies compiled, their surfaces' adjacency, B's compliance over its surface nodes.
struct PairedBoxesRig {
  std::unique_ptr<Model> model;
  const ElasticBody& front;
  const ElasticBody& behind;
  SurfaceAdjacency front_surface;
  SurfaceAdjacency behind_surface;
  std::unique_ptr<ComplianceColumns> behind_columns;
  std::vector<int> front_face;  ///< A's nodes on its face towards B, ascending
  explicit PairedBoxesRig(const PairedBoxesOptions& options = {});
};

}  // namespace cohaptic::testing
