// One-off reference tool (tests/io/data/README.md): replays a fakenect folder through a fakenect
// library in the depth mode its second argument names (reg, mm, 11) and writes each depth frame.
#include <libfreenect.h>
#include <stdio.h>
#include <stdlib.h>
static int n = 0, want = 0; static const char* out; static const char* tag;
static void on_depth(freenect_device* d, void* data, uint32_t ts) {
  if (n >= want) return;
  char p[512]; snprintf(p, sizeof p, "%s/%s-%02d.raw", out, tag, n);
  FILE* f = fopen(p, "wb"); fwrite(data, 2, 640*480, f); fclose(f); ++n;
}
static void on_video(freenect_device* d, void* data, uint32_t ts) {}
int main(int argc, char** argv) {
  out = argv[1]; tag = argv[2]; want = atoi(argv[3]);
  freenect_depth_format fmt = tag[0]=='r' ? FREENECT_DEPTH_REGISTERED : tag[0]=='m' ? FREENECT_DEPTH_MM : FREENECT_DEPTH_11BIT;
  freenect_context* ctx; freenect_device* dev;
  if (freenect_init(&ctx, 0) < 0 || freenect_open_device(ctx, &dev, 0) < 0) return 1;
  freenect_set_depth_callback(dev, on_depth); freenect_set_video_callback(dev, on_video);
  freenect_set_video_mode(dev, freenect_find_video_mode(FREENECT_RESOLUTION_MEDIUM, FREENECT_VIDEO_RGB));
  if (freenect_set_depth_mode(dev, freenect_find_depth_mode(FREENECT_RESOLUTION_MEDIUM, fmt)) < 0) return 2;
  freenect_start_depth(dev); freenect_start_video(dev);
  while (n < want && freenect_process_events(ctx) >= 0) {}
  printf("%s frames %d\n", tag, n);
  return 0;
}
