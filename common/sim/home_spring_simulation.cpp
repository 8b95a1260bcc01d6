#include "common/sim/home_spring_simulation.h"

#include <limits>

#include "common/laparoscopy/extract_home_spring_patch.h"
#include "common/util/stopwatch.h"

namespace cohaptic {

Eigen::Matrix3Xd dented_surface(const TissueDisplay& display, std::span<const TissueDent> dents) {
  Eigen::Matrix3Xd shown = display.rest;
  Eigen::Matrix3Xd dented(3, shown.cols());
  for (const TissueDent& dent : dents) {
    display_tissue(display, dent.from, dent.to, dented);
    shown += dented - display.rest;
  }
  return shown;
}

namespace {

// The corner of surface triangle `triangle` nearest `point` (the lowest corner on a tie),
// as the client picks the vertex of the triangle its shaft crosses.
int nearest_tissue_corner(const HomeSpringBody& body, int triangle, const Eigen::Vector3d& point) {
  int nearest = -1;
  double best = 0;
  for (const int v : body.surface.triangles[static_cast<std::size_t>(triangle)]) {
    const double d2 = (body.surface.vertices.col(v) - point).squaredNorm();
    if (nearest < 0 || d2 < best) {
      nearest = v;
      best = d2;
    }
  }
  return nearest;
}

ForcepsGeometry jaw_geometry(const InstrumentSpec& instrument) {
  return {instrument.jaw_length, instrument.open_angle, instrument.closing_step};
}

}  // namespace

HomeSpringSimulation::HomeSpringSimulation(const HomeSpringBody& body, int object,
                                           const std::vector<ToolSpec>& tools, double force_limit)
    : body_(body),
      object_(object),
      force_limit_(force_limit),
      beyond_tip_(
          (body.surface.vertices.rowwise().maxCoeff() - body.surface.vertices.rowwise().minCoeff())
              .norm() +
          body.longest_edge),
      users_(tools.size()) {
  for (std::size_t u = 0; u < tools.size(); ++u) {
    UserState& user = users_[u];
    user.instrument = tools[u].instrument;
    user.forceps = tools[u].shape == ToolShape::forceps;
    if (user.forceps) user.jaws = open_forceps(jaw_geometry(*user.instrument));
  }
}

void HomeSpringSimulation::set_tool(int user, const Eigen::Vector3d& position,
                                    std::uint32_t buttons) {
  UserState& state = users_[static_cast<std::size_t>(user)];
  state.known = position.allFinite();
  state.position = position;
  state.buttons = buttons;
}

void HomeSpringSimulation::clear_tool(int user) {
  users_[static_cast<std::size_t>(user)].known = false;
}

void HomeSpringSimulation::continue_epochs(int user, std::uint64_t epoch) {
  UserState& state = users_[static_cast<std::size_t>(user)];
  state.epoch = std::max(state.epoch, epoch);
}

double HomeSpringSimulation::distance_to_surface(const Eigen::Vector3d& point) const {
  return std::sqrt(body_.tree.closest_triangle(point).distance2);
}

StepReport HomeSpringSimulation::step(double time) {
  StepReport report;
  const Stopwatch watch;
  const double dt = previous_time_ ? std::max(0.0, time - *previous_time_) : 0;
  previous_time_ = time;
  for (int u = 0; u < user_count(); ++u) step_user(u, time, dt, report);
  if (report.rebuilt) report.rebuild_ms = watch.elapsed_ms();
  return report;
}

void HomeSpringSimulation::step_user(int u, double time, double dt, StepReport& report) {
  UserState& user = users_[static_cast<std::size_t>(u)];
  if (!user.instrument) return;
  if (!user.known) {
    if (user.forceps) user.jaws = open_forceps(jaw_geometry(*user.instrument));
    evaluate_user(user, dt);  // a viscous tissue's vertex goes on home
    return;
  }
  const auto shaft = shaft_frame(user.instrument->trocar, user.position, user.instrument->opening);
  if (!shaft) {
    evaluate_user(user, dt);
    return;
  }
  if (user.forceps)
    step_forceps(jaw_geometry(*user.instrument), *shaft, (user.buttons & 1u) != 0, body_.tree,
                 user.jaws);

  int centre = -1;
  if (user.jaws.grasping) {
    const AabbHit hit = body_.tree.closest_triangle(user.jaws.grasp_point);
    centre = nearest_tissue_corner(body_, hit.triangle, user.jaws.grasp_point);
  } else {
    // The shaft's line on through the tip, far enough to leave the tissue's bounds.
    const double reach = (user.position - shaft->pivot).norm() + beyond_tip_;
    const AabbCrossing hit =
        body_.tree.first_crossing(shaft->pivot, shaft->pivot + reach * shaft->axis);
    if (hit.triangle >= 0)
      centre = nearest_tissue_corner(body_, hit.triangle,
                                     shaft->pivot + hit.crossing.t * reach * shaft->axis);
    else if (user.grasped)
      centre =
          user.centre;  // released with the line off the tissue: the same patch, without the grasp
  }
  if (centre >= 0 && (!user.ir || centre != user.centre || user.jaws.grasping != user.grasped))
    publish_ir(u, centre, time, report);
  evaluate_user(user, dt);
}

void HomeSpringSimulation::evaluate_user(UserState& user, double dt) {
  user.pressing = false;
  user.dent.reset();
  user.force = {};
  if (!user.ir) return;
  const Eigen::Vector3d tool =
      user.known ? user.position
                 : Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  const ForceSample sample =
      evaluate_force_in_turn(*user.ir, user.evaluation, user.carry, tool, {}, dt);
  if (user.known) user.force = sample;
  user.pressing = (sample.flags & kInContact) != 0;
  const MovingVertex& moving = std::get<HomeSpringEvaluation>(user.evaluation.body).moving;
  if (moving.vertex < 0) return;
  const bool grasping = user.jaws.grasping;
  const Eigen::Vector3d from = grasping ? user.jaws.grasp_point : moving.contact_point;
  // A probe holding its vertex dents the surface to the tip itself.
  user.dent = TissueDent{
      from, moving.held && !grasping ? user.position : Eigen::Vector3d(from + moving.displacement)};
}

void HomeSpringSimulation::publish_ir(int u, int centre, double time, StepReport& report) {
  UserState& user = users_[static_cast<std::size_t>(u)];
  const HomeSpringObjectSpec& spec = body_.spec;
  HomeSpringPatch patch = extract_home_spring_patch(
      {body_.surface.vertices, body_.surface.triangles, body_.rings},
      body_.surface.vertices.col(centre), spec.patch_radius,
      {spec.home_stiffness, spec.neighbour_stiffness, spec.damping}, user.instrument->trocar);
  if (user.jaws.grasping)
    patch.grasp = {nearest_touchable_vertex(patch, user.jaws.grasp_point), user.jaws.tool_at_grasp};
  IntermediateRepresentation ir;
  ir.epoch = ++user.epoch;
  ir.simulation_time = time;
  ir.user = u;
  ir.object = object_;
  ir.force_limit = force_limit_;
  ir.body = std::move(patch);
  user.ir = std::make_shared<const PreparedIR>(prepare_ir(std::move(ir)));
  user.evaluation = make_evaluation_state(*user.ir);  // goes on from user.carry when evaluated
  user.centre = centre;
  user.grasped = user.jaws.grasping;
  report.rebuilt = true;
  report.recomputed = true;  // the patch was extracted: this body's counterpart of computing M~
  report.ir_bytes += user.ir->ir.size_bytes();
}

std::vector<TissueDent> HomeSpringSimulation::dents() const {
  std::vector<TissueDent> dents;
  for (const UserState& user : users_)
    if (user.dent) dents.push_back(*user.dent);
  return dents;
}

ForceSample HomeSpringSimulation::force(int u) const {
  return users_[static_cast<std::size_t>(u)].force;
}

}  // namespace cohaptic
