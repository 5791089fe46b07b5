// The pipeline's stages as the subcommands run them, shared by run, reconstruct and track.
#pragma once
#include <memory>

#include "app/run_context.hpp"
#include "recon/tracker_sequence.hpp"
#include "recon/volume.hpp"

namespace seamless::app {

struct ScanResult {
  std::unique_ptr<Volume> volume;  // null when tracking only
  TrackSequenceResult tracking;
};

// Tracks the experiment's input (and fuses it into a new volume when with_volume), writing
// trajectory.txt, tracking_stats.csv and, with a volume, mesh.ply (output.write_mesh).
ScanResult scan(RunContext& ctx, bool with_volume);

}  // namespace seamless::app
