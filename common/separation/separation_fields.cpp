#include "common/separation/separation_fields.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <fmt/format.h>

#include "common/separation/interface_condensation.h"
#include "common/separation/interface_regions.h"
#include "common/separation/polynomial_fit.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Principal axes of the symmetric `k`: z nearest `normal` (and along it), x nearest
// `tangent` (and along it), y = z x x, so that R^T k R is diagonal and R is a rotation.
Eigen::Matrix3d principal_frame(const Eigen::Matrix3d& k, const Eigen::Vector3d& normal,
                                const Eigen::Vector3d& tangent) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(k);
  const Eigen::Matrix3d v = eigen.eigenvectors();
  int z = 0;
  for (int a = 1; a < 3; ++a)
    if (std::abs(v.col(a).dot(normal)) > std::abs(v.col(z).dot(normal))) z = a;
  const int first = z == 0 ? 1 : 0, second = z == 2 ? 1 : 2;
  const int x =
      std::abs(v.col(first).dot(tangent)) >= std::abs(v.col(second).dot(tangent)) ? first : second;
  Eigen::Matrix3d frame;
  frame.col(2) = v.col(z) * (v.col(z).dot(normal) < 0 ? -1.0 : 1.0);
  frame.col(0) = v.col(x) * (v.col(x).dot(tangent) < 0 ? -1.0 : 1.0);
  frame.col(1) = frame.col(2).cross(frame.col(0));
  return frame;
}

// A unit tangent at the node: the global x axis projected on the tangent plane (y if x is
// nearly normal).
Eigen::Vector3d reference_tangent(const Eigen::Vector3d& normal) {
  Eigen::Vector3d t = Eigen::Vector3d::UnitX() - normal.x() * normal;
  if (t.norm() < 0.1) t = Eigen::Vector3d::UnitY() - normal.y() * normal;
  return t.normalized();
}

}  // namespace

const char* field_state_name(FieldState state) {
  switch (state) {
    case FieldState::connected:
      return "connected";
    case FieldState::locally_separated:
      return "locally separated";
    case FieldState::separated:
      return "separated";
  }
  return "?";
}

void validate(const FieldSettings& settings) {
  if (settings.degree < 1 || settings.degree > 9)
    throw Error(fmt::format("separation fields: degree must be 1..9, got {}", settings.degree));
  // An odd count samples zero deflection once, which constrains nothing.
  if (settings.samples_per_axis - settings.samples_per_axis % 2 < settings.degree)
    throw Error(fmt::format(
        "separation fields: samples_per_axis ({}) must give at least degree ({}) non-zero "
        "deflections (an odd count includes zero)",
        settings.samples_per_axis, settings.degree));
  if (!(settings.max_deflection > 0) || !std::isfinite(settings.max_deflection))
    throw Error(fmt::format("separation fields: max_deflection must be a positive length, got {}",
                            settings.max_deflection));
  if (settings.footprint_radii.empty() || settings.footprint_radii.size() > 8)
    throw Error(fmt::format("separation fields: 1..8 tool nodes (footprint_radii), got {}",
                            settings.footprint_radii.size()));
  for (double r : settings.footprint_radii)
    if (!(r >= 0) || !std::isfinite(r))
      throw Error(fmt::format("separation fields: a footprint radius must be >= 0, got {}", r));
}

std::span<const double> SeparationFields::block(int node, int tool_node, FieldState state) const {
  return const_cast<SeparationFields*>(this)->block(node, tool_node, state);
}

std::span<double> SeparationFields::block(int node, int tool_node, FieldState state) {
  const std::size_t size = static_cast<std::size_t>(block_size(degree));
  const std::size_t index =
      (static_cast<std::size_t>(node) * tool_node_count + tool_node) * kFieldStates +
      static_cast<std::size_t>(state);
  return {values.data() + index * size, size};
}

std::vector<int> tool_footprint(const SeparationInterface& interface, int node, double radius) {
  std::vector<int> footprint{node};
  for (int k = 0; k < interface.node_count(); ++k)
    if (k != node && (interface.positions.col(k) - interface.positions.col(node)).norm() <= radius)
      footprint.push_back(k);
  return footprint;
}

