// Hash table stress: many concurrent inserts with duplicates, deletes racing lookups, reinserts;
// no key lost or duplicated, on OpenMP threads and on CUDA.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>

#include "core/device.hpp"
#include "core/exec_cpu.hpp"
#include "hash_stress.inl"

namespace seamless::test {
#if SEAMLESS_HAS_CUDA
StressResult hash_stress_cuda(const std::vector<kernels::HashKey>& ops, const std::vector<kernels::HashKey>& unique,
                              std::int64_t slots);
#endif

namespace {
using kernels::HashKey;
using kernels::InsertResult;

struct Workload {
  std::vector<HashKey> unique, ops;
};

// 40000 distinct block keys, each inserted 4 times, shuffled: the duplicates race each other.
Workload make_workload() {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> c(-300, 300);
  std::set<HashKey> seen;
  Workload w;
  while (w.unique.size() < 40000) {
    HashKey k = kernels::pack_block({c(rng), c(rng), c(rng)});
    if (seen.insert(k).second) w.unique.push_back(k);
  }
  for (int rep = 0; rep < 4; ++rep) w.ops.insert(w.ops.end(), w.unique.begin(), w.unique.end());
  std::shuffle(w.ops.begin(), w.ops.end(), rng);
  return w;
}

void check(const Workload& w, const StressResult& r) {
  std::map<HashKey, int> inserted1, inserted3;
  std::map<HashKey, std::int32_t> slot_of;
  for (std::size_t i = 0; i < w.ops.size(); ++i) {
    ASSERT_NE(r.insert_result[i], int(InsertResult::Full));
    if (r.insert_result[i] == int(InsertResult::Inserted)) ++inserted1[w.ops[i]];
    auto [it, fresh] = slot_of.emplace(w.ops[i], r.insert_slot[i]);
    ASSERT_EQ(it->second, r.insert_slot[i]) << "one key, two slots";
  }
  for (HashKey k : w.unique) ASSERT_EQ(inserted1[k], 1) << "each key inserted exactly once";
  for (std::size_t j = 0; j < w.unique.size(); ++j) {
    if (j % 2 == 0) {
      ASSERT_EQ(r.erase_slot[j], slot_of[w.unique[j]]) << "erase found the key";
    } else ASSERT_EQ(r.lookup_slot[j], slot_of[w.unique[j]]) << "lookup during deletes lost a key";
  }
  std::map<HashKey, std::int32_t> slot3;
  for (std::size_t i = 0; i < w.ops.size(); ++i) {
    ASSERT_NE(r.reinsert_result[i], int(InsertResult::Full));
    if (r.reinsert_result[i] == int(InsertResult::Inserted)) ++inserted3[w.ops[i]];
    auto [it, fresh] = slot3.emplace(w.ops[i], r.reinsert_slot[i]);
    ASSERT_EQ(it->second, r.reinsert_slot[i]);
  }
  for (std::size_t j = 0; j < w.unique.size(); ++j) {
    HashKey k = w.unique[j];
    ASSERT_EQ(inserted3[k], j % 2 == 0 ? 1 : 0) << "erased keys come back once, kept keys are found";
    if (j % 2) {
      ASSERT_EQ(slot3[k], slot_of[k]);
    }
  }
  // The table holds exactly the key set: nothing lost, nothing twice.
  std::vector<HashKey> live;
  for (HashKey k : r.table)
    if (kernels::is_live_key(k)) live.push_back(k);
  std::sort(live.begin(), live.end());
  std::vector<HashKey> want = w.unique;
  std::sort(want.begin(), want.end());
  ASSERT_EQ(live, want);
}

TEST(HashStress, OpenMPThreadsLoseNoKey) {
  Workload w = make_workload();
  int threads = omp_get_max_threads();
  omp_set_num_threads(std::max(threads, 4));  // oversubscribe the CI's 2 cores: more interleavings
  for (int round = 0; round < 2; ++round) check(w, hash_stress(CpuExec{}, w.ops, w.unique, 1 << 17));
  omp_set_num_threads(threads);
}

TEST(HashStressParity, CudaLosesNoKeyAndMatchesCpu) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
#if SEAMLESS_HAS_CUDA
  Workload w = make_workload();
  StressResult g = hash_stress_cuda(w.ops, w.unique, 1 << 17);
  check(w, g);
  // Slot choice depends on thread timing, but the key sets agree.
  StressResult c = hash_stress(CpuExec{}, w.ops, w.unique, 1 << 17);
  auto live = [](const std::vector<HashKey>& t) {
    std::vector<HashKey> v;
    for (HashKey k : t)
      if (kernels::is_live_key(k)) v.push_back(k);
    std::sort(v.begin(), v.end());
    return v;
  };
  EXPECT_EQ(live(g.table), live(c.table));
#endif
}

}  // namespace
}  // namespace seamless::test
