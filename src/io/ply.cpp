#include "io/ply.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>

#include "core/error.hpp"
#include "core/output_file.hpp"

namespace seamless {

namespace {

std::size_t size_of(PlyType t) {
  switch (t) {
    case PlyType::i8:
    case PlyType::u8: return 1;
    case PlyType::i16:
    case PlyType::u16: return 2;
    case PlyType::i32:
    case PlyType::u32:
    case PlyType::f32: return 4;
    case PlyType::f64: return 8;
  }
  return 0;
}

const char* name_of(PlyType t) {
  static const char* const names[] = {"char", "uchar", "short", "ushort", "int", "uint", "float", "double"};
  return names[static_cast<int>(t)];
}

bool is_integer(PlyType t) { return t != PlyType::f32 && t != PlyType::f64; }

// Both spellings of the specification (char ... double, and int8 ... float64).
bool parse_type(const std::string& s, PlyType& t) {
  static const std::pair<const char*, PlyType> names[] = {
      {"char", PlyType::i8},   {"int8", PlyType::i8},     {"uchar", PlyType::u8},   {"uint8", PlyType::u8},
      {"short", PlyType::i16}, {"int16", PlyType::i16},   {"ushort", PlyType::u16}, {"uint16", PlyType::u16},
      {"int", PlyType::i32},   {"int32", PlyType::i32},   {"uint", PlyType::u32},   {"uint32", PlyType::u32},
      {"float", PlyType::f32}, {"float32", PlyType::f32}, {"double", PlyType::f64}, {"float64", PlyType::f64}};
  for (const auto& [n, type] : names)
    if (s == n) return t = type, true;
  return false;
}

template <class T> double load(const unsigned char* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return static_cast<double>(v);
}

double load_value(PlyType t, const unsigned char* p) {
  switch (t) {
    case PlyType::i8: return load<std::int8_t>(p);
    case PlyType::u8: return load<std::uint8_t>(p);
    case PlyType::i16: return load<std::int16_t>(p);
    case PlyType::u16: return load<std::uint16_t>(p);
    case PlyType::i32: return load<std::int32_t>(p);
    case PlyType::u32: return load<std::uint32_t>(p);
    case PlyType::f32: return load<float>(p);
    case PlyType::f64: return load<double>(p);
  }
  return 0.0;
}

template <class T> void store(double v, unsigned char* p) {
  const T x = static_cast<T>(v);
  std::memcpy(p, &x, sizeof x);
}

// v (already range-checked for integer types) as type t at p, in this machine's byte order.
void store_value(PlyType t, double v, unsigned char* p) {
  switch (t) {
    case PlyType::i8: return store<std::int8_t>(v, p);
    case PlyType::u8: return store<std::uint8_t>(v, p);
    case PlyType::i16: return store<std::int16_t>(v, p);
    case PlyType::u16: return store<std::uint16_t>(v, p);
    case PlyType::i32: return store<std::int32_t>(v, p);
    case PlyType::u32: return store<std::uint32_t>(v, p);
    case PlyType::f32: return store<float>(v, p);
    case PlyType::f64: return store<double>(v, p);
  }
}

void range_of(PlyType t, double& lo, double& hi) {
  switch (t) {
    case PlyType::i8: lo = -128, hi = 127; return;
    case PlyType::u8: lo = 0, hi = 255; return;
    case PlyType::i16: lo = -32768, hi = 32767; return;
    case PlyType::u16: lo = 0, hi = 65535; return;
    case PlyType::i32: lo = -2147483648.0, hi = 2147483647.0; return;
    case PlyType::u32: lo = 0, hi = 4294967295.0; return;
    default: lo = -std::numeric_limits<double>::infinity(), hi = std::numeric_limits<double>::infinity();
  }
}

// Component k of the first of a vector of 3-component structs (nullptr when it is empty).
template <class V> const void* component(const std::vector<V>& v, int k) {
  return v.empty() ? nullptr : &v.front().x + k;
}

// v as a float; +-infinity beyond the float range (a plain conversion would be undefined there).
float as_float(double v) {
  return std::fabs(v) > std::numeric_limits<float>::max() ? static_cast<float>(std::copysign(INFINITY, v))
                                                          : static_cast<float>(v);
}

std::string plural(const std::string& element) { return element == "vertex" ? "vertices" : element + "s"; }

// The data after the header, one value at a time, in the file's encoding.
class ValueReader {
 public:
  ValueReader(const std::string& path, PlyFormat format, std::string data)
      : path_(path), format_(format), data_(std::move(data)) {}

