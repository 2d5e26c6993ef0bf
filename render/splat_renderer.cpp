#include "render/splat_renderer.hpp"

#include <algorithm>
#include <array>
#include <chrono>

#include "render/gl_objects.hpp"
#include "render/splat_shaders.hpp"

namespace scanbench::render {

namespace {

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

struct SplatRenderer::Gpu {
  std::array<GlBuffer, 7> attributes;
  GlVertexArray points;
  SplatPasses passes{shaders::splat_vertex()};
};

SplatRenderer::SplatRenderer(const RenderModel& model)
    : model_(model), gpu_(std::make_unique<Gpu>()) {
  const RenderPoints& p = model.points;
  gpu_->attributes = {upload(p.position),  upload(p.normal), upload(p.radii_m),   upload(p.rgba),
                      upload(p.intensity), upload(p.node),   upload(p.major_axis)};
  gpu_->points = make_vertex_array();
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
  const RenderView view = SplatPasses::banded(picture_view);
  FrameResult result;
  result.plan = plan_frame(model_, view, settings.culling);
  SplatPasses& passes = gpu_->passes;
  result.gpu_ms = passes.draw(view, settings, height_range_, [&] {
    glBindVertexArray(gpu_->points.get());
    for (const TileDraw& draw : result.plan.draws) {
      passes.uniform("u_min_radius", draw.min_radius_m);
      glDrawArrays(GL_POINTS, static_cast<GLint>(model_.tiles[draw.tile].first),
                   static_cast<GLsizei>(draw.count));
    }
  });
  result.frame_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return result;
}

PictureTexture SplatRenderer::picture_texture() const {
  return gpu_->passes.picture_texture();
}

RenderedImage SplatRenderer::read_image() const {
  return gpu_->passes.read_image();
}

}  // namespace scanbench::render
