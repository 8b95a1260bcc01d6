// The laparoscopy paper's Eq. 8 over a HomeSpringPatch, and the potential it derives from.
//
// With the touchable vertex v displaced by u from its rest position P_o (P_c = P_o + u),
// its home spring and its 1-ring springs store
//   E(u) = k1 |u|^2 / 2 + sum_j k2 (|L_j| - d_j)^2 / 2,  L_j = P_c - P_j,  d_j = |P_o - P_j|,
// with the neighbours P_j at rest. Eq. 8's total is the gradient of E:
//   F_total = k1 u + sum_j k2 (|L_j| - d_j) L_j / |L_j|,
// the load the tool must apply to hold the vertex there; the tool feels -F_total. The
// field is therefore conservative. Where P_c falls exactly on a neighbour's rest position
// (L_j = 0) that spring's direction is undefined and its term is taken as zero.
// Both functions are noexcept and allocation-free; the caller passes a touchable vertex
// of a validated patch. Units: m, N, J.
#pragma once

#include <Eigen/Core>

#include "common/laparoscopy/home_spring_patch.h"

namespace cohaptic {

/// E(u) [J] for touchable vertex `vertex` displaced by `displacement`.
double home_spring_energy(const HomeSpringPatch& patch, int vertex,
                          const Eigen::Vector3d& displacement) noexcept;

/// Eq. 8's F_total [N] = grad E(u): the load holding `vertex` displaced by `displacement`.
Eigen::Vector3d home_spring_load(const HomeSpringPatch& patch, int vertex,
                                 const Eigen::Vector3d& displacement) noexcept;

}  // namespace cohaptic
