#include "recon/surfaces.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <tuple>

#include "core/basis.hpp"

namespace seamless {
namespace {

using Key = std::tuple<int, int, int>;  // cell across the surface (i, j), height bin k

struct Cell {
  double area = 0, area_h = 0;
  vec3 area_p{0, 0, 0};  // area-weighted sum of piece centroids
  vec3 lo{1e9f, 1e9f, 1e9f}, hi{-1e9f, -1e9f, -1e9f};
  int component = -1;
};

std::map<Key, Cell> bin_horizontal_pieces(const Mesh& mesh, vec3 up, const SurfaceParams& p) {
  vec3 e1, e2;
  orthonormal_basis(up, e1, e2);
  const float cos_tilt = std::cos(p.max_tilt_deg * 3.14159265f / 180.f);
  std::map<Key, Cell> cells;
  for (const int3& t : mesh.triangles) {
    const vec3 a = mesh.positions[t.x], b = mesh.positions[t.y], c = mesh.positions[t.z];
    const vec3 n = cross(b - a, c - a);
    const float twice_area = length(n);
    // Marching cubes winds triangles with the outward (free-space) side first: an upward face has
    // n . up > 0 (a desk top, not its underside).
    if (twice_area <= 0.f || dot(n, up) < cos_tilt * twice_area) continue;
    const vec3 m = (a + b + c) * (1.f / 3.f);
    const float h = dot(m, up), area = 0.5f * twice_area;
    Cell& cell =
        cells[{static_cast<int>(std::floor(dot(m, e1) / p.cell)), static_cast<int>(std::floor(dot(m, e2) / p.cell)),
               static_cast<int>(std::floor(h / p.height_bin))}];
    cell.area += area, cell.area_h += area * h, cell.area_p += m * area;
    cell.lo = vmin(cell.lo, m), cell.hi = vmax(cell.hi, m);
  }
  return cells;
}

// Heights of the mesh's vertices in the surface grid's columns (i, j): what stands above a cell.
std::map<std::pair<int, int>, std::vector<float>> vertex_columns(const Mesh& mesh, vec3 up, const SurfaceParams& p) {
  vec3 e1, e2;
  orthonormal_basis(up, e1, e2);
  std::map<std::pair<int, int>, std::vector<float>> cols;
  for (vec3 x : mesh.positions)
    cols[{static_cast<int>(std::floor(dot(x, e1) / p.cell)), static_cast<int>(std::floor(dot(x, e2) / p.cell))}]
        .push_back(dot(x, up));
  return cols;
}

// Flood fill over the 26-neighbourhood of occupied cells; returns the component count.
int label_components(std::map<Key, Cell>& cells) {
  int count = 0;
  std::vector<Key> stack;
  for (auto& [key, cell] : cells) {
    if (cell.component >= 0) continue;
    cell.component = count;
    stack.push_back(key);
    while (!stack.empty()) {
      const auto [i, j, k] = stack.back();
      stack.pop_back();
      for (int di = -1; di <= 1; ++di)
        for (int dj = -1; dj <= 1; ++dj)
          for (int dk = -1; dk <= 1; ++dk) {
            auto it = cells.find({i + di, j + dj, k + dk});
            if (it == cells.end() || it->second.component >= 0) continue;
            it->second.component = count;
            stack.push_back(it->first);
          }
    }
    ++count;
  }
  return count;
}

}  // namespace

std::vector<HorizontalSurface> find_horizontal_surfaces(const Mesh& mesh, vec3 up,
                                                        const std::vector<vec3>& camera_positions,
                                                        const SurfaceParams& p) {
  up = normalize(up);
  std::map<Key, Cell> cells = bin_horizontal_pieces(mesh, up, p);
  const int n = label_components(cells);
  std::vector<HorizontalSurface> s(n);
  std::vector<vec3> centroid(n, vec3{0, 0, 0});
  std::vector<double> area_h(n, 0.0);
  for (HorizontalSurface& x : s) x.lo = {1e9f, 1e9f, 1e9f}, x.hi = {-1e9f, -1e9f, -1e9f}, x.cell = p.cell;
  for (const auto& [key, c] : cells) {
    HorizontalSurface& x = s[c.component];
    x.area += static_cast<float>(c.area);
    area_h[c.component] += c.area_h;
    centroid[c.component] += c.area_p;
    x.lo = vmin(x.lo, c.lo), x.hi = vmax(x.hi, c.hi);
    x.cells.push_back(c.area_p * static_cast<float>(1.0 / c.area));
  }
  for (int i = 0; i < n; ++i) {
    s[i].height = static_cast<float>(area_h[i] / s[i].area);
    centroid[i] = centroid[i] * (1.f / s[i].area);
  }
  // The centre: the mean point of the component's most open cell, the one farthest (up to
  // p.open_radius) from the surface's edge and from anything standing on it (scanned geometry from
  // just above the surface up to p.clearance); among equally open cells, the nearest to the area
  // centroid. So an object lands on the free part of a desk, not on the monitor that stands at the
  // desk's centroid, nor at its edge.
  const std::map<std::pair<int, int>, std::vector<float>> columns = vertex_columns(mesh, up, p);
  std::map<std::pair<int, int>, std::set<int>> owners;  // (i, j) -> components with a cell there
  for (const auto& [key, c] : cells) owners[{std::get<0>(key), std::get<1>(key)}].insert(c.component);
  const int max_ring = std::max(1, static_cast<int>(std::lround(p.open_radius / p.cell)));
  std::vector<std::pair<int, float>> best(n, {-1, 1e30f});  // (open rings, distance^2 to the centroid)
  for (const auto& [key, c] : cells) {
    const auto [i, j, k] = key;
    const float h = static_cast<float>(c.area_h / c.area);
    const int component = c.component;  // a lambda may not capture a structured binding before Clang 16
    auto open = [&](int ci, int cj) {   // this column is the surface's and nothing stands on it
      auto o = owners.find({ci, cj});
      if (o == owners.end() || !o->second.count(component)) return false;
      auto col = columns.find({ci, cj});
      if (col == columns.end()) return true;
      for (float vh : col->second)
        if (vh > h + p.height_bin && vh < h + p.clearance) return false;
      return true;
    };
    int rings = -1;
    for (int d = 0; d <= max_ring; ++d) {
      bool ring_open = true;
      for (int di = -d; di <= d && ring_open; ++di)
        for (int dj = -d; dj <= d && ring_open; ++dj)
          if (std::max(std::abs(di), std::abs(dj)) == d) ring_open = open(i + di, j + dj);
      if (!ring_open) break;
      rings = d;
    }
    const vec3 m = c.area_p * static_cast<float>(1.0 / c.area);
    const vec3 dv = m - centroid[c.component];
    const float d2 = dot(dv, dv) - dot(dv, up) * dot(dv, up);  // distance across the surface
    auto& b = best[c.component];
    if (rings > b.first || (rings == b.first && d2 < b.second)) b = {rings, d2}, s[c.component].centre = m;
  }
  for (int i = 0; i < n; ++i) s[i].open_radius = std::max(0, best[i].first) * p.cell;
  for (int i = 0; i < n; ++i) s[i].centre += up * (s[i].height - dot(s[i].centre, up));
  s.erase(std::remove_if(s.begin(), s.end(), [&](const HorizontalSurface& x) { return x.area < p.min_area; }), s.end());
  std::sort(s.begin(), s.end(), [](const auto& a, const auto& b) { return a.area > b.area; });

  // The floor: the lowest large surface, if it lies far below the cameras (a room scanned from eye
  // height), or if furniture stands on it (another surface at least furniture_rise higher) and the
  // cameras are above it. Otherwise it may be a desk seen without its floor.
  HorizontalSurface* lowest = nullptr;
  for (HorizontalSurface& x : s)
    if (x.area >= p.floor_min_area && (!lowest || x.height < lowest->height)) lowest = &x;
  if (lowest) {
    const bool under_furniture = std::any_of(
        s.begin(), s.end(), [&](const HorizontalSurface& x) { return x.height > lowest->height + p.furniture_rise; });
    float camera_h = 0.f;
    for (vec3 c : camera_positions) camera_h += dot(c, up);
    const float drop = camera_positions.empty() ? 1e9f : camera_h / camera_positions.size() - lowest->height;
    lowest->floor =
        (drop >= p.floor_min_drop && !camera_positions.empty()) || (under_furniture && drop >= 0.5f * p.floor_min_drop);
  }
  return s;
}

const HorizontalSurface* find_floor(const std::vector<HorizontalSurface>& surfaces) {
  for (const HorizontalSurface& s : surfaces)
    if (s.floor) return &s;
  return nullptr;
}

std::vector<const HorizontalSurface*> support_surfaces(const std::vector<HorizontalSurface>& surfaces) {
  std::vector<const HorizontalSurface*> out;
  for (const HorizontalSurface& s : surfaces)
    if (!s.floor) out.push_back(&s);
  return out;
}

std::string describe(const HorizontalSurface& s) {
  char buf[192];
  std::snprintf(buf, sizeof buf, "%.2f m^2 at height %.2f m, centre (%.2f, %.2f, %.2f) with %.2f m free around%s",
                s.area, s.height, s.centre.x, s.centre.y, s.centre.z, s.open_radius, s.floor ? " (floor)" : "");
  return buf;
}

}  // namespace seamless
