// Child process of test_fakenect: runs the real Kinect source (make_source, source: kinect) and
// records what it delivers as a TUM folder. Started with FAKENECT_PATH and LD_LIBRARY_PATH pointing
// at Debian's fakenect libfreenect, it exercises the live capture path without hardware.
// usage: io_kinect_replay OUT_DIR FRAMES
#include <cstdio>
#include <cstdlib>

#include "core/error.hpp"
#include "io/frame_source.hpp"
#include "io/input_params.hpp"
#include "io/kinect_source.hpp"
#include "io/record.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s OUT_DIR FRAMES\n", argv[0]);
    return 2;
  }
  try {
    seamless::InputParams p;
    p.source = seamless::InputSource::kinect;
    p.kinect.queue_size = 64;  // the recorder writes PNGs slower than 30 Hz on a busy CI machine
    p.kinect.timeout_s = 20;
    auto src = seamless::make_source(p);
    seamless::RecordOptions opt;
    opt.max_frames = std::atoll(argv[2]);
    long long n = seamless::record(*src, argv[1], opt);
    std::printf("frames %lld dropped %lld\n", n, static_cast<long long>(src->skipped_frames()));
    return 0;
  } catch (const seamless::Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
