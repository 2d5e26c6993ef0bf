// The splat passes on the headless device (llvmpipe in CI), drawing the
// wall's store: raw points leave holes that splats close, each half of the
// wall keeps its colour, hidden objects are not drawn, and every kernel and
// colour mode draws.
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <memory>

#include "render/device.hpp"
#include "render/lod_renderer.hpp"
#include "render/object_palette.hpp"
#include "shared_device.hpp"
#include "wall_model.hpp"

namespace scanbench::render {
namespace {

using test::kOrigin;

RenderDevice& device() {
  return test::shared_device();
}

TEST(SplatRenderer, DevicesComeAndGoWhileAnotherDraws) {
  device();
  { const std::unique_ptr<RenderDevice> second = make_headless_device(); }
  device();
  LodRenderer renderer(test::wall_store(), {});
  renderer.draw_complete(
      make_render_view(test::camera_at({1000.0, 2000.0, 1.5}), renderer.header().origin), {});
  EXPECT_TRUE(renderer.read_image().covered(80, 60));
}

// The wall covers x 141…499, y 106…374 of the 640 × 480 frame; a margin in.
struct Inside {
  double covered = 0.0;   // share of pixels drawn
  double red_left = 0.0;  // share of drawn pixels of the left half that are red
  double blue_right = 0.0;
};

Inside inside_the_wall(const RenderedImage& image) {
  Inside out;
  std::size_t pixels = 0, covered = 0, left = 0, red = 0, right = 0, blue = 0;
  for (int y = 116; y < 364; ++y) {
    for (int x = 151; x < 489; ++x) {
      ++pixels;
      if (!image.covered(x, y)) continue;
      ++covered;
      const std::uint8_t* p = &image.rgba[4 * (static_cast<std::size_t>(y) * image.width + x)];
      if (x < 310) {
        ++left;
        red += p[0] > 150 && p[2] < 80;
      } else if (x > 330) {
        ++right;
        blue += p[2] > 150 && p[0] < 80;
      }
    }
  }
  out.covered = static_cast<double>(covered) / static_cast<double>(pixels);
  out.red_left = left ? static_cast<double>(red) / static_cast<double>(left) : 0.0;
  out.blue_right = right ? static_cast<double>(blue) / static_cast<double>(right) : 0.0;
  return out;
}

// The wall drawn complete through a 640 × 480 camera at `eye`.
RenderedImage render(const RenderSettings& settings,
                     const Eigen::Vector3d& eye = {1000.0, 2000.0, 1.5}, bool hide_right = false) {
  device();
  LodRenderer renderer(test::wall_store(), {});
  renderer.set_objects(test::wall_tree(hide_right));
  renderer.draw_complete(make_render_view(test::camera_at(eye, 640, 480), kOrigin), settings);
  return renderer.read_image();
}

TEST(SplatRenderer, ADrawLeavesTheGlStateAsItFoundIt) {
  device();
  LodRenderer renderer(test::wall_store(), {});
  const RenderView view = make_render_view(test::camera_at({1000.0, 2000.0, 1.5}, 64, 48), kOrigin);
  renderer.draw_complete(view, {});
  const RenderedImage clean = renderer.read_image();
  // A host's state, ImGui's for instance: none of what drawing splats needs.
  glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_PROGRAM_POINT_SIZE);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glEnable(GL_SCISSOR_TEST);
  glScissor(0, 0, 1, 1);
  glColorMask(GL_TRUE, GL_FALSE, GL_TRUE, GL_TRUE);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glUseProgram(0);
  glViewport(1, 2, 3, 4);
  renderer.draw_complete(view, {});
  // The same picture: the passes set their own state.
  EXPECT_EQ(renderer.read_image().rgba, clean.rgba);
  GLint origin = 0, framebuffer = -1, program = -1, source = 0;
  std::array<GLint, 4> viewport{};
  glGetIntegerv(GL_CLIP_ORIGIN, &origin);
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &framebuffer);
  glGetIntegerv(GL_CURRENT_PROGRAM, &program);
  glGetIntegerv(GL_BLEND_SRC_RGB, &source);
  glGetIntegerv(GL_VIEWPORT, viewport.data());
  EXPECT_EQ(origin, GL_LOWER_LEFT);
  EXPECT_FALSE(glIsEnabled(GL_DEPTH_TEST));
  EXPECT_FALSE(glIsEnabled(GL_PROGRAM_POINT_SIZE));
  EXPECT_TRUE(glIsEnabled(GL_BLEND));
  EXPECT_EQ(source, GL_SRC_ALPHA);
  EXPECT_EQ(framebuffer, 0);
  EXPECT_EQ(program, 0);
  EXPECT_EQ(viewport, (std::array<GLint, 4>{1, 2, 3, 4}));
  EXPECT_TRUE(glIsEnabled(GL_SCISSOR_TEST));
  std::array<GLboolean, 4> mask{};
  glGetBooleanv(GL_COLOR_WRITEMASK, mask.data());
  EXPECT_EQ(mask, (std::array<GLboolean, 4>{GL_TRUE, GL_FALSE, GL_TRUE, GL_TRUE}));
  glDisable(GL_BLEND);
  glDisable(GL_SCISSOR_TEST);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
}

