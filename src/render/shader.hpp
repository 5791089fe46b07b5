// GLSL programs built at start-up from the shader files under src/render/shaders/ (embedded into
// the binary at configure time). A compile or link error throws seamless::Error naming the
// shader file and line, e.g. "ssfr_filter.frag:17: error: ...".
#pragma once
#include <string>
#include <vector>

namespace seamless {

// The text of an embedded shader file (e.g. "mesh.vert"); throws if there is none by that name.
const std::string& shader_source(const std::string& name);

// One shader stage made of several files, concatenated in order after the #version line
// (shared helpers first, the file with main() last).
struct ShaderStage {
  unsigned type;                   // GL_VERTEX_SHADER, GL_FRAGMENT_SHADER
  std::vector<std::string> files;  // names of embedded files
};

class Program {
 public:
  Program() = default;
  // Compiles and links; `name` labels the program in error messages.
  Program(const std::string& name, const std::vector<ShaderStage>& stages);
  // Same from literal sources (name -> text), for tests of the error path.
  static Program from_sources(
      const std::string& name,
      const std::vector<std::pair<unsigned, std::vector<std::pair<std::string, std::string>>>>& stages);
  ~Program();
  Program(Program&& o) noexcept;
  Program& operator=(Program&& o) noexcept;
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  unsigned id() const { return id_; }
  void use() const;
  int loc(const char* uniform) const;  // -1 if the uniform is absent or optimised away

 private:
  unsigned id_ = 0;
};

// Rewrites a driver's info log so that each location (Mesa "0:200012(5)", NVIDIA "0(200012)")
// names the file and its own line: file i is numbered from (i + 1) * 100000 + 1 by #line.
std::string map_shader_log(const std::string& log, const std::vector<std::string>& files);

}  // namespace seamless
