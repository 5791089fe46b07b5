// Where an undistorted image holds colour (docs/INPUT.md, "Undistortion"): the lens of freiburg1/2
// images saw less than the ideal pinhole image covers, and undistortion leaves a black, curved
// border there. AR frames crop to the largest rectangle without it (docs/RENDERING.md).
#pragma once
#include <cstdint>
#include <vector>

#include "core/intrinsics.hpp"
#include "core/pixel_rect.hpp"

namespace seamless {

// The largest rectangle of the mask's own aspect ratio (w:h, to the pixel) whose pixels are all
// set, and among those the one whose centre is nearest the mask's centre. Empty when no pixel is
// set; the whole mask when all are. mask: w * h bytes, row by row, non-zero = set.
PixelRect largest_rect_of_aspect(const std::vector<std::uint8_t>& mask, int w, int h);

// For images undistorted with `lens` (its dist non-zero; kernels/io/undistort.hpp): the largest
// rectangle of the image's aspect where remap_rgb found colour. The whole image when dist is zero.
PixelRect undistorted_colour_region(const Intrinsics& lens);

struct InputParams;
// Where the frames of `input` hold colour (the AR frames show only that part): for a TUM folder
// undistorted on reading (TumSource: input.undistort and a lens with k1 != 0), the region above;
// empty (the whole image) for every other source. Resolves the intrinsics as the source does.
PixelRect input_colour_region(const InputParams& input);

}  // namespace seamless
