// The hash table stress run, written once over the executor (the test's own kernels): concurrent
// inserts with duplicates; deletes interleaved with lookups; reinserts. Included by
// hash_stress_test.cpp (OpenMP) and hash_stress_cuda.cu (CUDA).
#pragma once
#include <vector>

#include "core/buffer.hpp"
#include "kernels/recon/voxel_hash.hpp"

namespace seamless::test {

struct StressResult {
  std::vector<std::int32_t> insert_result, insert_slot;      // phase 1, per operation
  std::vector<std::int32_t> erase_slot, lookup_slot;         // phase 2, per unique key
  std::vector<std::int32_t> reinsert_result, reinsert_slot;  // phase 3, per operation
  std::vector<kernels::HashKey> table;                       // every slot's key at the end
};

template <class Exec>
StressResult hash_stress(const Exec& ex, const std::vector<kernels::HashKey>& ops,
                         const std::vector<kernels::HashKey>& unique, std::int64_t slots) {
  using namespace kernels;
  const Device d = Exec::device;
  Buffer<HashKey> keys(slots, d), op(std::int64_t(ops.size()), d), uq(std::int64_t(unique.size()), d);
  Buffer<std::int32_t> values(slots, d);
  op.copy_from_host(ops.data(), op.size());
  uq.copy_from_host(unique.data(), uq.size());
  const std::int64_t n = op.size(), u = uq.size();
  Buffer<std::int32_t> r1(n, d), s1(n, d), es(u, d), ls(u, d), r3(n, d), s3(n, d);
  HashTableView t{keys.data(), values.data(), static_cast<std::uint32_t>(slots - 1), 256};
  const HashKey* o = op.data();
  const HashKey* k = uq.data();
  std::int32_t *pr1 = r1.data(), *ps1 = s1.data(), *pes = es.data(), *pls = ls.data(), *pr3 = r3.data(),
               *ps3 = s3.data();
  ex.for_each(slots, [=] SEAMLESS_HD(std::int64_t i) { t.keys[i] = kEmptyKey; });
  auto insert_all = [&](std::int32_t* res, std::int32_t* slot) {
    ex.for_each(n, [=] SEAMLESS_HD(std::int64_t i) {
      std::int32_t s = -1;
      int probes = 0;
      res[i] = static_cast<std::int32_t>(t.insert(o[i], &s, &probes));
      slot[i] = s;
    });
  };
  insert_all(pr1, ps1);
  // Even keys are erased while odd keys are looked up, in the same launch.
  ex.for_each(u, [=] SEAMLESS_HD(std::int64_t i) {
    if (i % 2 == 0) pes[i] = t.erase(k[i]);
    else pls[i] = t.find(k[i]);
  });
  insert_all(pr3, ps3);
  ex.synchronize();
  return {r1.to_host(), s1.to_host(), es.to_host(), ls.to_host(), r3.to_host(), s3.to_host(), keys.to_host()};
}

}  // namespace seamless::test
