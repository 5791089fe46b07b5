// Shader errors name the file and line; every embedded program compiles on this driver.
#include <epoxy/gl.h>

#include "core/error.hpp"
#include "render/shader.hpp"
#include "render_test_util.hpp"

namespace seamless::test {
namespace {

TEST(RenderShader, LogMapsStringNumbersToFiles) {
  const std::vector<std::string> files = {"camera.glsl", "ssfr_filter.frag"};
  EXPECT_EQ(map_shader_log("0:200017(5): error: `x' undeclared", files), "ssfr_filter.frag:17: error: `x' undeclared");
  EXPECT_EQ(map_shader_log("0(100004) : error C1008: undefined variable", files),
            "camera.glsl:4 : error C1008: undefined variable");
}

TEST(RenderShader, CompileErrorNamesShaderAndLine) {
  SEAMLESS_REQUIRE_EGL();
  HeadlessContext ctx;
  const std::string good = "uniform float u_a;\n";
  const std::string bad = "out vec4 o;\nvoid main() {\n  o = vec4(undeclared_thing);\n}\n";
  try {
    Program::from_sources("test", {{GL_FRAGMENT_SHADER, {{"helpers.glsl", good}, {"broken.frag", bad}}}});
    FAIL() << "a broken shader compiled";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("broken.frag:3"), std::string::npos) << m;
  }
}

TEST(RenderShader, AllProgramsBuild) {
  SEAMLESS_REQUIRE_EGL();
  EXPECT_NO_THROW(Renderer(RenderParams{}, 32, 24));
}

}  // namespace
}  // namespace seamless::test
