// Program compilation with errors mapped back to shader files (see shader.hpp).
#include "render/shader.hpp"

#include <epoxy/gl.h>

#include <map>
#include <regex>

#include "core/error.hpp"

namespace seamless {
namespace detail {
// Generated at configure time from src/render/shaders/* (see src/render/CMakeLists.txt).
extern const char* const kShaderNames[];
extern const char* const kShaderTexts[];
extern const int kShaderCount;
}  // namespace detail

namespace {
constexpr long kLinesPerFile = 100000;  // see assemble()
}  // namespace

const std::string& shader_source(const std::string& name) {
  static const std::map<std::string, std::string> table = [] {
    std::map<std::string, std::string> t;
    for (int i = 0; i < detail::kShaderCount; ++i) t[detail::kShaderNames[i]] = detail::kShaderTexts[i];
    return t;
  }();
  auto it = table.find(name);
  if (it == table.end()) throw Error("render: no embedded shader named '" + name + "' (src/render/shaders/)");
  return it->second;
}

std::string map_shader_log(const std::string& log, const std::vector<std::string>& files) {
  // Mesa: "0:100017(5): error: ..."; NVIDIA: "0(100017) : error C1008: ...". Group 1 / 2 = line.
  static const std::regex loc(R"(\d+:(\d+)\(\d+\)|\d+\((\d+)\))");
  std::string out;
  std::size_t last = 0;
  for (auto it = std::sregex_iterator(log.begin(), log.end(), loc); it != std::sregex_iterator(); ++it) {
    const std::smatch& m = *it;
    const long line = std::stol(m[1].matched ? m[1].str() : m[2].str());
    const long file = line / kLinesPerFile - 1;
    out += log.substr(last, static_cast<std::size_t>(m.position()) - last);
    if (file >= 0 && file < static_cast<long>(files.size()))
      out += files[static_cast<std::size_t>(file)] + ":" + std::to_string(line % kLinesPerFile);
    else out += m.str();
    last = static_cast<std::size_t>(m.position() + m.length());
  }
  return out + log.substr(last);
}

namespace {

using Sources = std::vector<std::pair<std::string, std::string>>;  // file name, text

// "#version" first, then file i behind "#line (i + 1) * kLinesPerFile + 1" (GLSL 4.10 spec,
// section 3.4), so that a reported line says both the file and its own line. (The source-string
// number of #line would be the natural carrier, but Mesa reports it as 0.)
// Compute shaders need GLSL 4.30 (GL 4.3); they define SEAMLESS_COMPUTE so that shared files
// leave out what only a fragment has (gl_FragCoord, flat inputs).
std::string assemble(GLenum type, const Sources& src) {
  // Conservative depth (GL 4.2 core, an extension to 4.1) lets the sphere shaders keep the early
  // depth test although they write gl_FragDepth; "enable" only warns where it is missing.
  std::string s = type == GL_COMPUTE_SHADER ? "#version 430 core\n#define SEAMLESS_COMPUTE 1\n"
                                            : "#version 410 core\n#extension GL_ARB_conservative_depth : enable\n";
  for (std::size_t i = 0; i < src.size(); ++i)
    s += "#line " + std::to_string((static_cast<long>(i) + 1) * kLinesPerFile + 1) + "\n" + src[i].second + "\n";
  return s;
}

std::string info_log(GLuint obj, bool program) {
  GLint n = 0;
  program ? glGetProgramiv(obj, GL_INFO_LOG_LENGTH, &n) : glGetShaderiv(obj, GL_INFO_LOG_LENGTH, &n);
  std::string log(static_cast<std::size_t>(n > 0 ? n : 1), '\0');
  program ? glGetProgramInfoLog(obj, n, nullptr, log.data()) : glGetShaderInfoLog(obj, n, nullptr, log.data());
  return log.c_str();
}

GLuint compile(const std::string& program, GLenum type, const Sources& src) {
  const std::string text = assemble(type, src);
  const char* p = text.c_str();
  GLuint sh = glCreateShader(type);
  glShaderSource(sh, 1, &p, nullptr);
  glCompileShader(sh);
  GLint ok = 0;
  glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    std::vector<std::string> names;
    for (const auto& f : src) names.push_back(f.first);
    const std::string log = map_shader_log(info_log(sh, false), names);
    glDeleteShader(sh);
    throw Error("render: shader " + names.back() + " (program '" + program + "') failed to compile:\n" + log);
  }
  return sh;
}

}  // namespace

Program Program::from_sources(const std::string& name, const std::vector<std::pair<unsigned, Sources>>& stages) {
  Program p;
  p.id_ = glCreateProgram();
  std::vector<GLuint> shaders;
  for (const auto& [type, src] : stages) {
    try {
      shaders.push_back(compile(name, type, src));
    } catch (...) {
      for (GLuint s : shaders) glDeleteShader(s);
      throw;
    }
    glAttachShader(p.id_, shaders.back());
  }
  glLinkProgram(p.id_);
  for (GLuint s : shaders) glDeleteShader(s);
  GLint ok = 0;
  glGetProgramiv(p.id_, GL_LINK_STATUS, &ok);
  if (!ok) throw Error("render: program '" + name + "' failed to link:\n" + info_log(p.id_, true));
  return p;
}

Program::Program(const std::string& name, const std::vector<ShaderStage>& stages) {
  std::vector<std::pair<unsigned, Sources>> src;
  for (const ShaderStage& st : stages) {
    Sources files;
    for (const std::string& f : st.files) files.emplace_back(f, shader_source(f));
    src.emplace_back(st.type, std::move(files));
  }
  *this = from_sources(name, src);
}

Program::~Program() {
  if (id_) glDeleteProgram(id_);
}
Program::Program(Program&& o) noexcept : id_(o.id_) { o.id_ = 0; }
Program& Program::operator=(Program&& o) noexcept {
  if (this != &o) {
    if (id_) glDeleteProgram(id_);
    id_ = o.id_;
    o.id_ = 0;
  }
  return *this;
}
void Program::use() const { glUseProgram(id_); }
int Program::loc(const char* uniform) const { return glGetUniformLocation(id_, uniform); }

}  // namespace seamless
