#include "render/splat_renderer.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <chrono>

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

// Uploads one attribute array as its own buffer (at least one element: GL
// refuses empty storage).
template <typename T>
GlBuffer upload(const std::vector<T>& values) {
  GlBuffer buffer = make_buffer();
  const std::vector<T> one(1);
  const std::vector<T>& data = values.empty() ? one : values;
  glNamedBufferStorage(buffer.get(), static_cast<GLsizeiptr>(data.size() * sizeof(T)), data.data(),
                       0);
  return buffer;
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

struct SplatRenderer::Gpu {
  std::array<GlBuffer, 7> attributes;
  GlVertexArray points;
  GlVertexArray empty;  // the resolve's triangle needs no attributes
  GlProgram splat;
  GlProgram resolve;
  // The frame's targets, made for one size.
  int width = 0;
  int height = 0;
  GlTexture accumulated;  // RGBA32F: Σ w·colour, Σ w
  GlTexture depth;        // DEPTH_COMPONENT32F, reversed Z
  GlTexture picture;      // RGBA8: the resolved frame
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

  void set_splat_uniforms(const RenderView& view, const RenderSettings& settings,
                          const Eigen::Vector2f& height_range) const {
    const GLuint program = splat.get();
    glProgramUniformMatrix4fv(program, glGetUniformLocation(program, "u_view"), 1, GL_FALSE,
                              view.view.data());
    glProgramUniformMatrix4fv(program, glGetUniformLocation(program, "u_projection"), 1, GL_FALSE,
                              view.projection.data());
    glProgramUniform3fv(program, glGetUniformLocation(program, "u_eye"), 1, view.eye.data());
    glProgramUniform2f(program, glGetUniformLocation(program, "u_viewport"),
                       static_cast<float>(view.width), static_cast<float>(view.height));
    glProgramUniform2fv(program, glGetUniformLocation(program, "u_height_range"), 1,
                        height_range.data());
    uniform("u_focal", view.focal_px);
    uniform("u_scale", settings.splat_scale);
    uniform("u_points", settings.mode == DrawMode::kPoints ? 1 : 0);
    uniform("u_backface", settings.culling.backface ? 1 : 0);
    uniform("u_color_mode", static_cast<int>(settings.color));
    uniform("u_lighting", settings.lighting ? 1 : 0);
    uniform("u_kernel", static_cast<int>(settings.kernel));
    uniform("u_oriented", settings.oriented ? 1 : 0);
    uniform("u_depth_offset", settings.depth_offset);
    const Clipping& clip = settings.culling.clipping;
    uniform("u_clip_box", clip.box.isEmpty() ? 0 : 1);
    if (!clip.box.isEmpty()) {
      glProgramUniform3fv(program, glGetUniformLocation(program, "u_clip_min"), 1,
                          clip.box.min().data());
      glProgramUniform3fv(program, glGetUniformLocation(program, "u_clip_max"), 1,
                          clip.box.max().data());
    }
    glProgramUniform4f(program, glGetUniformLocation(program, "u_section"),
                       clip.section_normal.x(), clip.section_normal.y(), clip.section_normal.z(),
                       clip.section_offset);
    uniform("u_section_half_width", clip.section_half_width);
  }

  // The planned tiles into the splat target: one opaque pass, or the
  // visibility and accumulation passes of blending.
  void draw_splats(const RenderModel& model, const FramePlan& plan, DrawMode mode) const {
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
    glViewport(0, 0, width, height);
    const float clear_color[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    const float clear_depth = 0.0f;  // reversed Z: 0 is the far plane
    glClearNamedFramebufferfv(splat_target.get(), GL_COLOR, 0, clear_color);
    glClearNamedFramebufferfv(splat_target.get(), GL_DEPTH, 0, &clear_depth);
    glUseProgram(splat.get());
    glBindVertexArray(points.get());
    const auto draw_tiles = [&] {
      for (const TileDraw& draw : plan.draws) {
        uniform("u_min_radius", draw.min_radius_m);
        glDrawArrays(GL_POINTS, static_cast<GLint>(model.tiles[draw.tile].first),
                     static_cast<GLsizei>(draw.count));
      }
    };
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_GREATER);
    if (mode != DrawMode::kBlended) {
      uniform("u_pass", mode == DrawMode::kPoints ? shaders::kPassPoints : shaders::kPassOpaque);
      draw_tiles();
      return;
    }
    uniform("u_pass", shaders::kPassVisibility);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    draw_tiles();
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    uniform("u_pass", shaders::kPassAccumulate);
    glDepthMask(GL_FALSE);
    glDepthFunc(GL_GEQUAL);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    draw_tiles();
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
  }

  // Weighted colours divided into the picture, the background where none.
  void resolve_picture(const RenderView& view, const RenderSettings& settings) const {
    const GLuint program = resolve.get();
    glDisable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, picture_target.get());
    glUseProgram(program);
    glBindTextureUnit(0, accumulated.get());
    glBindTextureUnit(1, depth.get());
    glProgramUniform1i(program, glGetUniformLocation(program, "u_accumulated"), 0);
    glProgramUniform1i(program, glGetUniformLocation(program, "u_depth"), 1);
    glProgramUniform3f(program, glGetUniformLocation(program, "u_background"),
                       settings.background[0] / 255.0f, settings.background[1] / 255.0f,
                       settings.background[2] / 255.0f);
    glProgramUniform1i(program, glGetUniformLocation(program, "u_eye_dome"),
                       settings.eye_dome ? 1 : 0);
    glProgramUniform1i(program, glGetUniformLocation(program, "u_fill_reach"),
                       settings.mode == DrawMode::kPoints ? 0 : settings.fill_reach_px);
    glProgramUniform2f(program, glGetUniformLocation(program, "u_depth_ab"), view.projection(2, 2),
                       view.projection(2, 3));
    glBindVertexArray(empty.get());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }

  void uniform(const char* name, int value) const {
    glProgramUniform1i(splat.get(), glGetUniformLocation(splat.get(), name), value);
  }
  void uniform(const char* name, float value) const {
    glProgramUniform1f(splat.get(), glGetUniformLocation(splat.get(), name), value);
  }
};

