// Kernel family of the neighbour grid (solver.hpp lists the passes in order): prediction, the
// counting sort of particles by cell, the sorted copies, cell ranges and the neighbour lists.
#pragma once
#include <cstddef>
#include <cstdint>

#include "core/exec.hpp"
#include "kernels/physics/sim_views.hpp"

namespace seamless::kernels {

template <Executor Exec> struct NeighbourGrid {
  // External forces, speed limit, prediction p = x + v dt; cell keys of p; order = identity.
  static void predict(const Exec& ex, const SimViews& S);
  // Stable sort of (key, value) pairs by the low `bits` bits of key (the executor's radix sort).
  static void sort_cells(const Exec& ex, std::uint32_t* keys, int* values, std::int64_t n, int bits);
  // Bytes of the executor's temp storage that sort_cells needs (CudaExec::temp; 0 on the CPU).
  static std::size_t sort_cells_temp_bytes(const Exec& ex, std::int64_t n, int bits);
  // Gathers the sorted arrays after sort_by_key(key, order) and fills rank.
  static void reorder(const Exec& ex, const SimViews& S);
  // Cell offsets of sorted keys: start[k] = number of keys below k, k in [0, cells] (cells + 1
  // entries), so that cell k holds entries [start[k], start[k + 1]) and a run of cells one range.
  static void cell_starts(const Exec& ex, const std::uint32_t* keys, std::int64_t n, int* start, std::int64_t cells);
  // Keys of arbitrary points (static scene particles) and identity values for a sort.
  static void cell_keys(const Exec& ex, const vec3* p, std::int64_t n, GridSpec g, std::uint32_t* keys, int* idx);
  static void gather_vec3(const Exec& ex, const vec3* src, const int* idx, std::int64_t n, vec3* dst);
  // Neighbour lists (dynamic and static) of every particle within search_radius; counts overflow.
  static void find_neighbors(const Exec& ex, const SimViews& S);
};

}  // namespace seamless::kernels
