#include "common/mass_spring/tube_network.h"

#include <Eigen/Geometry>
#include <fmt/format.h>

#include <cmath>
#include <map>
#include <numbers>

#include "common/util/error.h"

namespace cohaptic {
namespace {

int centre(int section) { return kSectionNodes * section; }
int ring(int section, int k) { return kSectionNodes * section + 1 + (k + kRingNodes) % kRingNodes; }

// Points evenly spaced by arc length along the polyline.
std::vector<Eigen::Vector3d> resample(const std::vector<Eigen::Vector3d>& line, int count) {
  std::vector<double> arc{0};
  for (std::size_t i = 1; i < line.size(); ++i)
    arc.push_back(arc.back() + (line[i] - line[i - 1]).norm());
  std::vector<Eigen::Vector3d> points;
  std::size_t segment = 1;
  for (int i = 0; i < count; ++i) {
    const double s = arc.back() * i / (count - 1);
    while (segment + 1 < line.size() && arc[segment] < s) ++segment;
    const double span = arc[segment] - arc[segment - 1];
    const double t = span > 0 ? std::clamp((s - arc[segment - 1]) / span, 0.0, 1.0) : 0;
    points.push_back(line[segment - 1] + t * (line[segment] - line[segment - 1]));
  }
  return points;
}

double tet_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                  const Eigen::Vector3d& d) {
  return std::abs((b - a).cross(c - a).dot(d - a)) / 6;
}

}  // namespace

std::vector<std::array<int, 6>> tube_elements(int sections) {
  std::vector<std::array<int, 6>> prisms;
  for (int i = 0; i + 1 < sections; ++i)
    for (int k = 0; k < kRingNodes; ++k)
      prisms.push_back({centre(i), ring(i, k), ring(i, k + 1), centre(i + 1), ring(i + 1, k),
                        ring(i + 1, k + 1)});
  return prisms;
}

double prism_volume(const Eigen::Matrix3Xd& x, const std::array<int, 6>& p) {
  return tet_volume(x.col(p[0]), x.col(p[1]), x.col(p[2]), x.col(p[3])) +
         tet_volume(x.col(p[1]), x.col(p[2]), x.col(p[3]), x.col(p[4])) +
         tet_volume(x.col(p[2]), x.col(p[3]), x.col(p[4]), x.col(p[5]));
}

double enclosed_volume(const MassSpringNetwork& network, const Eigen::Matrix3Xd& x) {
  double six_volume = 0;
  for (const auto& t : network.triangles)
    six_volume += x.col(t[0]).dot(x.col(t[1]).cross(x.col(t[2])));
  return six_volume / 6;
}

