// The separation-forces paper's Fig. 10 as data: a tool holds the pulled body at one
// interface node, pulls it away from the base at a constant speed and brings it back.
//
// The loop runs step_contact at a fixed tick. It turns back at the paper's point C — the
// node's region D_n fully separated, or fracture no longer able to hold the force — when
// the fracture has stopped after starting, or at `max_travel`; it ends where it started.
// Phases: AB, loading up to point B, where the force first meets the fracture threshold (a
// sample is inserted there, inside the tick that crossed it); BC, from B to the turn (the
// tick that reaches C is redone in 32 sub-ticks and the loop turns at the first that does),
// so that BC starts and ends at B and C whatever the tick; CA, the way back. Works (trapezoidal
// over the samples, F . dx, F the force on the pulled body) are what the hand does on the tissue:
// net_work >= 0 means the loop took energy from the hand (passive). Units: m, s, N, J, m^2.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "common/separation/separation_contact.h"

namespace cohaptic {

struct PullLoopSettings {
  int node = 0;                                         ///< interface node held
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  ///< unit; zero: the node's normal
  double speed = 0.01;                                  ///< [m/s]
  double tick = 1e-3;                                   ///< [s]
  double max_travel = 0.02;                             ///< [m]
  ContactMode mode = ContactMode::grasp;
};

enum class PullPhase : char { loading = 'A', fracture = 'B', unloading = 'C' };

struct PullLoopSample {
  double time = 0;             ///< [s]
  double travel = 0;           ///< tool displacement along the pull [m]
  double force = 0;            ///< F . direction on the pulled body [N]
  double normal_force = 0;     ///< F . n [N]
  double separated_area = 0;   ///< Lambda [m^2]
  double local_separated = 0;  ///< A(R-bar) of the node
  PullPhase phase = PullPhase::loading;
};

struct PullLoop {
  std::vector<PullLoopSample> samples;
  double threshold = 0;        ///< J_c l(direction): F_n = J_c l_n for a normal pull [N]
  double fracture_work = 0;    ///< the hand's work over BC [J]
  double fracture_area = 0;    ///< area separated over BC [m^2]
  double fracture_travel = 0;  ///< normal travel over BC [m]
  double net_work = 0;         ///< over the whole loop [J]
  double turn_travel = 0;      ///< where it turned back [m]
  double final_energy = 0;     ///< the fields' potential at the end [J] (c may have moved)
};

/// Throws Error for a node out of range or a non-positive speed, tick or max_travel.
PullLoop run_pull_loop(const SeparationPatch& patch, const SeparationState& initial,
                       const PullLoopSettings& settings);

/// Where a tool holding interface node `node` touches: c on the node's first triangle.
ContactPoint contact_at_node(const SeparationPatch& patch, int node);

}  // namespace cohaptic