  // The next value of type t (in row `row` of element e: for errors), into p in this machine's
  // byte order; returns it as a double.
  double next(PlyType t, unsigned char* p, const PlyElement& e, std::int64_t row) {
    if (format_ == PlyFormat::ascii) return next_ascii(t, p, e, row);
    const std::size_t n = size_of(t);
    if (data_.size() - pos_ < n) throw InputError(where(e, row) + " is cut short (truncated?)");
    std::memcpy(p, data_.data() + pos_, n);
    pos_ += n;
    const bool swap = (format_ == PlyFormat::binary_big_endian) != (std::endian::native == std::endian::big);
    if (swap) std::reverse(p, p + n);
    return load_value(t, p);
  }

 private:
  std::string where(const PlyElement& e, std::int64_t row) const {
    return "PLY '" + path_ + "': element " + e.name + " row " + std::to_string(row);
  }

  double next_ascii(PlyType t, unsigned char* p, const PlyElement& e, std::int64_t row) {
    auto space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
    while (pos_ < data_.size() && space(data_[pos_])) ++pos_;
    std::size_t end = pos_;
    while (end < data_.size() && !space(data_[end])) ++end;
    if (end == pos_) throw InputError(where(e, row) + " is cut short (truncated?)");
    const char* first = data_.data() + pos_;
    const char* last = data_.data() + end;
    const std::string token(first, last);
    pos_ = end;
    double v = 0.0;
    if (is_integer(t)) {
      long long i = 0;
      const auto r = std::from_chars(first, last, i);
      if (r.ec != std::errc() || r.ptr != last)
        throw InputError(where(e, row) + ": '" + token + "' is not an integer (" + name_of(t) + ")");
      v = static_cast<double>(i);
      double lo, hi;
      range_of(t, lo, hi);
      if (v < lo || v > hi) throw InputError(where(e, row) + ": " + token + " does not fit a " + name_of(t));
    } else {
      const auto r = std::from_chars(first, last, v);
      if (r.ec != std::errc() || r.ptr != last)
        throw InputError(where(e, row) + ": '" + token + "' is not a number (" + name_of(t) + ")");
      if (t == PlyType::f32 && std::isfinite(v) && std::fabs(v) > std::numeric_limits<float>::max())
        throw InputError(where(e, row) + ": " + token + " does not fit a float");
    }
    store_value(t, v, p);
    return load_value(t, p);  // as stored (a float rounds)
  }

