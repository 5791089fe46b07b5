// A rectangle of whole pixels of an image.
#pragma once

namespace seamless {

// Columns x .. x + width - 1, rows y .. y + height - 1.
struct PixelRect {
  int x = 0, y = 0, width = 0, height = 0;
  bool empty() const { return width <= 0 || height <= 0; }
};

}  // namespace seamless
