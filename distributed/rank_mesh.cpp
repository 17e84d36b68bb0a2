#include "distributed/rank_mesh.h"

#include "bases/vertex_ordering.h"
#include "core/undirected_graph.h"
#include "distributed/comm.h"
#include "solvers/petsc_runtime.h"

#include <algorithm>
#include <cstdlib>
#include <numeric>
#include <stdexcept>

#ifdef MCFBENCH_HAVE_PETSC
#include <dlfcn.h>
#include <petscmat.h>
#endif

namespace mcf::dist {
namespace {

// Message tags of the scatter.
enum Tag : int {
  kTagInput = 100,
  kTagPositions,
  kTagFaces,
  kTagGhosts,
  kTagGhostPositions,
  kTagGhostOwners
};

/// Consecutive blocks of the bandwidth ordering, as equal as the count allows.
std::vector<int> ordered_blocks(const Triangles& faces, int vertex_count, int parts) {
  const std::vector<int> order = bandwidth_ordering(faces, vertex_count);
  std::vector<int> part(std::size_t(vertex_count), 0);
  for (std::size_t k = 0; k < order.size(); ++k)
    part[std::size_t(order[k])] = int((std::int64_t(k) * parts) / std::int64_t(order.size()));
  return part;
}

#ifdef MCFBENCH_HAVE_PETSC
/// PT-Scotch's partition through MatPartitioning on one process; empty if it failed.
std::vector<int> scotch_parts(const Triangles& faces, int vertex_count, int parts) {
  std::vector<std::pair<int, int>> pairs;
  pairs.reserve(3 * std::size_t(faces.rows()));
  for (Eigen::Index f = 0; f < faces.rows(); ++f)
    for (int c = 0; c < 3; ++c) pairs.emplace_back(faces(f, c), faces(f, (c + 1) % 3));
  std::vector<int> start, neighbour;
  undirected_graph(vertex_count, pairs, start, neighbour);
  pairs = {};
  PetscRuntime::instance();
  // MatCreateMPIAdj takes the arrays over (PetscMalloc'd, freed with the matrix).
  PetscInt *ia = nullptr, *ja = nullptr;
  petsc_check(PetscMalloc1(std::size_t(vertex_count) + 1, &ia), "PetscMalloc1");
  petsc_check(PetscMalloc1(std::max<std::size_t>(neighbour.size(), 1), &ja), "PetscMalloc1");
  std::copy(start.begin(), start.end(), ia);
  std::copy(neighbour.begin(), neighbour.end(), ja);
  Mat adjacency = nullptr;
  petsc_check(
      MatCreateMPIAdj(PETSC_COMM_SELF, vertex_count, vertex_count, ia, ja, nullptr, &adjacency),
      "MatCreateMPIAdj");
  // The same partition on every run, and so the same result files: PT-Scotch's threads divide
  // its work differently from run to run (measured: three runs, three partitions), and it draws
  // random numbers seeded per run unless reset. So one thread (SCOTCH_PTHREAD_NUMBER, read when it
  // partitions; a user's own setting is kept), and its generator reset first — the symbol is
  // PT-Scotch's (PETSc loads it), looked up so that nothing links it directly.
  setenv("SCOTCH_PTHREAD_NUMBER", "1", /*overwrite=*/0);
  using Reset = void (*)();
  if (const auto reset = reinterpret_cast<Reset>(dlsym(RTLD_DEFAULT, "SCOTCH_randomReset")))
    reset();
  MatPartitioning partitioning = nullptr;
  IS is = nullptr;
  std::vector<int> part;
  petsc_check(MatPartitioningCreate(PETSC_COMM_SELF, &partitioning), "MatPartitioningCreate");
  const PetscErrorCode code = [&]() -> PetscErrorCode {
    PetscCall(MatPartitioningSetAdjacency(partitioning, adjacency));
    PetscCall(MatPartitioningSetType(partitioning, MATPARTITIONINGPTSCOTCH));
    PetscCall(MatPartitioningSetNParts(partitioning, parts));
    PetscCall(MatPartitioningApply(partitioning, &is));
    const PetscInt* p = nullptr;
    PetscCall(ISGetIndices(is, &p));
    part.assign(p, p + vertex_count);
    PetscCall(ISRestoreIndices(is, &p));
    return 0;
  }();
  if (is) ISDestroy(&is);
  MatPartitioningDestroy(&partitioning);
  MatDestroy(&adjacency);
  if (code != 0) part.clear();
  return part;
}
#endif

}  // namespace

std::vector<int> partition_vertices(const Triangles& faces, int vertex_count, int parts,
                                    std::string* method) {
  if (parts < 1) throw std::invalid_argument("partition_vertices: parts must be at least 1");
  std::vector<int> part;
  if (parts == 1) {
    part.assign(std::size_t(vertex_count), 0);
    if (method) *method = "one part";
    return part;
  }
#ifdef MCFBENCH_HAVE_PETSC
  part = scotch_parts(faces, vertex_count, parts);
#endif
  std::vector<std::int64_t> size(std::size_t(parts), 0);
  bool sound = part.size() == std::size_t(vertex_count);
  for (const int p : part) {
    if (p < 0 || p >= parts) {
      sound = false;
      break;
    }
    ++size[std::size_t(p)];
  }
  sound = sound && std::all_of(size.begin(), size.end(), [](std::int64_t s) { return s > 0; });
  if (sound) {
    if (method) *method = "ptscotch";
    return part;
  }
  if (vertex_count < parts)
    throw std::invalid_argument("the mesh has " + std::to_string(vertex_count) +
                                " vertices, fewer than the " + std::to_string(parts) + " ranks");
  if (method) *method = "blocks of the bandwidth ordering";
  return ordered_blocks(faces, vertex_count, parts);
}

namespace {

/// The whole mesh as the one part of a single rank.
RankMesh one_part(const TriangleMesh& whole, OutputMap* output) {
  RankMesh m;
  m.global_vertices = whole.num_vertices();
  m.global_faces = whole.num_faces();
  m.owned = int(whole.num_vertices());
  m.first_of = {0, m.global_vertices};
  m.input_index.resize(std::size_t(m.owned));
  std::iota(m.input_index.begin(), m.input_index.end(), std::int64_t(0));
  m.vertices = whole.vertices;
  m.faces = whole.faces;
  m.counted.assign(std::size_t(whole.num_faces()), 1);
  m.partitioner = "one part";
  if (output) {
    output->faces = whole.faces;
    output->input_of_global = m.input_index;
  }
  return m;
}

/// Rank 0's plan of the scatter: each input vertex's part and global number, and the input
/// vertices in the bandwidth ordering.
struct ScatterPlan {
  std::vector<int> part;
  std::vector<std::int64_t> global_of;
  std::vector<int> order;
  std::vector<std::int64_t> first;  ///< per part its first global number; first[P] = vertices
  std::string method;
};

ScatterPlan plan_scatter(const TriangleMesh& whole, int P) {
  ScatterPlan plan;
  const int nv = int(whole.num_vertices());
  plan.part = partition_vertices(whole.faces, nv, P, &plan.method);
  plan.first.assign(std::size_t(P) + 1, 0);
  for (const int p : plan.part) ++plan.first[std::size_t(p) + 1];
  for (int r = 0; r < P; ++r) plan.first[std::size_t(r) + 1] += plan.first[std::size_t(r)];
  // Each part numbered in the bandwidth ordering (bases/vertex_ordering.h): neighbours get
  // nearby numbers, the order in which the smoothers' Gauss-Seidel sweeps go.
  plan.order = bandwidth_ordering(whole.faces, nv);
  plan.global_of.resize(std::size_t(nv));
  std::vector<std::int64_t> next(plan.first.begin(), plan.first.end() - 1);
  for (const int v : plan.order)
    plan.global_of[std::size_t(v)] = next[std::size_t(plan.part[std::size_t(v)])]++;
  return plan;
}

/// The sizes every rank needs (global vertices and faces, each rank's first global vertex), from
/// rank 0 to all; `whole` and `plan` are read on rank 0 only.
void share_sizes(const TriangleMesh& whole, const ScatterPlan& plan, RankMesh& m) {
  std::vector<std::int64_t> header;  // global vertices, global faces, first_of[0 .. P]
  if (m.rank == 0) {
    header = {whole.num_vertices(), whole.num_faces()};
    header.insert(header.end(), plan.first.begin(), plan.first.end());
  }
  std::vector<std::uint8_t> bytes(header.size() * sizeof(std::int64_t));
  std::copy_n(reinterpret_cast<const std::uint8_t*>(header.data()), bytes.size(), bytes.data());
  bytes = broadcast_bytes(bytes);
  header.resize(bytes.size() / sizeof(std::int64_t));
  std::copy_n(bytes.data(), bytes.size(), reinterpret_cast<std::uint8_t*>(header.data()));
  m.global_vertices = header[0];
  m.global_faces = header[1];
  m.first_of.assign(header.begin() + 2, header.end());
  m.first = m.first_of[std::size_t(m.rank)];
  m.owned = int(m.first_of[std::size_t(m.rank) + 1] - m.first);
  m.partitioner = broadcast_message(plan.method);
}

/// One rank's piece as rank 0 sends it: its owned vertices (input indices, positions), its
/// triangles on global numbers, and its ghosts (global numbers, increasing; positions; owners).
struct Piece {
  std::vector<std::int64_t> input, faces, ghosts;
  std::vector<double> positions, ghost_positions;
  std::vector<int> ghost_owners;
};

/// Each face in the buckets of the parts of its corners (once per part), in input order:
/// bucket[start[r] .. start[r + 1]) are part r's faces.
struct FaceBuckets {
  std::vector<std::int64_t> start;
  std::vector<int> bucket;
};

FaceBuckets face_buckets(const TriangleMesh& whole, const std::vector<int>& part, int P) {
  FaceBuckets b;
  b.start.assign(std::size_t(P) + 1, 0);
  const auto parts_of = [&](Eigen::Index f, int out[3]) {
    int n = 0;
    for (int c = 0; c < 3; ++c) {
      const int p = part[std::size_t(whole.faces(f, c))];
      if (std::find(out, out + n, p) == out + n) out[n++] = p;
    }
    return n;
  };
  int ps[3];
  for (Eigen::Index f = 0; f < whole.num_faces(); ++f)
    for (int k = 0, n = parts_of(f, ps); k < n; ++k) ++b.start[std::size_t(ps[k]) + 1];
  for (int r = 0; r < P; ++r) b.start[std::size_t(r) + 1] += b.start[std::size_t(r)];
  b.bucket.resize(static_cast<std::size_t>(b.start[std::size_t(P)]));
  std::vector<std::int64_t> at(b.start.begin(), b.start.end() - 1);
  for (Eigen::Index f = 0; f < whole.num_faces(); ++f)
    for (int k = 0, n = parts_of(f, ps); k < n; ++k)
      b.bucket[std::size_t(at[std::size_t(ps[k])]++)] = int(f);
  return b;
}

/// Part r's piece of the whole mesh; `owned` its vertices in the bandwidth ordering.
void make_piece(const TriangleMesh& whole, const ScatterPlan& plan, const FaceBuckets& buckets,
                const std::vector<int>& owned, int r, Piece& piece) {
  piece.input.assign(owned.begin(), owned.end());
  piece.positions.resize(3 * piece.input.size());
  for (std::size_t i = 0; i < piece.input.size(); ++i)
    for (int c = 0; c < 3; ++c)
      piece.positions[3 * i + std::size_t(c)] = whole.vertices(Eigen::Index(piece.input[i]), c);
  piece.faces.clear();
  std::vector<std::int64_t>& ghosts = piece.ghosts;
  ghosts.clear();
  for (std::int64_t b = buckets.start[std::size_t(r)]; b < buckets.start[std::size_t(r) + 1]; ++b)
    for (int c = 0; c < 3; ++c) {
      const int v = whole.faces(buckets.bucket[std::size_t(b)], c);
      piece.faces.push_back(plan.global_of[std::size_t(v)]);
      if (plan.part[std::size_t(v)] != r) ghosts.push_back(v);  // input index for now
    }
  std::sort(ghosts.begin(), ghosts.end(), [&](std::int64_t a, std::int64_t b) {
    return plan.global_of[std::size_t(a)] < plan.global_of[std::size_t(b)];
  });
  ghosts.erase(std::unique(ghosts.begin(), ghosts.end()), ghosts.end());
  piece.ghost_positions.resize(3 * ghosts.size());
  piece.ghost_owners.resize(ghosts.size());
  for (std::size_t k = 0; k < ghosts.size(); ++k) {
    const auto v = Eigen::Index(ghosts[k]);
    for (int c = 0; c < 3; ++c)
      piece.ghost_positions[3 * k + std::size_t(c)] = whole.vertices(v, c);
    piece.ghost_owners[k] = plan.part[std::size_t(v)];
    ghosts[k] = plan.global_of[std::size_t(v)];
  }
}

void send_piece(const Piece& piece, int r) {
  send(piece.input, r, kTagInput);
  send(piece.positions, r, kTagPositions);
  send(piece.faces, r, kTagFaces);
  send(piece.ghosts, r, kTagGhosts);
  send(piece.ghost_positions, r, kTagGhostPositions);
  send(piece.ghost_owners, r, kTagGhostOwners);
}

Piece receive_piece() {
  Piece piece;
  piece.input = receive_int64s(0, kTagInput);
  piece.positions = receive_doubles(0, kTagPositions);
  piece.faces = receive_int64s(0, kTagFaces);
  piece.ghosts = receive_int64s(0, kTagGhosts);
  piece.ghost_positions = receive_doubles(0, kTagGhostPositions);
  piece.ghost_owners = receive_ints(0, kTagGhostOwners);
  return piece;
}

/// Rank 0: every other rank's piece sent, its own returned (last, so that the others start
/// their set-up early), and the output map filled.
Piece send_pieces(const TriangleMesh& whole, const ScatterPlan& plan, int P, OutputMap* output) {
  const FaceBuckets buckets = face_buckets(whole, plan.part, P);
  std::vector<std::vector<int>> owned_of(static_cast<std::size_t>(P));
  for (const int v : plan.order) owned_of[std::size_t(plan.part[std::size_t(v)])].push_back(v);
  Piece piece;
  for (int step = 1; step <= P; ++step) {
    const int r = step % P;
    make_piece(whole, plan, buckets, owned_of[std::size_t(r)], r, piece);
    if (r != 0) send_piece(piece, r);
  }
  if (output) {
    const int nv = int(whole.num_vertices());
    output->faces = whole.faces;
    output->input_of_global.resize(std::size_t(nv));
    for (int v = 0; v < nv; ++v)
      output->input_of_global[std::size_t(plan.global_of[std::size_t(v)])] = v;
  }
  return piece;
}

/// The rank's mesh from its piece: owned vertices then ghosts, triangles on local numbers.
void take_piece(Piece piece, RankMesh& m) {
  if (std::int64_t(piece.input.size()) != m.owned)
    throw std::logic_error("scatter_mesh: the piece's owned count differs from the header's");
  m.input_index = std::move(piece.input);
  m.ghost_global = std::move(piece.ghosts);
  m.ghost_owner = std::move(piece.ghost_owners);
  const int n = m.local_vertices();
  m.vertices.resize(n, 3);
  for (int i = 0; i < m.owned; ++i)
    for (int c = 0; c < 3; ++c)
      m.vertices(i, c) = piece.positions[3 * std::size_t(i) + std::size_t(c)];
  for (int k = 0; k < m.ghosts(); ++k)
    for (int c = 0; c < 3; ++c)
      m.vertices(m.owned + k, c) = piece.ghost_positions[3 * std::size_t(k) + std::size_t(c)];
  const auto local = [&](std::int64_t g) {
    if (g >= m.first && g < m.first + m.owned) return int(g - m.first);
    const auto it = std::lower_bound(m.ghost_global.begin(), m.ghost_global.end(), g);
    return m.owned + int(it - m.ghost_global.begin());
  };
  const std::vector<std::int64_t>& faces = piece.faces;
  const Eigen::Index nf = Eigen::Index(faces.size() / 3);
  m.faces.resize(nf, 3);
  m.counted.resize(std::size_t(nf));
  for (Eigen::Index f = 0; f < nf; ++f) {
    std::int64_t smallest = faces[3 * std::size_t(f)];
    for (int c = 0; c < 3; ++c) {
      const std::int64_t g = faces[3 * std::size_t(f) + std::size_t(c)];
      m.faces(f, c) = local(g);
      smallest = std::min(smallest, g);
    }
    m.counted[std::size_t(f)] = smallest >= m.first && smallest < m.first + m.owned;
  }
}

}  // namespace

RankMesh scatter_mesh(const TriangleMesh& whole, OutputMap* output) {
  const int P = ranks();
  if (P == 1) return one_part(whole, output);
  RankMesh m;
  m.rank = rank();
  m.ranks = P;
  // Rank 0: the partition, the global numbering and each rank's piece; the sizes to everyone.
  ScatterPlan plan;
  if (m.rank == 0) plan = plan_scatter(whole, P);
  share_sizes(whole, plan, m);
  take_piece(m.rank == 0 ? send_pieces(whole, plan, P, output) : receive_piece(), m);
  return m;
}

}  // namespace mcf::dist