SplatRenderer::SplatRenderer(const RenderModel& model)
    : model_(model), gpu_(std::make_unique<Gpu>()) {
  const RenderPoints& p = model.points;
  gpu_->attributes = {upload(p.position),  upload(p.normal), upload(p.radii_m),   upload(p.rgba),
                      upload(p.intensity), upload(p.node),   upload(p.major_axis)};
  gpu_->points = make_vertex_array();
  gpu_->empty = make_vertex_array();
  const GLuint vao = gpu_->points.get();
  struct Layout {
    GLint size;
    GLenum type;
    GLboolean normalized;
    GLsizei stride;
    bool integer;
  };
  constexpr std::array<Layout, 7> kLayouts = {{{3, GL_FLOAT, GL_FALSE, 12, false},
                                               {3, GL_FLOAT, GL_FALSE, 12, false},
                                               {2, GL_FLOAT, GL_FALSE, 8, false},
                                               {4, GL_UNSIGNED_BYTE, GL_TRUE, 4, false},
                                               {1, GL_FLOAT, GL_FALSE, 4, false},
                                               {1, GL_UNSIGNED_INT, GL_FALSE, 4, true},
                                               {3, GL_FLOAT, GL_FALSE, 12, false}}};
  for (GLuint k = 0; k < kLayouts.size(); ++k) {
    const Layout& l = kLayouts[k];
    glVertexArrayVertexBuffer(vao, k, gpu_->attributes[k].get(), 0, l.stride);
    if (l.integer) {
      glVertexArrayAttribIFormat(vao, k, l.size, l.type, 0);
    } else {
      glVertexArrayAttribFormat(vao, k, l.size, l.type, l.normalized, 0);
    }
    glVertexArrayAttribBinding(vao, k, k);
    glEnableVertexArrayAttrib(vao, k);
  }
  gpu_->splat =
      build_program("splat shaders", shaders::splat_vertex().c_str(), shaders::kSplatFragment);
  gpu_->resolve =
      build_program("resolve shaders", shaders::kResolveVertex, shaders::kResolveFragment);
  height_range_ = {0.0f, 1.0f};
  if (!p.position.empty()) {
    const auto [low, high] = std::minmax_element(
        p.position.begin(), p.position.end(),
        [](const Eigen::Vector3f& a, const Eigen::Vector3f& b) { return a.z() < b.z(); });
    height_range_ = {low->z(), high->z()};
  }
}

SplatRenderer::~SplatRenderer() = default;

FrameResult SplatRenderer::draw(const RenderView& picture_view, const RenderSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  const GlStateGuard keep;  // the caller's state, given back whatever the draw changes
  const RenderView view = with_guard_band(picture_view, kGuardBandPixels);
  FrameResult result;
  result.plan = plan_frame(model_, view, settings.culling);
  Gpu& gpu = *gpu_;
  gpu.ensure_size(view.width, view.height);
  picture_width_ = picture_view.width;
  picture_height_ = picture_view.height;
  GLuint timer = 0;
  glCreateQueries(GL_TIME_ELAPSED, 1, &timer);  // 0 where the device has none
  if (timer != 0) glBeginQuery(GL_TIME_ELAPSED, timer);
  gpu.set_splat_uniforms(view, settings, height_range_);
  gpu.draw_splats(model_, result.plan, settings.mode);
  gpu.resolve_picture(view, settings);
  if (timer != 0) glEndQuery(GL_TIME_ELAPSED);
  glFinish();
  if (timer != 0) {
    GLuint64 elapsed_ns = 0;
    glGetQueryObjectui64v(timer, GL_QUERY_RESULT, &elapsed_ns);
    glDeleteQueries(1, &timer);
    result.gpu_ms = static_cast<double>(elapsed_ns) * 1e-6;
  }
  result.frame_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return result;
}

SplatRenderer::PictureTexture SplatRenderer::picture_texture() const {
  assert(picture_width_ > 0 && "picture_texture before the first draw");
  const auto w = static_cast<float>(gpu_->width), h = static_cast<float>(gpu_->height);
  const auto band = static_cast<float>(kGuardBandPixels);
  return {gpu_->picture.get(),
          {band / w, band / h, (band + static_cast<float>(picture_width_)) / w,
           (band + static_cast<float>(picture_height_)) / h}};
}

RenderedImage SplatRenderer::read_image() const {
  assert(picture_width_ > 0 && "read_image before the first draw");
  RenderedImage image;
  image.width = picture_width_;
  image.height = picture_height_;
  const std::size_t row = 4 * static_cast<std::size_t>(image.width);
  std::vector<std::uint8_t> bottom_up(row * image.height);
  glGetTextureSubImage(gpu_->picture.get(), 0, kGuardBandPixels, kGuardBandPixels, 0, image.width,
                       image.height, 1, GL_RGBA, GL_UNSIGNED_BYTE,
                       static_cast<GLsizei>(bottom_up.size()), bottom_up.data());
  image.rgba.resize(bottom_up.size());
  for (int y = 0; y < image.height; ++y) {
    std::copy_n(bottom_up.begin() + static_cast<std::ptrdiff_t>(row * (image.height - 1 - y)), row,
                image.rgba.begin() + static_cast<std::ptrdiff_t>(row * y));
  }
  return image;
}

}  // namespace scanbench::render
