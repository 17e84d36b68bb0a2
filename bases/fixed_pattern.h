#pragma once
// A sparsity pattern built once from element-local (row, col) slots: each nonzero knows the slots
// that land on it, in ascending order, so a basis can fill its values many times by gathering per
// nonzero from per-element values, without locks, in parallel and bitwise the same for any thread
// count (HatBasis::update).

#include "bases/basis.h"

#include <Eigen/SparseCore>

#include <span>
#include <vector>

namespace mcf {

class FixedPattern {
 public:
  FixedPattern() = default;
  /// rows/cols: one entry per local slot (element e, slot s stored at e * slots + s); at most
  /// 2^31 - 1 slots (std::length_error otherwise).
  FixedPattern(Eigen::Index dimension, const std::vector<int>& rows, const std::vector<int>& cols);

  Eigen::Index non_zeros() const { return Eigen::Index(inner_.size()); }

  /// Values on this pattern (non_zeros() of them, in CSC order) seen as a matrix, so that several
  /// matrices on the pattern share its index arrays.
  SparseView view(const std::vector<double>& values) const {
    return view_of(outer_, inner_, values);
  }

  /// The slots that land on nonzero nz, ascending.
  std::span<const int> slots(Eigen::Index nz) const {
    return {slot_of_.data() + first_[std::size_t(nz)],
            std::size_t(first_[std::size_t(nz) + 1] - first_[std::size_t(nz)])};
  }
  /// Column starts: the nonzeros of column j are [outer()[j], outer()[j + 1]).
  const std::vector<int>& outer() const { return outer_; }

 private:
  std::vector<int> outer_, inner_;  // the pattern: column starts and row indices
  std::vector<int> first_;          // per nonzero: range into slot_of_
  std::vector<int> slot_of_;        // slots grouped by nonzero, ascending slot order
};

}  // namespace mcf