TEST(SplatRenderer, TheHeadlessDeviceIsOpenGl45) {
  EXPECT_NE(device().describe().find("4.5"), std::string::npos) << device().describe();
}

TEST(SplatRenderer, RawPointsLeaveHolesThatBlendedSplatsClose) {
  RenderSettings points;
  points.mode = DrawMode::kPoints;
  const Inside raw = inside_the_wall(render(points));
  EXPECT_GT(raw.covered, 0.03);  // a pixel every 4.5 pixels each way
  EXPECT_LT(raw.covered, 0.1);
  EXPECT_GT(raw.red_left, 0.99);
  for (const DrawMode mode : {DrawMode::kSplats, DrawMode::kBlended}) {
    RenderSettings splats;
    splats.mode = mode;
    const Inside closed = inside_the_wall(render(splats));
    EXPECT_EQ(closed.covered, 1.0) << draw_mode_name(mode);
    EXPECT_GT(closed.red_left, 0.99) << draw_mode_name(mode);
    EXPECT_GT(closed.blue_right, 0.99) << draw_mode_name(mode);
  }
}

TEST(SplatRenderer, EveryKernelClosesTheWallAndTheBackgroundStaysEmpty) {
  for (const Kernel kernel : {Kernel::kDisk, Kernel::kGaussian, Kernel::kCosine}) {
    RenderSettings settings;
    settings.kernel = kernel;
    settings.background = {10, 20, 30};
    const RenderedImage image = render(settings);
    EXPECT_EQ(inside_the_wall(image).covered, 1.0) << kernel_name(kernel);
    EXPECT_FALSE(image.covered(5, 5));
    EXPECT_EQ(image.rgba[0], 10);
    EXPECT_EQ(image.rgba[2], 30);
  }
}

// Splats at 0.8 × their radii leave a pinhole at every cell's centre; the
// resolve fills each from the splats round it, and nothing beyond the
// wall's edges, where background lies on one side.
TEST(SplatRenderer, PinholesRingedBySplatsAreFilledAndTheSilhouetteStays) {
  RenderSettings thin;
  thin.splat_scale = 0.8f;
  thin.fill_reach_px = 0;
  const RenderedImage open = render(thin);
  EXPECT_LT(inside_the_wall(open).covered, 0.995);
  thin.fill_reach_px = 3;
  const RenderedImage filled = render(thin);
  const Inside inside = inside_the_wall(filled);
  EXPECT_EQ(inside.covered, 1.0);
  EXPECT_GT(inside.red_left, 0.99);
  EXPECT_GT(inside.blue_right, 0.99);
  for (int y = 0; y < 480; ++y) {
    for (const int x : {120, 136, 504, 520}) EXPECT_FALSE(filled.covered(x, y)) << x << ", " << y;
  }
  for (int x = 0; x < 640; ++x) {
    for (const int y : {90, 101, 379, 390}) EXPECT_FALSE(filled.covered(x, y)) << x << ", " << y;
  }
}

