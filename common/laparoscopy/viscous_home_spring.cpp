#include "common/laparoscopy/viscous_home_spring.h"

#include <Eigen/Cholesky>
#include <algorithm>

#include "common/laparoscopy/home_spring_force.h"

namespace cohaptic {
namespace {

// The Hessian of E at `displacement`, each 1-ring spring's transverse term kept only while
// the spring is stretched (|L| > d): positive definite, since k1 > 0.
Eigen::Matrix3d home_spring_stiffness(const HomeSpringPatch& patch, int vertex,
                                      const Eigen::Vector3d& displacement) noexcept {
  const Eigen::Vector3d rest = patch.rest_positions.col(vertex);
  const Eigen::Vector3d current = rest + displacement;
  Eigen::Matrix3d ring = Eigen::Matrix3d::Zero();
  for (const int j : patch.ring(vertex)) {
    const Eigen::Vector3d neighbour = patch.rest_positions.col(j);
    const Eigen::Vector3d link = current - neighbour;
    const double length = link.norm();
    if (!(length > 0)) continue;
    const Eigen::Vector3d along = link / length;
    const Eigen::Matrix3d axial = along * along.transpose();
    const double stretch = std::max(0.0, 1 - (rest - neighbour).norm() / length);
    ring += axial + stretch * (Eigen::Matrix3d::Identity() - axial);
  }
  return patch.home_stiffness * Eigen::Matrix3d::Identity() + patch.neighbour_stiffness * ring;
}

// The vertex left alone over the tick: relaxed, and forgotten once it is home.
void relax(const HomeSpringPatch& patch, MovingVertex& moving, double dt) noexcept {
  moving.held = false;
  if (moving.vertex < 0) return;
  if (dt > 0)
    moving.displacement = relax_home_spring_vertex(patch, moving.vertex, moving.displacement, dt);
  if (!(moving.displacement.norm() >= kVertexAtHome)) moving = MovingVertex{};
}

}  // namespace

Eigen::Vector3d relax_home_spring_vertex(const HomeSpringPatch& patch, int vertex,
                                         const Eigen::Vector3d& displacement, double dt) noexcept {
  const Eigen::Matrix3d system = (patch.damping / dt) * Eigen::Matrix3d::Identity() +
                                 home_spring_stiffness(patch, vertex, displacement);
  return displacement - system.llt().solve(home_spring_load(patch, vertex, displacement));
}

HomeSpringContact evaluate_viscous_home_spring(const PreparedHomeSpringPatch& prepared,
                                               MovingVertex& moving, const Eigen::Vector3d& tool,
                                               double dt) noexcept {
  const HomeSpringPatch& patch = prepared.patch;
  HomeSpringContact contact = evaluate_home_spring(prepared, tool);
  const auto hold = [&] {
    moving = {contact.vertex,
              patch.surface_vertex[static_cast<std::size_t>(contact.vertex)],
              true,
              patch.grasp.active(),
              contact.contact_point,
              contact.displacement};
  };
  if (!(patch.damping > 0)) {
    if (contact.touching)
      hold();
    else
      moving = MovingVertex{};
    return contact;
  }
  if (!contact.touching) {
    relax(patch, moving, dt);
    return {};
  }
  const bool grasped = patch.grasp.active();
  const Eigen::Vector3d shaft = (tool - patch.trocar_pivot).normalized();  // pushes along it
  if (!moving.held || moving.grasped != grasped) {
    // A vertex still on its way home is reached once the tool is as deep along its shaft.
    if (!grasped && moving.vertex == contact.vertex) {
      relax(patch, moving, dt);
      if (moving.vertex >= 0 && (contact.displacement - moving.displacement).dot(shaft) < 0)
        return {};
    }
    hold();  // no damping term: the massless vertex jumps to the tool
    return contact;
  }
  const Eigen::Vector3d velocity =
      dt > 0 ? Eigen::Vector3d((contact.displacement - moving.displacement) / dt)
             : Eigen::Vector3d::Zero();
  const Eigen::Vector3d load = patch.damping * velocity - contact.force;  // -force: grad E
  if (!grasped && !(load.dot(shaft) > 0)) {
    relax(patch, moving, dt);  // drawn back faster than the vertex returns: let go
    return {};
  }
  hold();
  contact.force = -load;
  return contact;
}

void carry_moving_vertex(const HomeSpringPatch& to, MovingVertex& moving) noexcept {
  if (moving.vertex < 0) return;
  const auto touchable = to.surface_vertex.begin() + to.contact_vertex_count;
  const auto found = std::find(to.surface_vertex.begin(), touchable, moving.surface_vertex);
  if (found == touchable)
    moving = MovingVertex{};
  else
    moving.vertex = static_cast<int>(found - to.surface_vertex.begin());
}

}  // namespace cohaptic
