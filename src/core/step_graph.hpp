// A simulation step's launches as one CUDA graph: the step runs on a stream of its own, is
// recorded once (a CUDA graph capture) and replayed with one launch while nothing it points to
// changed (Graph Management, CUDA programming guide). On the CPU, or a binary without CUDA, a
// step is just called. The owner says when a replay is allowed and what the graph was recorded
// for (StepGraph::Key); src/physics/particle_solver.cpp is the user.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "core/buffer.hpp"
#include "core/device.hpp"
#include "core/exec.hpp"
#include "seamless/build_config.hpp"

namespace seamless {

class StepGraph {
 public:
  // What a recorded graph is valid for: the owner's generation (bumped by anything a step points
  // to or depends on), the step's dt and its substeps. A replay needs the same key.
  struct Key {
    std::uint64_t generation = ~std::uint64_t{0};
    float dt = 0.f;
    int substeps = 0;
    bool operator==(const Key&) const = default;
  };

  // name: how warnings name the owner (e.g. "particle solver").
  StepGraph(Device d, std::string name);
  ~StepGraph();
  StepGraph(const StepGraph&) = delete;
  StepGraph& operator=(const StepGraph&) = delete;

  // Sizes the executor's own sort storage (CudaExec::temp) when size_key (e.g. the particle
  // count) changed since the last call: bytes(CudaExec{}) is what the sorts need; the storage
  // grows to that plus a quarter. Returns whether the storage moved (a recorded graph points at
  // it: the owner bumps its generation). Does nothing on the CPU.
  template <class F> bool reserve_temp(std::int64_t size_key, F&& bytes);

  // Calls fn(executor): on CUDA one that launches on this object's stream and sorts in its temp
  // storage (so that the launches can be recorded), on the CPU the CPU executor.
  template <class F> void run(F&& fn);

  // One step: on CUDA on this object's stream, ordered after what the default stream holds and
  // before what it gets next (no host synchronisation). With replay allowed (the owner's graphs
  // are on and the step already ran once directly with this key's generation: a recording pays
  // only when it is replayed), the graph for `key` is launched, recorded first if the one held is
  // for another key; otherwise step() runs directly. If a recording fails, the step runs
  // directly and graphs stay off from then on (nothing recorded was run). On the CPU: step().
  void step(bool replay, const Key& key, const std::function<void()>& step);

 private:
  bool replay_graph(const Key& key, const std::function<void()>& step);

  Device dev_;
  std::string name_;
#if SEAMLESS_HAS_CUDA
  std::unique_ptr<CudaStream> stream_;
  CudaGraph graph_;
  Buffer<unsigned char> temp_;  // the sort's own temp storage (the graph keeps pointing at it)
  std::int64_t temp_key_ = -1;  // size_key temp_ was sized for
  Key key_;                     // what graph_ was recorded for
  bool failed_ = false;
#endif
};

template <class F> bool StepGraph::reserve_temp(std::int64_t size_key, F&& bytes) {
#if SEAMLESS_HAS_CUDA
  const void* before = temp_.data();
  if (dev_ == Device::CUDA && temp_key_ != size_key) {
    std::size_t need = bytes(CudaExec{});
    if (static_cast<std::size_t>(temp_.size()) < need)
      temp_.reserve_discard(static_cast<std::int64_t>(need + need / 4), dev_);
    temp_key_ = size_key;
  }
  return before != temp_.data();
#else
  (void)size_key, (void)bytes;
  return false;
#endif
}

template <class F> void StepGraph::run(F&& fn) {
#if SEAMLESS_HAS_CUDA
  if (dev_ == Device::CUDA) {
    if (!stream_) stream_ = std::make_unique<CudaStream>();
    CudaExec ex;
    ex.stream = stream_->get(), ex.temp = temp_.data(), ex.temp_bytes = static_cast<std::size_t>(temp_.size());
    fn(ex);
    return;
  }
#endif
  with_exec(dev_, fn);
}

}  // namespace seamless
