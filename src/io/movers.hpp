// Poses the synthetic room's movers (input.synthetic.movers) at a time: a person as six capsules
// (torso, head, two arms, two legs swinging with the gait), a ball as one sphere rolling on the
// floor. The renderer (kernels/io/render_room) draws them and writes their ground-truth mask.
#pragma once
#include <string>
#include <vector>

#include "io/input_params.hpp"
#include "kernels/scene/movers.hpp"

namespace seamless {

// Every mover present at time t (seconds), mover i with id i + 1. Throws a ConfigError for a path
// of fewer than two distinct points or more capsules than the renderer takes.
kernels::movers::Scene pose_movers(const std::vector<MoverParams>& movers, double t);

// The ids (1-based, as in the mask) of the movers of one kind.
std::vector<int> mover_ids(const std::vector<MoverParams>& movers, MoverKind kind);

// movers.txt: a line per frame and capsule, `timestamp mover ax ay az bx by bz radius`, in the
// room frame of groundtruth.txt; a frame with no mover present has no line.
std::string movers_lines(double timestamp, const kernels::movers::Scene& s);

}  // namespace seamless