FieldStiffnesses field_stiffnesses(const SeparationBodies& bodies,
                                   const SeparationInterface& interface,
                                   const FieldSettings& settings, FieldPrecomputeReport* report) {
  validate(settings);
  const InterfaceCompliance compliance = interface_compliance(bodies, interface);
  auto start = Clock::now();
  const TiedInterface tied(compliance);
  const double tie_seconds = seconds_since(start);
  const NodeRegions regions = node_regions(interface.triangles, interface.node_count());
  const int tools = static_cast<int>(settings.footprint_radii.size());

  FieldStiffnesses out;
  out.stiffness.resize(static_cast<std::size_t>(interface.node_count()) * tools);
  start = Clock::now();
  for (int node = 0; node < interface.node_count(); ++node) {
    const std::vector<int> released = nodes_released_with(regions, interface.triangles, node);
    for (int j = 0; j < tools; ++j) {
      const std::vector<int> footprint =
          tool_footprint(interface, node, settings.footprint_radii[j]);
      const TiedInterface::FootprintCompliances c = tied.footprint_compliances(footprint, released);
      auto& k = out.stiffness[static_cast<std::size_t>(node) * tools + j];
      k[static_cast<int>(FieldState::connected)] = rigid_footprint_stiffness(c.connected);
      k[static_cast<int>(FieldState::locally_separated)] =
          rigid_footprint_stiffness(c.locally_separated);
      k[static_cast<int>(FieldState::separated)] = rigid_footprint_stiffness(c.separated);
    }
  }
  if (report) {
    report->compliance_seconds = compliance.seconds;
    report->tie_seconds = tie_seconds;
    report->stiffness_seconds = seconds_since(start);
    report->field_count = interface.node_count() * tools * kFieldStates;
  }
  return out;
}

SeparationFields precompute_separation_fields(const SeparationBodies& bodies,
                                              const SeparationInterface& interface,
                                              const FieldSettings& settings,
                                              FieldPrecomputeReport* report) {
  FieldPrecomputeReport local_report;
  FieldPrecomputeReport& r = report ? *report : local_report;
  const FieldStiffnesses stiffnesses = field_stiffnesses(bodies, interface, settings, &r);
  const int tools = static_cast<int>(settings.footprint_radii.size());
  const int d = settings.degree;
  const std::vector<double> abscissae =
      chebyshev_abscissae(settings.samples_per_axis, settings.max_deflection);

  SeparationFields fields;
  fields.degree = d;
  fields.node_count = interface.node_count();
  fields.tool_node_count = tools;
  fields.values.resize(static_cast<std::size_t>(fields.node_count) * tools * kFieldStates *
                       SeparationFields::block_size(d));
  std::vector<double> samples(abscissae.size());
  const auto start = Clock::now();
  const NodeRegions regions = node_regions(interface.triangles, interface.node_count());
  for (int node = 0; node < fields.node_count; ++node) {
    const Eigen::Vector3d normal =
        region_normal(interface.positions, interface.triangles, regions.of(node));
    const Eigen::Vector3d tangent = reference_tangent(normal);
    for (int j = 0; j < tools; ++j)
      for (int s = 0; s < kFieldStates; ++s) {
        const Eigen::Matrix3d& k =
            stiffnesses.stiffness[static_cast<std::size_t>(node) * tools + j][s];
        const Eigen::Matrix3d frame = principal_frame(k, normal, tangent);
        double* out = fields.block(node, j, static_cast<FieldState>(s)).data();
        Eigen::Map<Eigen::Matrix3d>{out} = frame;
        // The FEM force at each sampled deflection along each frame axis, its component
        // along that axis fitted; the other two components are what the fit leaves out.
        double largest_force = 0, largest_miss = 0;
        for (int a = 0; a < 3; ++a) {
          for (std::size_t i = 0; i < abscissae.size(); ++i)
            samples[i] = frame.col(a).dot(k * (abscissae[i] * frame.col(a)));
          const std::vector<double> c = fit_polynomial_through_origin(abscissae, samples, d);
          std::copy(c.begin(), c.end(), out + 9 + a * d);
        }
        for (int a = 0; a < 3; ++a)
          for (double sample : abscissae) {
            const Eigen::Vector3d delta = sample * frame.col(a);
            const Eigen::Vector3d fem = k * delta;
            const Eigen::Vector3d local = frame.transpose() * delta;
            Eigen::Vector3d fitted_local;
            for (int b = 0; b < 3; ++b)
              fitted_local[b] = polynomial_value(out + 9 + b * d, d, local[b]);
            largest_force = std::max(largest_force, fem.norm());
            largest_miss = std::max(largest_miss, (frame * fitted_local - fem).norm());
          }
        r.max_fit_error[s] =
            std::max(r.max_fit_error[s], largest_force > 0 ? largest_miss / largest_force : 0.0);
      }
  }
  r.fit_seconds = seconds_since(start);
  return fields;
}

}  // namespace cohaptic
