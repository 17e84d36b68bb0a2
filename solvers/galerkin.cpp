#include "solvers/galerkin.h"

#include "solvers/csc_view.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>

namespace mcf::multigrid_detail {

std::vector<int> transpose_positions(const SparseMatrix& C) {
  const Csc M(C);
  std::vector<int> transpose_pos(std::size_t(C.nonZeros()), -1);
  tbb::parallel_for(0, M.cols, [&](int J) {
    for (int e = M.outer[J]; e < M.outer[J + 1]; ++e) {
      const int i = M.inner[e];
      const int* b = M.inner + M.outer[i];
      const int* en = M.inner + M.outer[i + 1];
      const int* it = std::lower_bound(b, en, J);
      if (it != en && *it == J) transpose_pos[std::size_t(e)] = int(it - M.inner);
    }
  });
  return transpose_pos;
}

GalerkinPlan galerkin_plan(const Csc& A, const SparseMatrix& Pm, const SparseMatrix& Cm,
                           const std::vector<int>& column_order) {
  const Csc P(Pm);
  const int m = A.rows, q = P.cols;
  const int* Couter = Cm.outerIndexPtr();
  const int* Cinner = Cm.innerIndexPtr();
  const auto column = [&](int jj) {
    return column_order.empty() ? jj : column_order[std::size_t(jj)];
  };
  // A dot product's terms are named by their place in P's column (8 bits) and counted per entry
  // (8 bits): P's columns must be short.
  for (int I = 0; I < q; ++I)
    if (P.outer[I + 1] - P.outer[I] > 255) return {};
  GalerkinPlan plan;
  plan.scatter_start.assign(std::size_t(q) + 1, 0);
  plan.dot_start.assign(std::size_t(q) + 1, 0);
  plan.entry_start.assign(std::size_t(q) + 1, 0);
  std::vector<int> support(std::size_t(q), 0);
  // Local numbering of column J's fine rows in pass `pass`: slot[i] for rows with
  // stamp[i] == 2 J + pass (a thread may meet a column in both passes; the second numbers anew).
  struct Marks {
    std::vector<int> stamp, slot;
  };
  tbb::enumerable_thread_specific<Marks> marks([m] {
    return Marks{std::vector<int>(std::size_t(m), -1), std::vector<int>(std::size_t(m))};
  });
  // Walks column jj: numbers its support, then calls scatter(slot) for every scatter term,
  // dot(place in P's column, slot) for every dot-product term whose row lies in the support, and
  // entry(count) after each upper entry's terms, in the order galerkin_values visits them.
  const auto walk = [&](int jj, int pass, Marks& mk, auto&& scatter, auto&& dot, auto&& entry) {
    const int J = column(jj);
    const int mark = 2 * J + pass;
    int ns = 0;
    for (int p = P.outer[J]; p < P.outer[J + 1]; ++p) {
      const int t = P.inner[p];
      for (int a = A.outer[t]; a < A.outer[t + 1]; ++a) {
        const std::size_t i = std::size_t(A.inner[a]);
        if (mk.stamp[i] != mark) {
          mk.stamp[i] = mark;
          mk.slot[i] = ns++;
        }
        scatter(mk.slot[i]);
      }
    }
    for (int e = Couter[J]; e < Couter[J + 1]; ++e) {
      const int I = Cinner[e];
      if (I > J) break;
      int count = 0;
      for (int r = P.outer[I]; r < P.outer[I + 1]; ++r) {
        const std::size_t i = std::size_t(P.inner[r]);
        if (mk.stamp[i] != mark) continue;  // v is zero there
        dot(r - P.outer[I], mk.slot[i]);
        ++count;
      }
      entry(count);
    }
    return ns;
  };
  // Pass 1: counts and supports.
  tbb::parallel_for(tbb::blocked_range<int>(0, q, 64), [&](const tbb::blocked_range<int>& r) {
    Marks& mk = marks.local();
    for (int jj = r.begin(); jj < r.end(); ++jj) {
      std::int64_t ns_scatter = 0, ns_dot = 0, ns_entry = 0;
      support[std::size_t(jj)] = walk(
          jj, 0, mk, [&](int) { ++ns_scatter; }, [&](int, int) { ++ns_dot; },
          [&](int) { ++ns_entry; });
      plan.scatter_start[std::size_t(jj) + 1] = ns_scatter;
      plan.dot_start[std::size_t(jj) + 1] = ns_dot;
      plan.entry_start[std::size_t(jj) + 1] = ns_entry;
    }
  });
  const int largest = q ? *std::max_element(support.begin(), support.end()) : 0;
  for (std::size_t j = 0; j < std::size_t(q); ++j) {
    plan.scatter_start[j + 1] += plan.scatter_start[j];
    plan.dot_start[j + 1] += plan.dot_start[j];
    plan.entry_start[j + 1] += plan.entry_start[j];
  }
  const std::size_t bytes = 2 * std::size_t(plan.scatter_start.back()) +
                            3 * std::size_t(plan.dot_start.back()) +
                            std::size_t(plan.entry_start.back());
  const std::size_t a_bytes = std::size_t(A.outer[A.cols]) * (sizeof(int) + sizeof(double));
  if (largest > 65535 || bytes > a_bytes) return {};
  plan.max_support = largest;
  plan.support.assign(support.begin(), support.end());
  plan.scatter_slot.resize(std::size_t(plan.scatter_start.back()));
  plan.dot_slot.resize(std::size_t(plan.dot_start.back()));
  plan.dot_place.resize(std::size_t(plan.dot_start.back()));
  plan.dot_count.resize(std::size_t(plan.entry_start.back()));
  // Pass 2: the slots.
  tbb::parallel_for(tbb::blocked_range<int>(0, q, 64), [&](const tbb::blocked_range<int>& r) {
    Marks& mk = marks.local();
    for (int jj = r.begin(); jj < r.end(); ++jj) {
      std::uint16_t* sc = plan.scatter_slot.data() + plan.scatter_start[std::size_t(jj)];
      std::uint16_t* ds = plan.dot_slot.data() + plan.dot_start[std::size_t(jj)];
      std::uint8_t* dp = plan.dot_place.data() + plan.dot_start[std::size_t(jj)];
      std::uint8_t* dc = plan.dot_count.data() + plan.entry_start[std::size_t(jj)];
      walk(
          jj, 1, mk, [&](int s) { *sc++ = std::uint16_t(s); },
          [&](int place, int s) {
            *dp++ = std::uint8_t(place);
            *ds++ = std::uint16_t(s);
          },
          [&](int count) { *dc++ = std::uint8_t(count); });
    }
  });
  return plan;
}

void galerkin_values(const Csc& A, const SparseMatrix& Pm, const SparseMatrix& Cm, double* Cval,
                     const std::vector<int>& transpose_pos, const std::vector<int>& column_order,
                     Spa& spa, const GalerkinPlan* plan) {
  const Csc P(Pm);
  const int m = A.rows;
  const int* Couter = Cm.outerIndexPtr();
  const int* Cinner = Cm.innerIndexPtr();
  if (plan != nullptr && !plan->empty()) {
    tbb::parallel_for(
        tbb::blocked_range<int>(0, P.cols, 64), [&](const tbb::blocked_range<int>& r) {
          auto& v = spa.local();
          if (v.size() < std::size_t(plan->max_support) + 1)
            v.assign(std::size_t(plan->max_support) + 1, 0.0);
          double* b = v.data();
          for (int jj = r.begin(); jj < r.end(); ++jj) {
            const int J = column_order.empty() ? jj : column_order[std::size_t(jj)];
            std::fill(b, b + plan->support[std::size_t(jj)], 0.0);
            const std::uint16_t* sc =
                plan->scatter_slot.data() + plan->scatter_start[std::size_t(jj)];
            for (int p = P.outer[J]; p < P.outer[J + 1]; ++p) {
              const int t = P.inner[p];
              const double w = P.val[p];
              for (int a = A.outer[t]; a < A.outer[t + 1]; ++a) b[*sc++] += A.val[a] * w;
            }
            const std::uint16_t* ds = plan->dot_slot.data() + plan->dot_start[std::size_t(jj)];
            const std::uint8_t* dp = plan->dot_place.data() + plan->dot_start[std::size_t(jj)];
            const std::uint8_t* dc = plan->dot_count.data() + plan->entry_start[std::size_t(jj)];
            for (int e = Couter[J]; e < Couter[J + 1]; ++e) {
              const int I = Cinner[e];
              if (I > J) break;
              // The terms whose v is zero are left out: each would add +-0 to the sum.
              const double* pv = P.val + P.outer[I];
              double sum = 0.0;
              for (int k = *dc++; k > 0; --k) sum += pv[*dp++] * b[*ds++];
              Cval[e] = sum;
              const int t = transpose_pos[std::size_t(e)];
              if (t >= 0) Cval[t] = sum;
            }
          }
        });
    return;
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, P.cols, 64), [&](const tbb::blocked_range<int>& r) {
    auto& v = spa.local();
    if (v.size() < std::size_t(m)) v.assign(std::size_t(m), 0.0);
    for (int jj = r.begin(); jj < r.end(); ++jj) {
      const int J = column_order.empty() ? jj : column_order[std::size_t(jj)];
      for (int p = P.outer[J]; p < P.outer[J + 1]; ++p) {
        const int t = P.inner[p];
        const double w = P.val[p];
        for (int a = A.outer[t]; a < A.outer[t + 1]; ++a)
          v[std::size_t(A.inner[a])] += A.val[a] * w;
      }
      for (int e = Couter[J]; e < Couter[J + 1]; ++e) {
        const int I = Cinner[e];
        if (I > J) break;  // sorted: the rest is the mirror of columns > J
        double sum = 0.0;
        for (int q = P.outer[I]; q < P.outer[I + 1]; ++q)
          sum += P.val[q] * v[std::size_t(P.inner[q])];
        Cval[e] = sum;
        const int t = transpose_pos[std::size_t(e)];
        if (t >= 0) Cval[t] = sum;
      }
      for (int p = P.outer[J]; p < P.outer[J + 1]; ++p) {
        const int t = P.inner[p];
        for (int a = A.outer[t]; a < A.outer[t + 1]; ++a) v[std::size_t(A.inner[a])] = 0.0;
      }
    }
  });
}

}  // namespace mcf::multigrid_detail
