// The reference answer for sphere tools under the sphere contact model
// (common/contact/sphere_contact.h): full sparse FEM solves of the unilateral problem.
//
// The candidates are the nodes of the touchable triangles and those a rigid obstacle
// constrains (obstacle_constraints.h), less the held boundary nodes B, each held by the
// sphere or obstacle with the least gap (node_constraint). K is factored (CHOLMOD) with B's dofs
// prescribed; one solve gives the candidates' displacement u0 under B's displacements alone, and
// multi-right-hand-side solves the compliance L under unit forces at the free dofs of the
// working set's nodes (working_set_contact_solve.h), over the rows of every candidate. With
// A = N^T L N and q = g + N^T u0 the unilateral problem is solved over every candidate,
// without a work limit; its pushes lambda_i n_i are the tools' forces on the nodes, and
// -sum lambda_i n_i over a tool's nodes the force on the tool (an obstacle's pushes are no
// tool's).
//
// This is the slow path the intermediate representation is checked against: it shares
// neither the condensation nor the evaluator with it (only the working-set solve, which
// tests check against a dense solve over every candidate). Compliance columns are cached per
// node until the held set changes (then K is factored again), so a motion costs one
// factorisation per held set. Units: m, N. Not thread-safe (the cache grows).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <unordered_map>
#include <vector>

#include "common/contact/sphere_contact.h"
#include "common/fem/static_solve.h"
#include "common/model/static_contact.h"

namespace cohaptic {

struct SphereContactSolution {
  std::vector<int> candidates;                ///< every candidate (volume node), ascending
  std::vector<SphereConstraint> constraints;  ///< per candidate
  Eigen::VectorXd pushes;                     ///< lambda per candidate [N]; 0: released
  std::vector<Eigen::Vector3d> reactions;     ///< force on each tool [N] (zero if it holds nothing)

  /// The candidates in contact (lambda > 0), ascending.
  std::vector<int> contact_nodes() const;
};

class SphereContactReference {
 public:
  /// `body` must outlive the reference. `obstacles`: per volume node, its obstacle
  /// constraint (obstacle_constraints.h), or empty for none.
  explicit SphereContactReference(const ElasticBody& body,
                                  std::vector<SphereConstraint> obstacles = {});
  ~SphereContactReference();

  /// Every tool is a sphere (radius > 0). Also returns the displacement field (3N) if asked.
  /// Throws NumericalError if the problem cannot be solved.
  SphereContactSolution solve(const std::vector<PressedTool>& tools, const HeldNodes& held = {},
                              Eigen::VectorXd* displacement = nullptr);

  std::size_t factorisations() const { return factorisations_; }

 private:
  void factor_for(const HeldNodes& held);
  const Eigen::MatrixXd& columns_of(int node);
  void compute_columns(const std::vector<int>& nodes);

  const ElasticBody& body_;
  std::vector<SphereConstraint> obstacles_;  // per volume node, or empty
  std::vector<int> candidates_;  // nodes of the touchable triangles and the obstacles', ascending
  std::vector<int> candidate_row_;  // per volume node: its first row (3 per candidate), or -1
  std::vector<int> row_dofs_;       // global dof of each row
  std::vector<int> held_key_;
  std::unique_ptr<ConstrainedStaticSolver> solver_;
  std::unordered_map<int, Eigen::MatrixXd> columns_;  // node -> rows x 3 (its x, y, z unit forces)
  std::size_t factorisations_ = 0;
};

/// One-shot: SphereContactReference(body, obstacles).solve(tools, held).
SphereContactSolution sphere_reactions_reference(const ElasticBody& body,
                                                 const std::vector<PressedTool>& tools,
                                                 const HeldNodes& held = {},
                                                 Eigen::VectorXd* displacement = nullptr,
                                                 std::vector<SphereConstraint> obstacles = {});

}  // namespace cohaptic
