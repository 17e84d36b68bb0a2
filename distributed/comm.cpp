#include "distributed/comm.h"

#include "solvers/petsc_runtime.h"

#ifdef MCFBENCH_HAVE_PETSC
#include <petscsys.h>

#include <algorithm>
#include <climits>
#endif

namespace mcf::dist {

#ifndef MCFBENCH_HAVE_PETSC

namespace {
[[noreturn]] void unavailable() {
  throw PetscUnavailable("a flow across MPI ranks: " + petsc_unavailable_message());
}
}  // namespace

int rank() {
  return 0;
}
int ranks() {
  return 1;
}
std::vector<double> ordered_sum(const std::vector<double>& partial) {
  return partial;
}
double ordered_sum(double partial) {
  return partial;
}
double max_over_ranks(double value) {
  return value;
}
long long sum_over_ranks(long long value) {
  return value;
}
bool any_rank(bool flag) {
  return flag;
}
std::vector<double> all_values(double value) {
  return {value};
}
std::vector<long long> all_values(long long value) {
  return {value};
}
std::string broadcast_message(const std::string& message) {
  return message;
}
std::vector<std::uint8_t> broadcast_bytes(const std::vector<std::uint8_t>& bytes) {
  return bytes;
}
void send(const std::vector<double>&, int, int) {
  unavailable();
}
void send(const std::vector<std::int64_t>&, int, int) {
  unavailable();
}
void send(const std::vector<int>&, int, int) {
  unavailable();
}
std::vector<double> receive_doubles(int, int) {
  unavailable();
}
std::vector<std::int64_t> receive_int64s(int, int) {
  unavailable();
}
std::vector<int> receive_ints(int, int) {
  unavailable();
}
void barrier() {}

#else

namespace {

MPI_Comm world() {
  PetscRuntime::instance();
  return PETSC_COMM_WORLD;
}

void check(int code, const char* what) {
  if (code != MPI_SUCCESS) throw std::runtime_error(std::string("MPI: ") + what + " failed");
}

// Pieces of at most 2^30 elements: MPI counts are ints.
constexpr std::size_t kPiece = std::size_t(1) << 30;

template <class T>
void send_array(const std::vector<T>& v, MPI_Datatype type, int to, int tag) {
  const std::int64_t n = std::int64_t(v.size());
  check(MPI_Send(&n, 1, MPI_INT64_T, to, tag, world()), "MPI_Send");
  for (std::size_t at = 0; at < v.size(); at += kPiece)
    check(MPI_Send(v.data() + at, int(std::min(kPiece, v.size() - at)), type, to, tag, world()),
          "MPI_Send");
}

template <class T>
std::vector<T> receive_array(MPI_Datatype type, int from, int tag) {
  std::int64_t n = 0;
  check(MPI_Recv(&n, 1, MPI_INT64_T, from, tag, world(), MPI_STATUS_IGNORE), "MPI_Recv");
  std::vector<T> v(static_cast<std::size_t>(n));
  for (std::size_t at = 0; at < v.size(); at += kPiece)
    check(MPI_Recv(v.data() + at, int(std::min(kPiece, v.size() - at)), type, from, tag, world(),
                   MPI_STATUS_IGNORE),
          "MPI_Recv");
  return v;
}

}  // namespace

int rank() {
  return PetscRuntime::instance().rank();
}
int ranks() {
  return PetscRuntime::instance().size();
}

std::vector<double> ordered_sum(const std::vector<double>& partial) {
  const int p = ranks(), n = int(partial.size());
  std::vector<double> all(rank() == 0 ? std::size_t(p) * partial.size() : 0);
  check(MPI_Gather(partial.data(), n, MPI_DOUBLE, all.data(), n, MPI_DOUBLE, 0, world()),
        "MPI_Gather");
  std::vector<double> sum(partial.size(), 0.0);
  if (rank() == 0)
    for (int r = 0; r < p; ++r)
      for (int i = 0; i < n; ++i) sum[std::size_t(i)] += all[std::size_t(r) * partial.size() + i];
  check(MPI_Bcast(sum.data(), n, MPI_DOUBLE, 0, world()), "MPI_Bcast");
  return sum;
}

double ordered_sum(double partial) {
  return ordered_sum(std::vector<double>{partial})[0];
}

double max_over_ranks(double value) {
  double out = value;
  check(MPI_Allreduce(&value, &out, 1, MPI_DOUBLE, MPI_MAX, world()), "MPI_Allreduce");
  return out;
}

long long sum_over_ranks(long long value) {
  long long out = value;
  check(MPI_Allreduce(&value, &out, 1, MPI_LONG_LONG, MPI_SUM, world()), "MPI_Allreduce");
  return out;
}

bool any_rank(bool flag) {
  int mine = flag ? 1 : 0, out = 0;
  check(MPI_Allreduce(&mine, &out, 1, MPI_INT, MPI_MAX, world()), "MPI_Allreduce");
  return out != 0;
}

std::vector<double> all_values(double value) {
  std::vector<double> out(static_cast<std::size_t>(ranks()));
  check(MPI_Allgather(&value, 1, MPI_DOUBLE, out.data(), 1, MPI_DOUBLE, world()), "MPI_Allgather");
  return out;
}

std::vector<long long> all_values(long long value) {
  std::vector<long long> out(static_cast<std::size_t>(ranks()));
  check(MPI_Allgather(&value, 1, MPI_LONG_LONG, out.data(), 1, MPI_LONG_LONG, world()),
        "MPI_Allgather");
  return out;
}

std::vector<std::uint8_t> broadcast_bytes(const std::vector<std::uint8_t>& bytes) {
  std::int64_t n = std::int64_t(bytes.size());
  check(MPI_Bcast(&n, 1, MPI_INT64_T, 0, world()), "MPI_Bcast");
  std::vector<std::uint8_t> out = rank() == 0 ? bytes : std::vector<std::uint8_t>(std::size_t(n));
  for (std::size_t at = 0; at < out.size(); at += kPiece)
    check(
        MPI_Bcast(out.data() + at, int(std::min(kPiece, out.size() - at)), MPI_UINT8_T, 0, world()),
        "MPI_Bcast");
  return out;
}

std::string broadcast_message(const std::string& message) {
  const std::vector<std::uint8_t> bytes =
      broadcast_bytes(rank() == 0 ? std::vector<std::uint8_t>(message.begin(), message.end())
                                  : std::vector<std::uint8_t>{});
  return std::string(bytes.begin(), bytes.end());
}

void send(const std::vector<double>& v, int to, int tag) {
  send_array(v, MPI_DOUBLE, to, tag);
}
void send(const std::vector<std::int64_t>& v, int to, int tag) {
  send_array(v, MPI_INT64_T, to, tag);
}
void send(const std::vector<int>& v, int to, int tag) {
  send_array(v, MPI_INT, to, tag);
}
std::vector<double> receive_doubles(int from, int tag) {
  return receive_array<double>(MPI_DOUBLE, from, tag);
}
std::vector<std::int64_t> receive_int64s(int from, int tag) {
  return receive_array<std::int64_t>(MPI_INT64_T, from, tag);
}
std::vector<int> receive_ints(int from, int tag) {
  return receive_array<int>(MPI_INT, from, tag);
}

void barrier() {
  check(MPI_Barrier(world()), "MPI_Barrier");
}

#endif

}  // namespace mcf::dist
