#pragma once
// A sparsity pattern built once from element-local (row, col) slots, then filled many times
// from per-element local values without locks: each nonzero gathers the slots that land on it
// in a fixed order, so assembly is parallel and bitwise deterministic for any thread count.

#include "bases/basis.h"

#include <Eigen/SparseCore>

#include <cstdint>
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

  /// values[nz] = Σ local[slot] over the slots of nonzero nz (parallel over nonzeros); `values`
  /// is resized to non_zeros().
  void gather(const std::vector<double>& local, std::vector<double>& values) const;

  /// Values on this pattern (non_zeros() of them, in CSC order) seen as a matrix, so that several
  /// matrices on the pattern share its index arrays.
  SparseView view(const std::vector<double>& values) const {
    return view_of(outer_, inner_, values);
  }

  std::size_t num_slots() const { return slot_of_.size(); }

  /// The slots that land on nonzero nz, ascending: for element-aware gathers that read fewer
  /// bytes than one local value per slot (HatBasis::update reads per-face values).
  std::span<const int> slots(Eigen::Index nz) const {
    return {slot_of_.data() + first_[std::size_t(nz)],
            std::size_t(first_[std::size_t(nz) + 1] - first_[std::size_t(nz)])};
  }
  const std::vector<int>& outer() const { return outer_; }
  const std::vector<int>& inner() const { return inner_; }

 private:
  std::vector<int> outer_, inner_;  // the pattern: column starts and row indices
  std::vector<int> first_;          // per nonzero: range into slot_of_
  std::vector<int> slot_of_;        // slots grouped by nonzero, ascending slot order
};

}  // namespace mcf
