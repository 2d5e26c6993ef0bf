#include "render/splat_passes.hpp"

#include <algorithm>
#include <cassert>

#include "render/gl_objects.hpp"
#include "render/gl_state.hpp"
#include "render/splat_shaders.hpp"

namespace scanbench::render {

namespace {

constexpr std::array<std::string_view, 3> kDrawModeNames = {"points", "splats", "blended"};
constexpr std::array<std::string_view, 3> kKernelNames = {"disk", "gaussian", "cosine"};
constexpr std::array<std::string_view, 5> kColorModeNames = {"color", "intensity", "height",
                                                             "normal", "object"};

template <typename Enum, std::size_t N>
std::optional<Enum> from_name(const std::array<std::string_view, N>& names, std::string_view name) {
  const auto found = std::find(names.begin(), names.end(), name);
  if (found == names.end()) return std::nullopt;
  return static_cast<Enum>(found - names.begin());
}

}  // namespace

std::string_view draw_mode_name(DrawMode mode) {
  return kDrawModeNames[static_cast<int>(mode)];
}
std::string_view kernel_name(Kernel kernel) {
  return kKernelNames[static_cast<int>(kernel)];
}
std::string_view color_mode_name(ColorMode mode) {
  return kColorModeNames[static_cast<int>(mode)];
}
std::optional<DrawMode> draw_mode_from_name(std::string_view name) {
  return from_name<DrawMode>(kDrawModeNames, name);
}
std::optional<Kernel> kernel_from_name(std::string_view name) {
  return from_name<Kernel>(kKernelNames, name);
}
std::optional<ColorMode> color_mode_from_name(std::string_view name) {
  return from_name<ColorMode>(kColorModeNames, name);
}

std::vector<std::uint8_t> RenderedImage::rgb() const {
  std::vector<std::uint8_t> out(3 * (rgba.size() / 4));
  for (std::size_t i = 0; i < rgba.size() / 4; ++i) {
    for (std::size_t c = 0; c < 3; ++c) out[3 * i + c] = rgba[4 * i + c];
  }
  return out;
}

std::vector<std::uint8_t> RenderedImage::coverage() const {
  std::vector<std::uint8_t> out(rgba.size() / 4);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = rgba[4 * i + 3] != 0;
  return out;
}

struct SplatPasses::Gpu {
  GlVertexArray empty;  // the resolve's triangle needs no attributes
  GlProgram splat;
  GlProgram resolve;
  // The frame's targets, made for one size.
  int width = 0;
  int height = 0;
  GlTexture accumulated;  // RGBA32F: Σ w·colour, Σ w
  GlTexture depth;        // DEPTH_COMPONENT32F, reversed Z
  GlTexture picture;      // RGBA8: the resolved frame, the picture's size
  GlFramebuffer splat_target;
  GlFramebuffer picture_target;

  void ensure_size(int w, int h) {
    if (w == width && h == height) return;
    width = w;
    height = h;
    accumulated = make_texture_2d(GL_RGBA32F, w, h);
    depth = make_texture_2d(GL_DEPTH_COMPONENT32F, w, h);
    picture = make_texture_2d(GL_RGBA8, w, h);
    splat_target = make_framebuffer();
    glNamedFramebufferTexture(splat_target.get(), GL_COLOR_ATTACHMENT0, accumulated.get(), 0);
    glNamedFramebufferTexture(splat_target.get(), GL_DEPTH_ATTACHMENT, depth.get(), 0);
    picture_target = make_framebuffer();
    glNamedFramebufferTexture(picture_target.get(), GL_COLOR_ATTACHMENT0, picture.get(), 0);
  }

  GLint location(const char* name) const { return glGetUniformLocation(splat.get(), name); }

