#include "common/condense/normal_compliance.h"

#include <fmt/format.h>

#include <algorithm>

#include "common/condense/dof_blocks.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

constexpr Eigen::Index kFirstCapacity = 64;

}  // namespace

NormalCompliance::NormalCompliance(ComplianceColumns& columns, const DofMap& dofs,
                                   Eigen::Index expected_candidates)
    : columns_(columns),
      dofs_(dofs),
      slot_of_node_(static_cast<std::size_t>(dofs.node_count()), -1) {
  grow(std::clamp(expected_candidates, kFirstCapacity, kMaxInitialCapacity));
}

int NormalCompliance::slot_of(int node) const {
  return node >= 0 && node < static_cast<int>(slot_of_node_.size())
             ? slot_of_node_[static_cast<std::size_t>(node)]
             : -1;
}

bool NormalCompliance::current(int node, const Eigen::Vector3d& direction) const {
  const int slot = slot_of(node);
  return slot >= 0 && slot_direction_.col(slot) == direction;
}

void NormalCompliance::grow(Eigen::Index capacity) {
  const Eigen::Index old = w_.rows(), dofs = p_.rows();
  const auto resize_square = [&](Eigen::MatrixXd& m) {
    Eigen::MatrixXd grown = Eigen::MatrixXd::Identity(capacity, capacity);
    grown.topLeftCorner(old, old) = m;
    m = std::move(grown);
  };
  resize_square(w0_);
  resize_square(w_);
  for (Eigen::MatrixXd* m : {&p_, &q_}) {
    Eigen::MatrixXd grown = Eigen::MatrixXd::Zero(dofs, capacity);
    grown.leftCols(old) = *m;
    *m = std::move(grown);
  }
  Eigen::Matrix3Xd directions = Eigen::Matrix3Xd::Zero(3, capacity);
  directions.leftCols(old) = slot_direction_;
  slot_direction_ = std::move(directions);
  Eigen::VectorXd clearance = Eigen::VectorXd::Zero(capacity);
  clearance.head(old) = free_clearance_;
  free_clearance_ = std::move(clearance);
  nonnegative_.resize(static_cast<std::size_t>(capacity), 1);
}

bool NormalCompliance::update(std::span<const int> nodes, const Eigen::Matrix3Xd& directions,
                              const IncrementalCondensation& condensation,
                              const Eigen::VectorXd& boundary_displacement) {
  std::vector<char> wanted(slot_of_node_.size(), 0);
  for (int node : nodes) {
    if (node < 0 || node >= static_cast<int>(wanted.size()) ||
        wanted[static_cast<std::size_t>(node)])
      throw Error(fmt::format(
          "normal compliance: candidate node {} is listed twice or is no mesh node", node));
    if (condensation.in_boundary(node))
      throw Error(
          fmt::format("normal compliance: candidate node {} is held as a boundary node", node));
    wanted[static_cast<std::size_t>(node)] = 1;
  }
  // Leaving nodes (and those with a new direction) free their slots; joining nodes take the
  // lowest free slot, or a new one.
  for (int slot = 0; slot < slot_count(); ++slot) {
    const int node = node_of_slot_[static_cast<std::size_t>(slot)];
    if (node < 0 || (wanted[static_cast<std::size_t>(node)] && current(node, directions.col(node))))
      continue;
    node_of_slot_[static_cast<std::size_t>(slot)] = -1;
    slot_of_node_[static_cast<std::size_t>(node)] = -1;
    free_slots_.push_back(slot);
    for (Eigen::MatrixXd* m : {&w0_, &w_}) {
      m->row(slot).setZero();
      m->col(slot).setZero();
      (*m)(slot, slot) = 1;
    }
    p_.col(slot).setZero();
    q_.col(slot).setZero();
  }
  std::sort(free_slots_.begin(), free_slots_.end(), std::greater<>());
  std::vector<int> joined;
  for (int node : nodes) {
    if (slot_of_node_[static_cast<std::size_t>(node)] >= 0) continue;
    int slot = slot_count();
    if (!free_slots_.empty()) {
      slot = free_slots_.back();
      free_slots_.pop_back();
    } else {
      node_of_slot_.push_back(-1);
      if (slot_count() > capacity()) grow(2 * capacity());
    }
    node_of_slot_[static_cast<std::size_t>(slot)] = node;
    slot_of_node_[static_cast<std::size_t>(node)] = slot;
    slot_direction_.col(slot) = directions.col(node);
    joined.push_back(slot);
  }
  std::sort(joined.begin(), joined.end());

  const bool boundary_changed = condensation.boundary_nodes() != boundary_;
  if (boundary_changed) {
    boundary_ = condensation.boundary_nodes();
    boundary_dofs_ = free_dofs_of_nodes(dofs_, boundary_);
    p_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(boundary_dofs_.size()), capacity());
    q_ = p_;
  }
  if (static_cast<Eigen::Index>(boundary_dofs_.size()) != boundary_displacement.size())
    throw Error(fmt::format("normal compliance: {} held displacements for {} free dofs of B",
                            boundary_displacement.size(), boundary_dofs_.size()));
  std::vector<int> every_slot;
  for (int slot = 0; slot < slot_count(); ++slot)
    if (node_of(slot) >= 0) every_slot.push_back(slot);
  // A joining slot's W0 and P; with a new B, every slot's P (W0 is kept).
  add_columns(boundary_changed ? std::span<const int>(every_slot) : std::span<const int>(joined),
              joined);
  condense(boundary_changed ? std::span<const int>(every_slot) : std::span<const int>(joined),
           condensation);
  free_clearance_.setZero();
  if (!boundary_dofs_.empty())
    for (int slot : every_slot) free_clearance_[slot] = q_.col(slot).dot(boundary_displacement);
  find_nonnegative_rows(joined, boundary_changed);
  const bool kept_slots =
      static_cast<Eigen::Index>(every_slot.size()) > static_cast<Eigen::Index>(joined.size());
  return boundary_changed && kept_slots;
}