  std::string path_;
  PlyFormat format_;
  std::string data_;
  std::size_t pos_ = 0;
};

// The fewest bytes (binary) or characters (ascii: a digit and a separator per value) a row of e
// takes: what the header's counts are checked against before anything is allocated.
std::size_t min_row_size(const PlyElement& e, PlyFormat format) {
  std::size_t n = 0;
  for (const PlyProperty& p : e.properties)
    n += format == PlyFormat::ascii ? 2 : size_of(p.list ? p.count_type : p.type);
  return n;
}

PlyData read_header(std::istream& f, const std::string& path) {
  std::string line;
  std::getline(f, line);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line != "ply") throw InputError("'" + path + "' is not a PLY file (first line is not 'ply')");
  PlyData d;
  bool format_seen = false, end_seen = false;
  while (std::getline(f, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();  // written on Windows
    if (line == "end_header") {
      end_seen = true;
      break;
    }
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (word == "format") {
      std::string fmt;
      ls >> fmt;
      if (fmt == "ascii") d.format = PlyFormat::ascii;
      else if (fmt == "binary_little_endian") d.format = PlyFormat::binary_little_endian;
      else if (fmt == "binary_big_endian") d.format = PlyFormat::binary_big_endian;
      else
        throw InputError("PLY '" + path + "': format '" + fmt +
                         "' is not one of ascii, binary_little_endian, binary_big_endian");
      format_seen = true;
    } else if (word == "element") {
      PlyElement e;
      if (!(ls >> e.name >> e.count) || e.count < 0)
        throw InputError("PLY '" + path + "': '" + line + "' is not 'element <name> <count>'");
      d.elements.push_back(std::move(e));
    } else if (word == "property") {
      if (d.elements.empty()) throw InputError("PLY '" + path + "': property before any element");
      PlyProperty p;
      std::string t, count_t;
      ls >> t;
      if (t == "list") {
        p.list = true;
        ls >> count_t >> t;
        if (!parse_type(count_t, p.count_type) || !is_integer(p.count_type))
          throw InputError("PLY '" + path + "': '" + line + "': a list's length type must be an integer type");
      }
      if (!parse_type(t, p.type)) throw InputError("PLY '" + path + "': unsupported property type '" + t + "'");
      if (!(ls >> p.name)) throw InputError("PLY '" + path + "': '" + line + "' names no property");
      d.elements.back().properties.push_back(std::move(p));
    } else if (word != "comment" && word != "obj_info" && !word.empty()) {
      throw InputError("PLY '" + path + "': header line '" + line + "' is not understood");
    }
  }
  if (!end_seen) throw InputError("PLY '" + path + "': no end_header line");
  if (!format_seen) throw InputError("PLY '" + path + "': no format line");
  return d;
}

}  // namespace

double PlyProperty::value(std::int64_t i) const {
  return load_value(type, bytes.data() + static_cast<std::size_t>(i) * size_of(type));
}

const PlyProperty* PlyElement::find(std::string_view property) const {
  for (const PlyProperty& p : properties)
    if (p.name == property) return &p;
  return nullptr;
}

const PlyElement* PlyData::find(std::string_view element) const {
  for (const PlyElement& e : elements)
    if (e.name == element) return &e;
  return nullptr;
}

PlyData read_ply_data(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw InputError("cannot open PLY file '" + path + "'");
  PlyData d = read_header(f, path);
  std::string data((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  // The counts come from the header: check them against the file's size before allocating.
  const std::uint64_t avail = data.size() + 1;  // ascii: the last value needs no separator
  std::uint64_t need = 0;
  bool too_many = false;
  for (const PlyElement& e : d.elements) {
    const std::uint64_t row = min_row_size(e, d.format);
    if (row == 0) continue;
    if (static_cast<std::uint64_t>(e.count) > (avail - need) / row) {
      too_many = true;
      break;
    }
    need += static_cast<std::uint64_t>(e.count) * row;
  }
  if (too_many) {
    std::string counts;
    for (const PlyElement& e : d.elements)
      counts += (counts.empty() ? "" : " and ") + std::to_string(e.count) + " " + plural(e.name);
    throw InputError("PLY '" + path + "': the header announces " + counts + ", more than the file's " +
                     std::to_string(data.size()) + " bytes of data hold (truncated?)");
  }
  ValueReader in(path, d.format, std::move(data));
  for (PlyElement& e : d.elements) {
    if (e.properties.empty()) continue;  // rows of nothing
    for (PlyProperty& p : e.properties) {
      p.bytes.reserve(static_cast<std::size_t>(e.count) * size_of(p.type) * (p.list ? 3 : 1));
      if (p.list) p.starts.assign(1, 0);
    }
    unsigned char scratch[8];
    for (std::int64_t r = 0; r < e.count; ++r) {
      for (PlyProperty& p : e.properties) {
        std::int64_t items = 1;
        if (p.list) {
          const double n = in.next(p.count_type, scratch, e, r);
          if (n < 0)
            throw InputError("PLY '" + path + "': element " + e.name + " row " + std::to_string(r) + " has a list of " +
                             std::to_string(n) + " items");
          items = static_cast<std::int64_t>(n);
        }
        const std::size_t size = size_of(p.type);
        for (std::int64_t k = 0; k < items; ++k) {
          in.next(p.type, scratch, e, r);
          p.bytes.insert(p.bytes.end(), scratch, scratch + size);
        }
        if (p.list) p.starts.push_back(p.starts.back() + items);
      }
    }
  }
  return d;
}

void write_ply_data(const std::string& path, const std::vector<PlyElementOut>& elements, const std::string& what) {
  std::ofstream f(partial_path(path), std::ios::binary);
  if (!f) throw Error("cannot write " + what + " to '" + path + "' (does the folder exist and is it writable?)");
  f << "ply\nformat " << (std::endian::native == std::endian::big ? "binary_big_endian" : "binary_little_endian")
    << " 1.0\ncomment written by seamless\n";
  std::vector<std::size_t> row_bytes;
  for (const PlyElementOut& e : elements) {
    f << "element " << e.name << ' ' << e.count << '\n';
    std::size_t bytes = 0;
    for (const PlyColumn& c : e.columns) {
      if (c.list_length > 0) f << "property list uchar " << name_of(c.type) << ' ' << c.name << '\n';
      else f << "property " << name_of(c.type) << ' ' << c.name << '\n';
      bytes += c.list_length > 0 ? 1 + c.list_length * size_of(c.type) : size_of(c.type);
    }
    row_bytes.push_back(bytes);
  }
  f << "end_header\n";
  std::vector<char> buf;
  for (std::size_t i = 0; i < elements.size(); ++i) {
    const PlyElementOut& e = elements[i];
    buf.resize(static_cast<std::size_t>(e.count) * row_bytes[i]);
    char* out = buf.data();
    for (std::int64_t r = 0; r < e.count; ++r)
      for (const PlyColumn& c : e.columns) {
        const char* src = static_cast<const char*>(c.base) + static_cast<std::size_t>(r) * c.stride;
        if (c.list_length > 0) {
          *out++ = static_cast<char>(c.list_length);
          const std::size_t n = c.list_length * size_of(c.type);
          std::memcpy(out, src, n), out += n;
        } else {
          std::memcpy(out, src, size_of(c.type)), out += size_of(c.type);
        }
      }
    f.write(buf.data(), out - buf.data());
  }
  f.close();
  if (!f) throw Error("writing " + what + " to '" + path + "' failed (disk full?)");
  commit_partial(path);
}

// ---- meshes ------------------------------------------------------------------------------------

void write_mesh_ply(const std::string& path, const Mesh& mesh) {
  const auto n = static_cast<std::int64_t>(mesh.positions.size());
  PlyElementOut v{"vertex", n, {}};
  for (int k = 0; k < 3; ++k)
    v.columns.push_back({std::string(1, "xyz"[k]), PlyType::f32, component(mesh.positions, k), sizeof(vec3), 0});
  if (mesh.normals.size() == mesh.positions.size())
    for (int k = 0; k < 3; ++k)
      v.columns.push_back({std::string("n") + "xyz"[k], PlyType::f32, component(mesh.normals, k), sizeof(vec3), 0});
  if (mesh.colors.size() == mesh.positions.size()) {
    const char* names[] = {"red", "green", "blue"};
    for (int k = 0; k < 3; ++k)
      v.columns.push_back({names[k], PlyType::u8, component(mesh.colors, k), sizeof(uchar3), 0});
  }
  PlyElementOut faces{"face", static_cast<std::int64_t>(mesh.triangles.size()), {}};
  faces.columns.push_back({"vertex_indices", PlyType::i32, mesh.triangles.data(), sizeof(int3), 3});
  write_ply_data(path, {v, faces}, "mesh");
}

Mesh read_mesh_ply(const std::string& path) {
  const PlyData d = read_ply_data(path);
  Mesh m;
  const PlyElement* v = d.find("vertex");
  const std::int64_t nv = v ? v->count : 0;
  const PlyProperty* xyz[3] = {nullptr, nullptr, nullptr};
  for (int k = 0; k < 3 && nv > 0; ++k) {
    xyz[k] = v->find(std::string(1, "xyz"[k]));
    if (!xyz[k] || xyz[k]->list)
      throw InputError("PLY '" + path + "': the vertices have no property " + std::string(1, "xyz"[k]));
  }
  const PlyProperty *nrm[3] = {nullptr, nullptr, nullptr}, *rgb[3] = {nullptr, nullptr, nullptr};
  bool has_n = false, has_c = false;
  const char* colour_names[] = {"red", "green", "blue"};
  for (int k = 0; k < 3 && nv > 0; ++k) {
    nrm[k] = v->find(std::string("n") + "xyz"[k]);
    rgb[k] = v->find(colour_names[k]);
    if (nrm[k] && nrm[k]->list) nrm[k] = nullptr;
    if (rgb[k] && rgb[k]->list) rgb[k] = nullptr;
    has_n |= nrm[k] != nullptr, has_c |= rgb[k] != nullptr;
  }
  m.positions.resize(nv);
  if (has_n) m.normals.assign(nv, vec3{0.f, 0.f, 0.f});
  if (has_c) m.colors.assign(nv, uchar3{0, 0, 0});
  for (std::int64_t i = 0; i < nv; ++i)
    for (int k = 0; k < 3; ++k) {
      const float x = as_float(xyz[k]->value(i));
      const float nk = nrm[k] ? as_float(nrm[k]->value(i)) : 0.f;
      if (!std::isfinite(x) || !std::isfinite(nk))
        throw InputError("PLY '" + path + "': vertex " + std::to_string(i) + " has a non-finite " +
                         std::string(std::isfinite(x) ? "n" : "") + "xyz"[k]);
      (&m.positions[i].x)[k] = x;
      if (has_n) (&m.normals[i].x)[k] = nk;
      if (rgb[k]) {
        const double c = rgb[k]->value(i);
        if (!(c >= 0 && c <= 255))
          throw InputError("PLY '" + path + "': vertex " + std::to_string(i) + " has " + colour_names[k] + " " +
                           std::to_string(c) + ", outside 0..255");
        (&m.colors[i].x)[k] = static_cast<std::uint8_t>(c);
      }
    }
  const PlyElement* f = d.find("face");
  if (!f || f->count == 0) return m;
  const PlyProperty* idx = f->find("vertex_indices");
  if (!idx) idx = f->find("vertex_index");
  if (!idx || !idx->list || !is_integer(idx->type))
    throw InputError("PLY '" + path + "': the faces have no integer list vertex_indices");
  m.triangles.resize(f->count);
  for (std::int64_t i = 0; i < f->count; ++i) {
    const std::int64_t a = idx->starts[i];
    if (idx->starts[i + 1] - a != 3)
      throw InputError("PLY '" + path + "': face " + std::to_string(i) + " is not a triangle");
    int c[3];
    for (int k = 0; k < 3; ++k) {
      const double j = idx->value(a + k);
      if (j < 0 || j >= static_cast<double>(nv) || j > std::numeric_limits<int>::max())
        throw InputError("PLY '" + path + "': face " + std::to_string(i) + " refers to vertex " +
                         std::to_string(static_cast<std::int64_t>(j)) + ", but there are " + std::to_string(nv) +
                         " vertices");
      c[k] = static_cast<int>(j);
    }
    m.triangles[i] = {c[0], c[1], c[2]};
  }
  return m;
}

// ---- particle states ---------------------------------------------------------------------------

void write_particles_ply(const std::string& path, const ParticleState& s) {
  PlyElementOut v{"vertex", static_cast<std::int64_t>(s.x.size()), {}};
  for (int k = 0; k < 3; ++k)
    v.columns.push_back({std::string(1, "xyz"[k]), PlyType::f32, component(s.x, k), sizeof(vec3), 0});
  for (int k = 0; k < 3; ++k)
    v.columns.push_back({std::string("v") + "xyz"[k], PlyType::f32, component(s.v, k), sizeof(vec3), 0});
  v.columns.push_back({"phase", PlyType::u32, s.phase.data(), sizeof(std::uint32_t), 0});
  write_ply_data(path, {v}, "particle file");
}

ParticleState read_particles_ply(const std::string& path) {
  const PlyData d = read_ply_data(path);
  const PlyElement* v = d.find("vertex");
  const char* names[] = {"x", "y", "z", "vx", "vy", "vz", "phase"};
  const PlyProperty* p[7];
  for (int k = 0; k < 7; ++k) {
    p[k] = v ? v->find(names[k]) : nullptr;
    if (!p[k] || p[k]->list)
      throw InputError("'" + path + "' is not a particle file of `seamless run` (its vertices have no " + names[k] +
                       "; expected x y z vx vy vz phase)");
  }
  if (!is_integer(p[6]->type)) throw InputError("PLY '" + path + "': phase is not an integer property");
  const std::int64_t n = v->count;
  ParticleState s;
  s.x.resize(n), s.v.resize(n), s.phase.resize(n), s.inv_mass.assign(n, 1.f);
  for (std::int64_t i = 0; i < n; ++i) {
    s.x[i] = {as_float(p[0]->value(i)), as_float(p[1]->value(i)), as_float(p[2]->value(i))};
    s.v[i] = {as_float(p[3]->value(i)), as_float(p[4]->value(i)), as_float(p[5]->value(i))};
    const double ph = p[6]->value(i);
    if (ph < 0 || ph > 4294967295.0)
      throw InputError("PLY '" + path + "': particle " + std::to_string(i) + " has phase " + std::to_string(ph));
    s.phase[i] = static_cast<std::uint32_t>(ph);
  }
  return s;
}

}  // namespace seamless