  void set_splat_uniforms(const RenderView& view, const RenderSettings& settings,
                          const Eigen::Vector2f& height_range) const {
    const GLuint program = splat.get();
    glProgramUniformMatrix4fv(program, location("u_view"), 1, GL_FALSE, view.view.data());
    glProgramUniformMatrix4fv(program, location("u_projection"), 1, GL_FALSE,
                              view.projection.data());
    glProgramUniform3fv(program, location("u_eye"), 1, view.eye.data());
    glProgramUniform2f(program, location("u_viewport"), static_cast<float>(view.width),
                       static_cast<float>(view.height));
    glProgramUniform2f(program, location("u_viewport_origin"), -kGuardBandPixels,
                       -kGuardBandPixels);
    glProgramUniform2fv(program, location("u_height_range"), 1, height_range.data());
    glProgramUniform1f(program, location("u_focal"), view.focal_px);
    glProgramUniform1f(program, location("u_scale"), settings.splat_scale);
    glProgramUniform1i(program, location("u_points"), settings.mode == DrawMode::kPoints ? 1 : 0);
    glProgramUniform1i(program, location("u_backface"), settings.culling.backface ? 1 : 0);
    glProgramUniform1i(program, location("u_color_mode"), static_cast<int>(settings.color));
    glProgramUniform1i(program, location("u_lighting"), settings.lighting ? 1 : 0);
    glProgramUniform1i(program, location("u_kernel"), static_cast<int>(settings.kernel));
    glProgramUniform1i(program, location("u_oriented"), settings.oriented ? 1 : 0);
    glProgramUniform1f(program, location("u_depth_offset"), settings.depth_offset);
    const Clipping& clip = settings.culling.clipping;
    glProgramUniform1i(program, location("u_clip_box"), clip.box.isEmpty() ? 0 : 1);
    if (!clip.box.isEmpty()) {
      glProgramUniform3fv(program, location("u_clip_min"), 1, clip.box.min().data());
      glProgramUniform3fv(program, location("u_clip_max"), 1, clip.box.max().data());
    }
    glProgramUniform4f(program, location("u_section"), clip.section_normal.x(),
                       clip.section_normal.y(), clip.section_normal.z(), clip.section_offset);
    glProgramUniform1f(program, location("u_section_half_width"), clip.section_half_width);
  }

  // The renderer's draws into the splat target: one opaque pass, or the
  // visibility and accumulation passes of blending.
  void draw_splats(DrawMode mode, const std::function<void()>& draw_points) const {
    // Whatever state the host left (its blending, scissor, culling, stencil,
    // colour mask), the passes set what they rely on.
    glDisable(GL_BLEND);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_CULL_FACE);
    glDisable(GL_STENCIL_TEST);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    glEnable(GL_PROGRAM_POINT_SIZE);
    glEnable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, splat_target.get());
    // The banded view over the picture's target: splats whose centres lie
    // in the guard band pass the clipping, and their fragments beyond the
    // target are never shaded.
    glViewport(-kGuardBandPixels, -kGuardBandPixels, width + 2 * kGuardBandPixels,
               height + 2 * kGuardBandPixels);
    const float clear_color[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    const float clear_depth = 0.0f;  // reversed Z: 0 is the far plane
    glClearNamedFramebufferfv(splat_target.get(), GL_COLOR, 0, clear_color);
    glClearNamedFramebufferfv(splat_target.get(), GL_DEPTH, 0, &clear_depth);
    glUseProgram(splat.get());
    const GLint pass = location("u_pass");
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_GREATER);
    if (mode != DrawMode::kBlended) {
      glProgramUniform1i(splat.get(), pass,
                         mode == DrawMode::kPoints ? shaders::kPassPoints : shaders::kPassOpaque);
      draw_points();
      return;
    }
    glProgramUniform1i(splat.get(), pass, shaders::kPassVisibility);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    draw_points();
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glProgramUniform1i(splat.get(), pass, shaders::kPassAccumulate);
    glDepthMask(GL_FALSE);
    glDepthFunc(GL_GEQUAL);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    draw_points();
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
  }

  // Weighted colours divided into the picture, the background where none.
  void resolve_picture(const RenderView& view, const RenderSettings& settings) const {
    const GLuint program = resolve.get();
    const auto at = [&](const char* name) { return glGetUniformLocation(program, name); };
    glDisable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, picture_target.get());
    glViewport(0, 0, width, height);
    glUseProgram(program);
    glBindTextureUnit(0, accumulated.get());
    glBindTextureUnit(1, depth.get());
    glProgramUniform1i(program, at("u_accumulated"), 0);
    glProgramUniform1i(program, at("u_depth"), 1);
    glProgramUniform3f(program, at("u_background"), settings.background[0] / 255.0f,
                       settings.background[1] / 255.0f, settings.background[2] / 255.0f);
    glProgramUniform1i(program, at("u_eye_dome"), settings.eye_dome ? 1 : 0);
    glProgramUniform1i(program, at("u_fill_reach"),
                       settings.mode == DrawMode::kPoints ? 0 : settings.fill_reach_px);
    glProgramUniform2f(program, at("u_depth_ab"), view.projection(2, 2), view.projection(2, 3));
    glBindVertexArray(empty.get());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }
};

