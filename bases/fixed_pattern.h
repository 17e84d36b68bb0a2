#pragma once
// A sparsity pattern built once from element-local (row, col) slots, then filled many times
// from per-element local values without locks: each nonzero gathers the slots that land on it
// in a fixed order, so assembly is parallel and bitwise deterministic for any thread count.

#include <Eigen/SparseCore>

#include <cstdint>
#include <vector>

namespace mcf {

class FixedPattern {
 public:
  FixedPattern() = default;
  /// rows/cols: one entry per local slot (element e, slot s stored at e * slots + s).
  FixedPattern(Eigen::Index dimension, const std::vector<int>& rows, const std::vector<int>& cols);

  /// A compressed matrix with this pattern and zero values.
  const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& zero_matrix() const { return zero_; }

  /// values[nz] = Σ local[slot] over the slots of nonzero nz (parallel over nonzeros).
  void gather(const std::vector<double>& local, Eigen::SparseMatrix<double, Eigen::ColMajor, int>& out) const;

  std::size_t num_slots() const { return slot_of_.size(); }

 private:
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> zero_;
  std::vector<std::int64_t> first_;   // per nonzero: range into slot_of_
  std::vector<std::int64_t> slot_of_; // slots grouped by nonzero, ascending slot order
};

}  // namespace mcf