void NormalCompliance::add_columns(std::span<const int> slots, std::span<const int> joined) {
  if (slots.empty()) return;
  std::vector<int> nodes;
  for (int slot : slots) nodes.push_back(node_of(slot));
  columns_.compute_columns(nodes);  // one solve per group for any not cached yet
  std::vector<char> is_joined(static_cast<std::size_t>(slot_count()), 0);
  for (int slot : joined) is_joined[static_cast<std::size_t>(slot)] = 1;
  std::vector<int> row_of_slot(static_cast<std::size_t>(slot_count()), -1);
  for (int slot = 0; slot < slot_count(); ++slot)
    if (node_of(slot) >= 0)
      row_of_slot[static_cast<std::size_t>(slot)] = columns_.row_position(node_of(slot));
  std::vector<Eigen::Index> row_of_boundary_dof;
  for (int dof : boundary_dofs_)
    row_of_boundary_dof.push_back(3 * columns_.row_position(dof / 3) + dof % 3);
  for (int b : slots) {
    // L[rows, b] n_b: the displacement of every row node under b's unit normal push.
    const Eigen::VectorXd moved = columns_.column(node_of(b)) * normal(b);
    for (std::size_t d = 0; d < row_of_boundary_dof.size(); ++d)
      p_(static_cast<Eigen::Index>(d), b) = moved[row_of_boundary_dof[d]];
    if (!is_joined[static_cast<std::size_t>(b)]) continue;  // its W0 is kept
    for (int a = 0; a < slot_count(); ++a) {
      const int row = row_of_slot[static_cast<std::size_t>(a)];
      if (row < 0 || (is_joined[static_cast<std::size_t>(a)] && a > b))
        continue;  // two joined: the pair once
      w0_(a, b) = w0_(b, a) = normal(a).dot(moved.segment<3>(3 * row));
    }
  }
}

void NormalCompliance::condense(std::span<const int> slots,
                                const IncrementalCondensation& condensation) {
  if (slots.empty()) return;
  Eigen::MatrixXd p_listed(p_.rows(), static_cast<Eigen::Index>(slots.size()));
  for (std::size_t i = 0; i < slots.size(); ++i)
    p_listed.col(static_cast<Eigen::Index>(i)) = p_.col(slots[i]);
  if (p_.rows() > 0) {
    const Eigen::MatrixXd q_listed = condensation.solve_boundary(p_listed);
    for (std::size_t i = 0; i < slots.size(); ++i)
      q_.col(slots[i]) = q_listed.col(static_cast<Eigen::Index>(i));
  }
  // Each pair once, P of the lower slot against Q of the higher, so that W is symmetric
  // bit for bit whichever way a pair was reached.
  const auto pair = [&](int a, int b) {
    const int low = std::min(a, b), high = std::max(a, b);
    const double value = w0_(low, high) - (p_.rows() > 0 ? p_.col(low).dot(q_.col(high)) : 0.0);
    w_(low, high) = w_(high, low) = value;
  };
  std::vector<char> listed(static_cast<std::size_t>(slot_count()), 0);
  for (int slot : slots) listed[static_cast<std::size_t>(slot)] = 1;
  for (int b : slots)
    for (int a = 0; a < slot_count(); ++a)
      if (node_of(a) >= 0 && !(listed[static_cast<std::size_t>(a)] && a > b)) pair(a, b);
}

void NormalCompliance::find_nonnegative_rows(std::span<const int> joined, bool all) {
  const auto scan = [&](int a) {
    bool nonnegative = true;
    if (node_of(a) >= 0)
      for (int b = 0; b < slot_count() && nonnegative; ++b)
        nonnegative = node_of(b) < 0 || w_(a, b) >= 0;
    nonnegative_[static_cast<std::size_t>(a)] = nonnegative;
  };
  if (all) {
    for (int a = 0; a < slot_count(); ++a) scan(a);
    return;
  }
  // A joining slot's row is scanned; in the other rows only its column is new. A row that
  // lost its only negative entry to a leaving slot stays flagged: that costs a check, never
  // an answer.
  for (int b : joined) {
    scan(b);
    for (int a = 0; a < slot_count(); ++a)
      if (node_of(a) >= 0 && w_(a, b) < 0) nonnegative_[static_cast<std::size_t>(a)] = 0;
  }
}

}  // namespace cohaptic