SplatPasses::SplatPasses(const std::string& vertex_source) : gpu_(std::make_unique<Gpu>()) {
  gpu_->empty = make_vertex_array();
  gpu_->splat = build_program("splat shaders", vertex_source.c_str(), shaders::kSplatFragment);
  gpu_->resolve =
      build_program("resolve shaders", shaders::kResolveVertex, shaders::kResolveFragment);
}

SplatPasses::~SplatPasses() = default;

RenderView SplatPasses::banded(const RenderView& picture_view) {
  return with_guard_band(picture_view, kGuardBandPixels);
}

double SplatPasses::draw(const RenderView& banded_view, const RenderSettings& settings,
                         const Eigen::Vector2f& height_range,
                         const std::function<void()>& draw_points) {
  const GlStateGuard keep;  // the caller's state, given back whatever the draw changes
  Gpu& gpu = *gpu_;
  picture_width_ = banded_view.width - 2 * kGuardBandPixels;
  picture_height_ = banded_view.height - 2 * kGuardBandPixels;
  gpu.ensure_size(picture_width_, picture_height_);
  GLuint timer = 0;
  glCreateQueries(GL_TIME_ELAPSED, 1, &timer);  // 0 where the device has none
  if (timer != 0) glBeginQuery(GL_TIME_ELAPSED, timer);
  gpu.set_splat_uniforms(banded_view, settings, height_range);
  gpu.draw_splats(settings.mode, draw_points);
  gpu.resolve_picture(banded_view, settings);
  if (timer != 0) glEndQuery(GL_TIME_ELAPSED);
  glFinish();
  if (timer == 0) return -1.0;
  GLuint64 elapsed_ns = 0;
  glGetQueryObjectui64v(timer, GL_QUERY_RESULT, &elapsed_ns);
  glDeleteQueries(1, &timer);
  return static_cast<double>(elapsed_ns) * 1e-6;
}

void SplatPasses::uniform(const char* name, int value) const {
  glProgramUniform1i(gpu_->splat.get(), gpu_->location(name), value);
}
void SplatPasses::uniform(const char* name, unsigned value) const {
  glProgramUniform1ui(gpu_->splat.get(), gpu_->location(name), value);
}
void SplatPasses::uniform(const char* name, float value) const {
  glProgramUniform1f(gpu_->splat.get(), gpu_->location(name), value);
}
void SplatPasses::uniform(const char* name, const Eigen::Vector3f& value) const {
  glProgramUniform3fv(gpu_->splat.get(), gpu_->location(name), 1, value.data());
}

PictureTexture SplatPasses::picture_texture() const {
  assert(picture_width_ > 0 && "picture_texture before the first draw");
  return {gpu_->picture.get(), {0.0f, 0.0f, 1.0f, 1.0f}};
}

RenderedImage SplatPasses::read_image() const {
  assert(picture_width_ > 0 && "read_image before the first draw");
  RenderedImage image;
  image.width = picture_width_;
  image.height = picture_height_;
  const std::size_t row = 4 * static_cast<std::size_t>(image.width);
  std::vector<std::uint8_t> bottom_up(row * image.height);
  glGetTextureSubImage(gpu_->picture.get(), 0, 0, 0, 0, image.width, image.height, 1, GL_RGBA,
                       GL_UNSIGNED_BYTE, static_cast<GLsizei>(bottom_up.size()), bottom_up.data());
  image.rgba.resize(bottom_up.size());
  for (int y = 0; y < image.height; ++y) {
    std::copy_n(bottom_up.begin() + static_cast<std::ptrdiff_t>(row * (image.height - 1 - y)), row,
                image.rgba.begin() + static_cast<std::ptrdiff_t>(row * y));
  }
  return image;
}

}  // namespace scanbench::render
