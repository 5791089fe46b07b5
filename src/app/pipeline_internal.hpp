// Helpers that the run paths of pipeline.cpp (scan, simulate) and live.cpp (the live loop) share;
// internal to the app.
#pragma once
#include "app/pipeline.hpp"
#include "app/run_context.hpp"
#include "io/frame_source.hpp"
#include "recon/tracker_sequence.hpp"
#include "recon/volume.hpp"

namespace seamless::app {

class RunRenderer;

namespace detail {

// Closes the renderer's outputs (the video encoder) after the run: a failed encoder (say, one
// stopped by the same Ctrl-C) is reported, not thrown, so that the particles, trajectory, stats
// and summary that follow are still written.
void finish_renderer(RunContext& ctx, RunRenderer& r);
// The tracking session's parameters from the experiment's sections.
TrackSequenceParams tracking_params(const Experiment& e, StageTimer* volume_stages);
// A frame with its images on the host.
RgbdFrame host_copy(const RgbdFrame& f);
void log_volume(const VolumeStats& s);
// The intrinsics the frames arrive with (after undistortion), in the log and in the run's folder
// (intrinsics.txt, calibration.txt's format): a run says which camera model it tracked with.
void record_intrinsics(RunContext& ctx, const FrameSource& source);

}  // namespace detail
}  // namespace seamless::app
