// The Executor concept (core/exec.hpp) checks every primitive: a type that has all of them but one
// is not an Executor, for each one in turn. These are compile-time checks: this file does not
// compile if the concept lets a missing primitive through.
#include <cstdint>
#include <type_traits>

#include "core/exec.hpp"

namespace seamless {
namespace {

enum class Missing {
  none,
  device,
  for_each,
  exclusive_scan,
  sort_by_key,
  transform_reduce,
  transform_reduce_into,
  transform_reduce_into_then,
  transform_reduce_rounds,
  for_each_grouped,
  for_each_grouped_min_blocks,
  lanes,
  for_each_phases,
  for_each_phases_staged,
  synchronize,
};

struct OnCpu {
  static constexpr Device device = Device::CPU;
};
struct Nowhere {};

// CpuExec's declarations, less the one named by M (declared only, never called).
template <Missing M> struct AllBut : std::conditional_t<M == Missing::device, Nowhere, OnCpu> {
  template <class F> void for_each(std::int64_t, F) const requires(M != Missing::for_each);
  template <class T> T exclusive_scan(const T*, T*, std::int64_t) const requires(M != Missing::exclusive_scan);
  template <class K, class V>
  void sort_by_key(K*, V*, std::int64_t, int = 8 * sizeof(K)) const requires(M != Missing::sort_by_key);
  template <class T, class F> T transform_reduce(std::int64_t, T, F) const requires(M != Missing::transform_reduce);
  template <class T, class F>
  void transform_reduce_into(std::int64_t, F, T*) const requires(M != Missing::transform_reduce_into);
  template <class T, class F, class G>
  void transform_reduce_into(std::int64_t, F, T*, G) const requires(M != Missing::transform_reduce_into_then);
  template <class T, class F, class G>
  void transform_reduce_rounds(std::int64_t, int, F, T*, G) const requires(M != Missing::transform_reduce_rounds);
  int lanes(std::int64_t, int) const requires(M != Missing::lanes);
  template <class F> void for_each_grouped(std::int64_t, int, F) const requires(M != Missing::for_each_grouped);
  template <int B, class F>
  void for_each_grouped(std::int64_t, int, F, MinBlocks<B>) const requires(M != Missing::for_each_grouped_min_blocks);
  template <class F>
  void for_each_phases(int, const std::int64_t*, const std::int64_t*, F) const requires(M != Missing::for_each_phases);
  template <class F, class... T>
  void for_each_phases_staged(int, const std::int64_t*, const std::int64_t*, F, Staged<T>...) const
      requires(M != Missing::for_each_phases_staged);
  void synchronize() const requires(M != Missing::synchronize);
};

// The probe type itself is an Executor when nothing is missing (so the checks below fail for the
// missing primitive, not for a mistake in AllBut), and so is the real CPU backend.
static_assert(Executor<AllBut<Missing::none>>);
static_assert(Executor<CpuExec>);

static_assert(!Executor<AllBut<Missing::device>>);
static_assert(!Executor<AllBut<Missing::for_each>>);
static_assert(!Executor<AllBut<Missing::exclusive_scan>>);
static_assert(!Executor<AllBut<Missing::sort_by_key>>);
static_assert(!Executor<AllBut<Missing::transform_reduce>>);
static_assert(!Executor<AllBut<Missing::transform_reduce_into>>);
static_assert(!Executor<AllBut<Missing::transform_reduce_into_then>>);
static_assert(!Executor<AllBut<Missing::transform_reduce_rounds>>);
static_assert(!Executor<AllBut<Missing::for_each_grouped>>);
static_assert(!Executor<AllBut<Missing::for_each_grouped_min_blocks>>);
static_assert(!Executor<AllBut<Missing::lanes>>);
static_assert(!Executor<AllBut<Missing::for_each_phases>>);
static_assert(!Executor<AllBut<Missing::for_each_phases_staged>>);
static_assert(!Executor<AllBut<Missing::synchronize>>);

}  // namespace
}  // namespace seamless
