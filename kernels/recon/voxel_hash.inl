// Kernel bodies for the hash table maintenance in recon/tsdf.hpp, compiled once per backend.
#include "kernels/recon/tsdf.hpp"

namespace seamless::kernels {

template <Executor Exec> void VoxelHash<Exec>::hash_clear(const Exec& ex, HashTableView t) {
  ex.for_each(static_cast<std::int64_t>(t.mask) + 1, [=] SEAMLESS_HD(std::int64_t i) {
    t.keys[i] = kEmptyKey;
    t.values[i] = -1;
  });
}

template <Executor Exec>
void VoxelHash<Exec>::pool_reset(const Exec& ex, View<std::int32_t> free_list, HashCounters* counters) {
  ex.for_each(free_list.size, [=] SEAMLESS_HD(std::int64_t i) {
    // Reversed so that pops hand out blocks 0, 1, 2, ... (cache-friendly, easy to read in tests).
    free_list[i] = static_cast<std::int32_t>(free_list.size - 1 - i);
  });
  const int n = static_cast<int>(free_list.size);
  ex.for_each(1, [=] SEAMLESS_HD(std::int64_t) { *counters = HashCounters{n, 0, 0, 0, 0, 0, 0, 0, 0}; });
}

template <Executor Exec>
void VoxelHash<Exec>::pool_append(const Exec& ex, View<std::int32_t> free_list, HashCounters* counters,
                                  std::int32_t first, std::int32_t n) {
  // One thread: reads free_top once, so the appended range is contiguous above it.
  ex.for_each(1, [=] SEAMLESS_HD(std::int64_t) {
    int top = counters->free_top < 0 ? 0 : counters->free_top;
    for (std::int32_t k = 0; k < n; ++k) free_list[top + k] = first + n - 1 - k;
    counters->free_top = top + n;
  });
}

template <Executor Exec> void VoxelHash<Exec>::reset_frame_counters(const Exec& ex, HashCounters* counters) {
  ex.for_each(1, [=] SEAMLESS_HD(std::int64_t) {
    HashCounters& c = *counters;
    c.inserted = c.collisions = c.probe_failures = c.pool_failures = c.visible = c.removed = c.listed = 0;
  });
}

template <Executor Exec>
void VoxelHash<Exec>::hash_insert(const Exec& ex, HashTableView t, View<const HashKey> keys,
                                  View<const std::int32_t> value_in, View<std::int32_t> slot_out,
                                  View<std::int32_t> result_out, HashCounters* counters) {
  ex.for_each(keys.size, [=] SEAMLESS_HD(std::int64_t i) {
    std::int32_t slot = -1;
    int probes = 0;
    InsertResult r = t.insert(keys[i], &slot, &probes);
    slot_out[i] = r == InsertResult::Full ? -1 : slot;
    result_out[i] = static_cast<std::int32_t>(r);
    if (r == InsertResult::Full) {
      atomic_add(&counters->probe_failures, 1);
    } else if (r == InsertResult::Inserted) {
      t.values[slot] = value_in.size ? value_in[i] : -1;
      atomic_add(&counters->inserted, 1);
      if (probes > 0) atomic_add(&counters->collisions, 1);
    }
  });
}

template <Executor Exec>
void VoxelHash<Exec>::hash_find(const Exec& ex, HashTableView t, View<const HashKey> keys,
                                View<std::int32_t> slot_out) {
  ex.for_each(keys.size, [=] SEAMLESS_HD(std::int64_t i) { slot_out[i] = t.find(keys[i]); });
}

template <Executor Exec>
void VoxelHash<Exec>::hash_erase(const Exec& ex, HashTableView t, View<const HashKey> keys, View<std::int32_t> slot_out,
                                 HashCounters* counters) {
  ex.for_each(keys.size, [=] SEAMLESS_HD(std::int64_t i) {
    std::int32_t s = t.erase(keys[i]);
    slot_out[i] = s;
    if (s >= 0) atomic_add(&counters->tombstones, 1);
  });
}

// Writes the slots for which keep(slot) holds to slots_out, in slot order; returns how many.
// flags (one int per slot) becomes the exclusive prefix sum: the output position of each slot.
template <class Exec, class Pred>
std::int64_t compact_slots(const Exec& ex, HashTableView t, View<std::int32_t> flags, View<std::int32_t> slots_out,
                           Pred keep) {
  const std::int64_t n = static_cast<std::int64_t>(t.mask) + 1;
  ex.for_each(n, [=] SEAMLESS_HD(std::int64_t i) { flags[i] = keep(i) ? 1 : 0; });
  std::int32_t total = ex.exclusive_scan(flags.data, flags.data, n);
  ex.for_each(n, [=] SEAMLESS_HD(std::int64_t i) {
    if (keep(i)) slots_out[flags[i]] = static_cast<std::int32_t>(i);
  });
  return total;
}

template <Executor Exec>
std::int64_t VoxelHash<Exec>::hash_live_slots(const Exec& ex, HashTableView t, View<std::int32_t> flags,
                                              View<std::int32_t> slots_out) {
  return compact_slots(ex, t, flags, slots_out,
                       [=] SEAMLESS_HD(std::int64_t i) { return is_live_key(t.keys[i]) && t.values[i] >= 0; });
}

template <Executor Exec>
std::int64_t VoxelHash<Exec>::hash_slots_beyond(const Exec& ex, HashTableView t, vec3 center, float radius,
                                                View<std::int32_t> flags, View<std::int32_t> slots_out) {
  const float r2 = radius * radius;
  return compact_slots(ex, t, flags, slots_out, [=] SEAMLESS_HD(std::int64_t i) {
    HashKey k = t.keys[i];
    if (!is_live_key(k) || t.values[i] < 0) return false;
    int3 b = unpack_block(k);
    vec3 c{b.x * 8.f + 3.5f, b.y * 8.f + 3.5f, b.z * 8.f + 3.5f};  // centre of voxels 8b .. 8b+7
    return length2(c - center) > r2;
  });
}

template <Executor Exec>
void VoxelHash<Exec>::insert_with_blocks(const Exec& ex, HashTableView t, View<const std::int32_t> free_list,
                                         HashCounters* counters, View<const HashKey> keys,
                                         View<std::int32_t> blocks_out) {
  ex.for_each(keys.size, [=] SEAMLESS_HD(std::int64_t i) {
    blocks_out[i] = -1;
    std::int32_t slot = -1;
    int probes = 0;
    InsertResult r = t.insert(keys[i], &slot, &probes);
    if (r == InsertResult::Full) atomic_add(&counters->probe_failures, 1);
    if (r != InsertResult::Inserted) return;  // Found: the key was already there (the caller checks)
    std::int32_t block = pool_pop(counters, free_list.data);
    if (block < 0) {  // no block: give the slot up so that a later attempt can insert the key again
      atomic_add(&counters->pool_failures, 1);
      atomic_exch(&t.keys[slot], kTombstone);
      atomic_add(&counters->tombstones, 1);
      return;
    }
    atomic_exch(&t.values[slot], block);
    atomic_add(&counters->inserted, 1);
    if (probes > 0) atomic_add(&counters->collisions, 1);
    blocks_out[i] = block;
  });
}

template <Executor Exec>
void VoxelHash<Exec>::hash_gather(const Exec& ex, HashTableView t, View<const std::int32_t> slots,
                                  View<HashKey> keys_out, View<std::int32_t> values_out) {
  ex.for_each(slots.size, [=] SEAMLESS_HD(std::int64_t i) {
    keys_out[i] = t.keys[slots[i]];
    values_out[i] = t.values[slots[i]];
  });
}

template <Executor Exec>
void VoxelHash<Exec>::gather_blocks(const Exec& ex, const Voxel* pool, const uchar3* colors,
                                    View<const std::int32_t> blocks, View<Voxel> out, View<uchar3> out_colors) {
  ex.for_each(blocks.size * kBlockVoxels, [=] SEAMLESS_HD(std::int64_t i) {
    const std::int64_t k = static_cast<std::int64_t>(blocks[i / kBlockVoxels]) * kBlockVoxels + i % kBlockVoxels;
    out[i] = pool[k];
    out_colors[i] = colors[k];
  });
}

template <Executor Exec>
void VoxelHash<Exec>::scatter_blocks(const Exec& ex, Voxel* pool, uchar3* colors, View<const std::int32_t> blocks,
                                     View<const Voxel> in, View<const uchar3> in_colors) {
  ex.for_each(blocks.size * kBlockVoxels, [=] SEAMLESS_HD(std::int64_t i) {
    const std::int32_t block = blocks[i / kBlockVoxels];
    if (block < 0) return;
    const std::int64_t k = static_cast<std::int64_t>(block) * kBlockVoxels + i % kBlockVoxels;
    pool[k] = in[i];
    colors[k] = in_colors[i];
  });
}

}  // namespace seamless::kernels
