#pragma once
// The MPI operations of the distributed flow, on the ranks PETSc runs on (PETSC_COMM_WORLD;
// solvers/petsc_runtime.h starts them). MPI's types stay in comm.cpp, so that this header
// compiles without PETSc; in such a build every call throws PetscUnavailable.
//
// Reductions whose result must not depend on the order of arrival are made in a fixed order:
// every rank's partial sums are gathered on rank 0, added there in rank order and broadcast, so
// that a rerun on the same ranks is bitwise equal, and runs on different rank counts differ by
// rounding only (never a bare MPI_Allreduce of a sum, whose order MPI may vary).

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace mcf::dist {

/// This process's rank and the number of ranks (PETSC_COMM_WORLD; starts PETSc).
int rank();
int ranks();

/// Entry by entry Σ over ranks of `partial` (the same length on every rank), added on rank 0 in
/// rank order and broadcast: the same bits on every rank.
std::vector<double> ordered_sum(const std::vector<double>& partial);
double ordered_sum(double partial);
/// The largest of a value over the ranks (order-free).
double max_over_ranks(double value);
long long sum_over_ranks(long long value);
/// Whether the flag is set on any rank.
bool any_rank(bool flag);
/// Each rank's value, in rank order, on every rank.
std::vector<double> all_values(double value);
std::vector<long long> all_values(long long value);

/// Rank 0's message (empty: none) on every rank: a failure found on rank 0 alone (reading the
/// mesh) is then thrown on every rank (RankFailure).
std::string broadcast_message(const std::string& message);
/// Rank 0's bytes on every rank (the caller sizes nothing).
std::vector<std::uint8_t> broadcast_bytes(const std::vector<std::uint8_t>& bytes);

/// Point to point, for the scatter of the mesh and the gathers of the output: whole arrays, any
/// length (sent as their size, then in pieces of at most 2^30 elements).
void send(const std::vector<double>& v, int to, int tag);
void send(const std::vector<std::int64_t>& v, int to, int tag);
void send(const std::vector<int>& v, int to, int tag);
std::vector<double> receive_doubles(int from, int tag);
std::vector<std::int64_t> receive_int64s(int from, int tag);
std::vector<int> receive_ints(int from, int tag);

/// Waits until every rank arrives.
void barrier();

/// A failure that another rank has already reported: the command exits non-zero without
/// printing it again (tools/main.cpp), so that a bad input under P ranks gives one message.
struct RankFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace mcf::dist
