// The last two frames an external tracker prepared (pyramids, point clouds): the current frame of
// one call is the previous frame of the next, so each frame is prepared once; after a lost frame
// the last good frame stays, being the one used most recently.
#pragma once
#include <array>
#include <cstdint>

#include "io/frame_source.hpp"

namespace seamless::external {

template <class T> class TwoFrameCache {
 public:
  // The prepared form of `f`, made by make(f) when it is not one of the two kept.
  template <class Make> const T& get(const RgbdFrame& f, Make&& make) {
    ++tick_;
    for (Entry& e : entries_)
      if (e.used != 0 && e.index == f.index && e.timestamp == f.timestamp) {
        e.used = tick_;
        return e.value;
      }
    Entry& e = entries_[0].used <= entries_[1].used ? entries_[0] : entries_[1];  // least recently used
    e = {f.index, f.timestamp, tick_, make(f)};
    return e.value;
  }

 private:
  struct Entry {
    std::int64_t index = -1;
    double timestamp = 0;
    std::uint64_t used = 0;  // 0: empty
    T value{};
  };
  std::array<Entry, 2> entries_;
  std::uint64_t tick_ = 0;
};

}  // namespace seamless::external