MassSpringNetwork tube_network(const TubeGeometry& geometry, const TubeMaterial& material) {
  if (geometry.centre_line.size() < 2)
    throw Error("a tube's centre line needs at least two points");
  double length = 0;
  for (std::size_t i = 1; i < geometry.centre_line.size(); ++i)
    length += (geometry.centre_line[i] - geometry.centre_line[i - 1]).norm();
  if (!(length > 0) || !std::isfinite(length)) throw Error("a tube's centre line has no length");
  if (!(geometry.radius > 0))
    throw Error(fmt::format("a tube needs a positive radius, not {}", geometry.radius));
  if (geometry.sections < 2)
    throw Error(fmt::format("a tube needs at least 2 sections, not {}", geometry.sections));
  if (!(material.youngs_modulus > 0) || !(material.density > 0) || !(material.spring_damping >= 0))
    throw Error(
        "a tube needs a positive Young's modulus and density and a non-negative spring damping");

  const int sections = geometry.sections;
  const std::vector<Eigen::Vector3d> centres = resample(geometry.centre_line, sections);
  MassSpringNetwork network;
  network.rest_positions.resize(3, kSectionNodes * sections);
  // A frame per section, transported along the line so that the rings do not twist.
  Eigen::Vector3d previous_tangent = (centres[1] - centres[0]).normalized();
  Eigen::Vector3d u = geometry.up - geometry.up.dot(previous_tangent) * previous_tangent;
  if (u.norm() < 1e-9) u = previous_tangent.unitOrthogonal();
  u.normalize();
  for (int i = 0; i < sections; ++i) {
    const Eigen::Vector3d tangent =
        (centres[static_cast<std::size_t>(std::min(i + 1, sections - 1))] -
         centres[static_cast<std::size_t>(std::max(i - 1, 0))])
            .normalized();
    u = Eigen::Quaterniond::FromTwoVectors(previous_tangent, tangent) * u;
    u = (u - u.dot(tangent) * tangent).normalized();
    previous_tangent = tangent;
    const Eigen::Vector3d w = tangent.cross(u);
    network.rest_positions.col(centre(i)) = centres[static_cast<std::size_t>(i)];
    for (int k = 0; k < kRingNodes; ++k) {
      const double angle = 2 * std::numbers::pi * (k + 0.5) / kRingNodes;
      network.rest_positions.col(ring(i, k)) =
          centres[static_cast<std::size_t>(i)] +
          geometry.radius * (std::cos(angle) * u + std::sin(angle) * w);
    }
  }

  const int nodes = kSectionNodes * sections;
  network.mass = Eigen::VectorXd::Zero(nodes);
  network.held.assign(static_cast<std::size_t>(nodes), 0);
  std::map<std::pair<int, int>, double>
      element_volume;  // per spring: volume of the elements holding both ends
  auto add_spring = [&](int a, int b) { element_volume.emplace(std::minmax(a, b), 0.0); };
  for (int i = 0; i < sections; ++i)
    for (int k = 0; k < kRingNodes; ++k) {
      add_spring(ring(i, k), ring(i, k + 1));
      add_spring(centre(i), ring(i, k));
      if (i + 1 == sections) continue;
      add_spring(ring(i, k), ring(i + 1, k));
      add_spring(ring(i, k), ring(i + 1, k + 1));
      add_spring(ring(i, k), ring(i + 1, k - 1));
      add_spring(centre(i), ring(i + 1, k));
      add_spring(centre(i + 1), ring(i, k));
      if (k == 0) add_spring(centre(i), centre(i + 1));
    }
  for (const auto& prism : tube_elements(sections)) {
    const double volume = prism_volume(network.rest_positions, prism);
    for (int node : prism) network.mass[node] += material.density * volume / 6;
    for (int a = 0; a < 6; ++a)
      for (int b = a + 1; b < 6; ++b)
        if (auto found = element_volume.find(std::minmax(prism[static_cast<std::size_t>(a)],
                                                         prism[static_cast<std::size_t>(b)]));
            found != element_volume.end())
          found->second += volume;
  }
  for (const auto& [ends, volume] : element_volume) {
    Spring spring;
    spring.a = ends.first;
    spring.b = ends.second;
    spring.rest_length =
        (network.rest_positions.col(spring.b) - network.rest_positions.col(spring.a)).norm();
    spring.stiffness = material.youngs_modulus * volume / (spring.rest_length * spring.rest_length);
    spring.damping = material.spring_damping * spring.stiffness;
    network.springs.push_back(spring);
  }

  for (int i = 0; i + 1 < sections; ++i)
    for (int k = 0; k < kRingNodes; ++k) {
      network.triangles.push_back({ring(i, k), ring(i, k + 1), ring(i + 1, k + 1)});
      network.triangles.push_back({ring(i, k), ring(i + 1, k + 1), ring(i + 1, k)});
    }
  for (int k = 0; k < kRingNodes; ++k) {
    network.triangles.push_back({centre(0), ring(0, k + 1), ring(0, k)});
    network.triangles.push_back(
        {centre(sections - 1), ring(sections - 1, k), ring(sections - 1, k + 1)});
  }
  index_surface(network);
  return network;
}

}  // namespace cohaptic