TEST(SplatRenderer, HiddenObjectsAreNotDrawn) {
  const RenderedImage image = render({}, {1000.0, 2000.0, 1.5}, true);
  std::size_t right = 0;
  for (int y = 116; y < 364; ++y) {
    for (int x = 340; x < 489; ++x) right += image.covered(x, y);
  }
  EXPECT_EQ(right, 0u);
  EXPECT_GT(inside_the_wall(image).red_left, 0.99);
}

// A clipping box around the left half draws only it; a slice 1 m thick
// through the wall's middle draws only that band (the wall spans 3 m, rows
// 106…374: the band lies within rows 150…330).
TEST(SplatRenderer, AClippingBoxAndASliceLimitWhatIsDrawn) {
  RenderSettings boxed;
  boxed.culling.clipping.box = Eigen::AlignedBox3f(Eigen::Vector3f(9.0f, 0.0f, -1.0f),
                                                   Eigen::Vector3f(11.0f, 3.0f, 4.0f));
  const RenderedImage left = render(boxed);
  std::size_t right = 0;
  for (int y = 116; y < 364; ++y) {
    for (int x = 340; x < 489; ++x) right += left.covered(x, y);
  }
  EXPECT_EQ(right, 0u);
  EXPECT_GT(inside_the_wall(left).red_left, 0.99);

  RenderSettings sliced;
  sliced.culling.clipping.section_normal = Eigen::Vector3f::UnitZ();
  sliced.culling.clipping.section_offset = 1.5f;
  sliced.culling.clipping.section_half_width = 0.5f;
  const RenderedImage band = render(sliced);
  std::size_t outside = 0, inside = 0, pixels = 0;
  for (int x = 151; x < 489; ++x) {
    for (int y = 116; y < 140; ++y) outside += band.covered(x, y);
    for (int y = 360; y < 364; ++y) outside += band.covered(x, y);
    for (int y = 200; y < 280; ++y, ++pixels) inside += band.covered(x, y);
  }
  EXPECT_EQ(outside, 0u);
  EXPECT_EQ(inside, pixels);
}

TEST(SplatRenderer, TheBackOfTheWallIsCulledUnlessAskedFor) {
  const Eigen::Vector3d behind(1020.0, 2000.0, 1.5);
  std::size_t drawn = 0;
  const RenderedImage culled = render({}, behind);
  for (std::size_t i = 3; i < culled.rgba.size(); i += 4) drawn += culled.rgba[i] != 0;
  EXPECT_EQ(drawn, 0u);
  RenderSettings both_sides;
  both_sides.culling.backface = false;
  const RenderedImage seen = render(both_sides, behind);
  EXPECT_TRUE(seen.covered(320, 240));
}

TEST(SplatRenderer, ColourModesDrawWhatTheyName) {
  RenderSettings settings;
  settings.color = ColorMode::kObject;
  const RenderedImage objects = render(settings);
  const auto pixel = [&](const RenderedImage& image, int x, int y) {
    const std::uint8_t* p = &image.rgba[4 * (static_cast<std::size_t>(y) * image.width + x)];
    return Eigen::Vector3i(p[0], p[1], p[2]);
  };
  EXPECT_NE(pixel(objects, 200, 240), pixel(objects, 440, 240));  // objects 1 and 2
  // The shaders' palette is object_palette.hpp's, as the panorama shows it.
  const std::array<std::uint8_t, 3> one = object_color(1);
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(pixel(objects, 200, 240)[c], one[static_cast<std::size_t>(c)], 1);
  settings.color = ColorMode::kIntensity;
  EXPECT_EQ(pixel(render(settings), 200, 240), Eigen::Vector3i(128, 128, 128));
  settings.color = ColorMode::kNormal;  // (−1, 0, 0) → (0, 0.5, 0.5)
  EXPECT_EQ(pixel(render(settings), 200, 240), Eigen::Vector3i(0, 128, 128));
  for (const ColorMode mode : {ColorMode::kHeight, ColorMode::kColor}) {
    settings.color = mode;
    settings.lighting = true;
    settings.eye_dome = true;
    EXPECT_EQ(inside_the_wall(render(settings)).covered, 1.0) << color_mode_name(mode);
  }
}

}  // namespace
}  // namespace scanbench::render
