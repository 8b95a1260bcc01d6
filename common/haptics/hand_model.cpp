#include "common/haptics/hand_model.h"

#include <cmath>
#include <fmt/format.h>

#include "common/util/yaml_cursor.h"
#include "common/util/error.h"

namespace cohaptic {

void validate_hand_parameters(const HandParameters& p) {
  if (!(p.mass_kg > 0) || !std::isfinite(p.mass_kg))
    throw Error(fmt::format("hand model: expected a positive mass in kg, found {}", p.mass_kg));
  if (!(p.stiffness_n_per_m > 0) || !std::isfinite(p.stiffness_n_per_m))
    throw Error(fmt::format("hand model: expected a positive stiffness in N/m, found {}",
                            p.stiffness_n_per_m));
  if (!(p.damping_ns_per_m >= 0) || !std::isfinite(p.damping_ns_per_m))
    throw Error(
        fmt::format("hand model: expected a damping >= 0 in N s/m, found {}", p.damping_ns_per_m));
}

HandModelDevice::HandModelDevice(Trajectory reference, HandParameters parameters,
                                 double force_limit, double max_substep_s)
    : reference_(std::move(reference)),
      parameters_(parameters),
      force_limit_(force_limit),
      max_substep_(max_substep_s) {
  validate_hand_parameters(parameters_);
  if (!(force_limit_ > 0) || !std::isfinite(force_limit_))
    throw Error(fmt::format("hand model {}: expected a positive force limit in N, found {}",
                            reference_.source(), force_limit_));
  if (!(max_substep_ > 0) || max_substep_ > kDefaultMaxSubstep)
    throw Error(fmt::format("hand model: expected a sub-step in (0, {}] s, found {}",
                            kDefaultMaxSubstep, max_substep_));
  const double omega = std::sqrt(parameters_.stiffness_n_per_m / parameters_.mass_kg);
  if (omega * max_substep_ > 0.5)
    throw Error(fmt::format(
        "hand model: stiffness/mass too high for a {} s sub-step: sqrt(k/m) h = {:.3g} > 0.5",
        max_substep_, omega * max_substep_));
  if (parameters_.damping_ns_per_m / parameters_.mass_kg * max_substep_ > 0.5)
    throw Error(fmt::format(
        "hand model: damping/mass too high for a {} s sub-step: c h / m = {:.3g} > 0.5",
        max_substep_, parameters_.damping_ns_per_m / parameters_.mass_kg * max_substep_));
  state_.time_s = 0.0;
  state_.position = reference_.position(0.0);
  state_.velocity.setZero();
}

std::string HandModelDevice::describe() const {
  return fmt::format("hand:{} (m {} kg, k {} N/m, c {} N s/m, {:.3f} s, force limit {} N)",
                     reference_.source(), parameters_.mass_kg, parameters_.stiffness_n_per_m,
                     parameters_.damping_ns_per_m, reference_.duration(), force_limit_);
}

void HandModelDevice::advance_to(double time_s) {
  if (!(time_s > state_.time_s)) return;  // not later (or NaN): nothing to integrate
  double t0 = state_.time_s;
  // The tolerance keeps a gap of exactly k sub-steps (up to round-off) at k, not k + 1.
  auto n = static_cast<std::int64_t>(std::ceil((time_s - t0) / max_substep_ - 1e-9));
  if (n >
      kMaxSubstepsPerRead) {  // a stall: integrate the last stretch only, freeze the arm before it
    const double integrated = static_cast<double>(kMaxSubstepsPerRead) * max_substep_;
    skipped_s_ += (time_s - t0) - integrated;
    t0 = time_s - integrated;
    n = kMaxSubstepsPerRead;
  }
  if (n < 1) n = 1;
  const double h = (time_s - t0) / static_cast<double>(n);
  const double m = parameters_.mass_kg;
  const double k = parameters_.stiffness_n_per_m;
  const double c = parameters_.damping_ns_per_m;
  Eigen::Vector3d x = state_.position;
  Eigen::Vector3d v = state_.velocity;
  for (std::int64_t i = 0; i < n; ++i) {
    const double t = t0 + static_cast<double>(i) * h;
    const Eigen::Vector3d r = reference_.position(t);
    const Eigen::Vector3d rd = reference_.velocity(t);
    const Eigen::Vector3d a = (k * (r - x) + c * (rd - v) + force_) / m;
    v += h * a;
    x += h * v;
  }
  state_.position = x;
  state_.velocity = v;
  state_.time_s = time_s;
  substeps_ += static_cast<std::uint64_t>(n);
}

DeviceState HandModelDevice::read(double time_s) {
  advance_to(time_s);
  DeviceState out;
  out.position = state_.position;
  out.buttons = reference_.buttons(time_s);  // the hand presses what its script says
  out.valid = true;
  return out;
}

void HandModelDevice::write_force(const Eigen::Vector3d& force, double /*time_s*/) {
  if (force.allFinite()) {
    force_ = force;
  } else {
    force_.setZero();
    ++non_finite_forces_;
  }
}

std::optional<HandParameters> parse_hand_parameters(const std::string& yaml,
                                                    const std::string& name) {
  using Cursor = YamlCursor;
  const Cursor top(load_yaml(yaml, name), "", &name, 1);
  if (!top.is_map()) top.fail("a map");
  const auto hand = top.find("hand");
  if (!hand) return std::nullopt;
  hand->only_keys({"mass", "stiffness", "damping"});
  HandParameters p;
  if (auto mass = hand->find("mass")) p.mass_kg = mass->positive("a positive mass in kg");
  if (auto stiffness = hand->find("stiffness"))
    p.stiffness_n_per_m = stiffness->positive("a positive stiffness in N/m");
  if (auto damping = hand->find("damping")) {
    p.damping_ns_per_m = damping->number();
    if (p.damping_ns_per_m < 0) damping->fail("a damping >= 0 in N s/m");
  }
  return p;
}

std::optional<HandParameters> load_hand_parameters(const std::filesystem::path& file) {
  const std::string name = file.string();
  return parse_hand_parameters(read_text_file(name), name);
}

}  // namespace cohaptic
