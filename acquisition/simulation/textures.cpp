// Procedural surface patterns. Every pattern is a pure function of the
// material and the hit's texture coordinates [m], built from hashed lattice
// values (value noise), so colour and reflectance are deterministic, need no
// allocation and are identical on every thread.
#include "acquisition/simulation/textures.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <string>

#include "acquisition/simulation/random.hpp"

namespace scanbench::acquisition::sim {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3f;

// Colour and reflectance of one surface point, before clamping to [0, 1].
struct Sample {
  Vector3f albedo;
  float reflectance;
};

// A hashed value in [0, 1) for an integer lattice point; `salt` separates
// patterns so bricks and mortar noise are not correlated.
float lattice(std::int64_t ix, std::int64_t iy, std::uint64_t salt) {
  const std::uint64_t h = hash_combine(hash_combine(salt, static_cast<std::uint64_t>(ix)),
                                       static_cast<std::uint64_t>(iy));
  return static_cast<float>(h >> 40) * 0x1.0p-24f;
}

// Smoothly interpolated lattice values in [0, 1]: one lattice cell per unit.
float value_noise(double x, double y, std::uint64_t salt) {
  const double fx = std::floor(x);
  const double fy = std::floor(y);
  const auto ix = static_cast<std::int64_t>(fx);
  const auto iy = static_cast<std::int64_t>(fy);
  const auto smooth = [](double t) { return static_cast<float>(t * t * (3.0 - 2.0 * t)); };
  const float tx = smooth(x - fx);
  const float ty = smooth(y - fy);
  const float bottom = std::lerp(lattice(ix, iy, salt), lattice(ix + 1, iy, salt), tx);
  const float top = std::lerp(lattice(ix, iy + 1, salt), lattice(ix + 1, iy + 1, salt), tx);
  return std::lerp(bottom, top, ty);
}

// Three octaves of value noise in [0, 1]: blotches with some finer detail.
float fbm(double x, double y, std::uint64_t salt) {
  float sum = 0.0f;
  float amplitude = 0.5f;
  double frequency = 1.0;
  for (int octave = 0; octave < 3; ++octave) {
    sum += amplitude * value_noise(x * frequency, y * frequency, salt + octave);
    amplitude *= 0.5f;
    frequency *= 2.0;
  }
  return sum / 0.875f;
}

// The base colour and reflectance scaled by one factor, so the intensity
// image carries the same structure as the colour image.
Sample scaled(const Material& m, float factor) {
  return {m.albedo * factor, m.reflectance * factor};
}

bool odd(double row) {
  return (static_cast<std::int64_t>(row) & 1) != 0;
}

// Running bond: courses one third of a brick length high (≈ 240 × 80 mm with
// joints), every other course shifted by half a brick, 10 mm mortar joints.
Sample brick(const Material& m, const Vector2d& uv) {
  const double length = m.texture_scale_m;
  const double course = length / 3.0;
  constexpr double kMortar = 0.01;
  const double row = std::floor(uv.y() / course);
  const double shifted = uv.x() / length + (odd(row) ? 0.5 : 0.0);
  const double col = std::floor(shifted);
  const bool joint = (shifted - col) * length < kMortar || uv.y() - row * course < kMortar;
  const float grain = 0.9f + 0.2f * value_noise(uv.x() * 60.0, uv.y() * 60.0, 11);
  if (joint) return {Vector3f(0.52f, 0.50f, 0.46f) * grain, m.reflectance * 0.55f * grain};
  const float tint =
      0.75f + 0.45f * lattice(static_cast<std::int64_t>(col), static_cast<std::int64_t>(row), 12);
  return scaled(m, tint * grain);
}

// Coursed stone blocks: courses half a block high, odd courses shifted, wide
// dark joints, each block with its own shade and a pitted surface.
Sample stone(const Material& m, const Vector2d& uv) {
  const double length = m.texture_scale_m;
  const double course = 0.5 * length;
  constexpr double kJoint = 0.015;
  const double row = std::floor(uv.y() / course);
  const double shifted = uv.x() / length + (odd(row) ? 0.5 : 0.0);
  const double col = std::floor(shifted);
  const bool joint = (shifted - col) * length < kJoint || uv.y() - row * course < kJoint;
  if (joint) return scaled(m, 0.45f);
  const float tint =
      0.8f + 0.35f * lattice(static_cast<std::int64_t>(col), static_cast<std::int64_t>(row), 21);
  const float pits = 0.85f + 0.3f * fbm(uv.x() * 25.0, uv.y() * 25.0, 22);
  return scaled(m, tint * pits);
}

// Grain stripes running along u, warped by noise like growth rings.
Sample wood(const Material& m, const Vector2d& uv) {
  const double warp = 0.3 * value_noise(uv.x() * 2.0, uv.y() * 8.0, 31);
  const double stripes =
      std::sin(2.0 * std::numbers::pi * (uv.y() * 40.0 / m.texture_scale_m + warp));
  return scaled(m, 0.8f + 0.2f * static_cast<float>(stripes));
}

// Vertical furrows of bark: dark grooves every texture_scale_m around the trunk.
Sample bark(const Material& m, const Vector2d& uv) {
  const double wobble = 0.4 * value_noise(uv.x() * 3.0, uv.y() * 1.5, 41);
  const double ridge = std::abs(std::sin(std::numbers::pi * (uv.x() / m.texture_scale_m + wobble)));
  return scaled(m, 0.45f + 0.6f * static_cast<float>(ridge));
}

// Dark asphalt with light stone speckles (1.5 cm grains) and large stains.
Sample asphalt(const Material& m, const Vector2d& uv) {
  const float grain = lattice(static_cast<std::int64_t>(std::floor(uv.x() / 0.015)),
                              static_cast<std::int64_t>(std::floor(uv.y() / 0.015)), 51);
  const float speckle = grain > 0.92f ? 1.8f : 0.85f + 0.25f * grain;
  const float stains = 0.85f + 0.3f * fbm(uv.x() / 3.0, uv.y() / 3.0, 52);
  return scaled(m, speckle * stains);
}

// Grass: patches between the base green and a dry yellow-green, plus blades.
Sample grass(const Material& m, const Vector2d& uv) {
  const float patches = fbm(uv.x() / m.texture_scale_m, uv.y() / m.texture_scale_m, 61);
  const Vector3f dry(0.22f, 0.22f, 0.08f);
  const Vector3f colour = m.albedo + (dry - m.albedo) * (0.7f * patches);
  const float blades = 0.65f + 0.7f * value_noise(uv.x() * 90.0, uv.y() * 90.0, 62);
  return {colour * blades, m.reflectance * (0.85f + 0.3f * patches)};
}

// Leafy noise of a crown: bright leaves and dark gaps at leaf size.
Sample foliage(const Material& m, const Vector2d& uv) {
  const double s = m.texture_scale_m;
  const float leaves = value_noise(uv.x() * 8.0 / s, uv.y() * 8.0 / s, 71);
  const float clusters = fbm(uv.x() / s, uv.y() / s, 72);
  return scaled(m, 0.45f + 0.6f * leaves + 0.3f * clusters);
}

// Dark blue-grey glass with faint reflections of the sky; low return.
Sample glass(const Material& m, const Vector2d& uv) {
  const float sheen = value_noise(uv.x() * 0.7 + uv.y() * 0.5, uv.y() * 0.3, 81);
  const Vector3f tint(0.06f, 0.08f, 0.11f);
  return {tint + m.albedo * (0.3f * sheen), std::min(m.reflectance, 0.05f) * (0.8f + 0.4f * sheen)};
}

// Brushed metal: noise stretched along u.
Sample metal(const Material& m, const Vector2d& uv) {
  return scaled(m, 0.85f + 0.3f * value_noise(uv.x() * 3.0, uv.y() * 300.0, 91));
}

// Light concrete or plaster: soft blotches with a fine sandy grain.
Sample blotches(const Material& m, const Vector2d& uv, float strength, std::uint64_t salt) {
  const double s = m.texture_scale_m;
  const float blotch = fbm(uv.x() / s, uv.y() / s, salt);
  const float sand = value_noise(uv.x() * 150.0, uv.y() * 150.0, salt + 7);
  return scaled(m, 1.0f - strength + 2.0f * strength * blotch + 0.08f * (sand - 0.5f));
}

// Bilinear texel lookup with clamped edges; outside the image the plain
// material colour (e.g. the back of a sign that has its own border).
Sample image(const Material& m, const Scene& scene, const Vector2d& uv) {
  assert(m.image >= 0 && m.image < static_cast<int>(scene.images().size()) &&
         "kImage material without an image");
  const TextureImage& img = scene.images()[static_cast<std::size_t>(m.image)];
  if (uv.x() < 0.0 || uv.y() < 0.0 || uv.x() > img.width_m || uv.y() > img.height_m) {
    return {m.albedo, m.reflectance};
  }
  const double x = std::clamp(uv.x() / img.width_m * img.columns - 0.5, 0.0, img.columns - 1.0);
  const double y = std::clamp((1.0 - uv.y() / img.height_m) * img.rows - 0.5, 0.0, img.rows - 1.0);
  const int c0 = static_cast<int>(x);
  const int r0 = static_cast<int>(y);
  const int c1 = std::min(c0 + 1, img.columns - 1);
  const int r1 = std::min(r0 + 1, img.rows - 1);
  const auto texel = [&](int r, int c) {
    return img.rgb[static_cast<std::size_t>(r * img.columns + c)];
  };
  const auto tx = static_cast<float>(x - c0);
  const auto ty = static_cast<float>(y - r0);
  const Vector3f top = texel(r0, c0) * (1.0f - tx) + texel(r0, c1) * tx;
  const Vector3f bottom = texel(r1, c0) * (1.0f - tx) + texel(r1, c1) * tx;
  const Vector3f rgb = top * (1.0f - ty) + bottom * ty;
  const float luminance = 0.2126f * rgb.x() + 0.7152f * rgb.y() + 0.0722f * rgb.z();
  return {rgb, m.reflectance * (0.2f + 0.8f * luminance)};
}

Sample evaluate(const Scene& scene, const Hit& hit) {
  assert(hit.material < scene.materials().size() && "hit with an unknown material");
  const Material& m = scene.materials()[hit.material];
  const Vector2d& uv = hit.uv_m;
  switch (m.pattern) {
    case Pattern::kFlat:
      return {m.albedo, m.reflectance};
    case Pattern::kBrick:
      return brick(m, uv);
    case Pattern::kPlaster:
      return blotches(m, uv, 0.08f, 101);
    case Pattern::kStone:
      return stone(m, uv);
    case Pattern::kWood:
      return wood(m, uv);
    case Pattern::kGlass:
      return glass(m, uv);
    case Pattern::kAsphalt:
      return asphalt(m, uv);
    case Pattern::kGrass:
      return grass(m, uv);
    case Pattern::kBark:
      return bark(m, uv);
    case Pattern::kFoliage:
      return foliage(m, uv);
    case Pattern::kPaint:
      return scaled(m, 0.97f + 0.06f * value_noise(uv.x(), uv.y(), 111));
    case Pattern::kMetal:
      return metal(m, uv);
    case Pattern::kConcrete:
      return blotches(m, uv, 0.15f, 121);
    case Pattern::kImage:
      return image(m, scene, uv);
  }
  assert(false && "unknown Pattern");
  return {m.albedo, m.reflectance};
}

// sRGB-encoded byte to linear RGB, the colour space of TextureImage.
float linear_from_srgb(std::uint8_t value) {
  const double c = value / 255.0;
  return static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
}

std::string upper_case(std::string text) {
  for (char& c : text) {
    if (c >= 'a' && c <= 'z') c = static_cast<char>(c - 'a' + 'A');
  }
  return text;
}

// Draws `text` centred on the panel as large as fits (88 % of the width, 60 %
// of the height) with strokes about a sixth of the letter height: a scanner
// sampling every 3–4 cm then resolves each stroke from 20 m.
void draw_centred_text(cv::Mat& panel, const std::string& text) {
  constexpr int kFont = cv::FONT_HERSHEY_DUPLEX;
  int baseline = 0;
  const cv::Size unit = cv::getTextSize(text, kFont, 1.0, 1, &baseline);
  if (unit.width <= 0 || unit.height <= 0) return;
  double scale = std::min(0.88 * panel.cols / unit.width, 0.6 * panel.rows / unit.height);
  int thickness = 1;
  cv::Size size;
  for (int attempt = 0; attempt < 8; ++attempt) {  // thick strokes widen the text; shrink to fit
    thickness = std::max(2, static_cast<int>(std::lround(scale * unit.height / 6.0)));
    size = cv::getTextSize(text, kFont, scale, thickness, &baseline);
    if (size.width <= 0.92 * panel.cols && size.height <= 0.7 * panel.rows) break;
    scale *= 0.92;
  }
  const cv::Point origin((panel.cols - size.width) / 2, (panel.rows + size.height) / 2);
  cv::putText(panel, text, origin, kFont, scale, cv::Scalar(40, 30, 25), thickness, cv::LINE_AA);
}

}  // namespace

TextureImage make_sign_image(const std::string& text, double width_m, double height_m,
                             double pixels_per_m) {
  assert(width_m > 0.0 && height_m > 0.0 && pixels_per_m > 0.0 && "sign size must be positive");
  const int columns = std::max(16, static_cast<int>(std::lround(width_m * pixels_per_m)));
  const int rows = std::max(16, static_cast<int>(std::lround(height_m * pixels_per_m)));
  cv::Mat panel(rows, columns, CV_8UC3, cv::Scalar(215, 232, 240));  // BGR: light cream
  const int border = std::max(2, rows / 25);
  cv::rectangle(panel, cv::Rect(0, 0, columns, rows), cv::Scalar(60, 50, 45), border);
  draw_centred_text(panel, upper_case(text));
  std::array<float, 256> linear{};
  for (int v = 0; v < 256; ++v)
    linear[static_cast<std::size_t>(v)] = linear_from_srgb(static_cast<std::uint8_t>(v));
  TextureImage image{rows, columns, {}, width_m, height_m};
  image.rgb.reserve(static_cast<std::size_t>(rows) * static_cast<std::size_t>(columns));
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < columns; ++c) {
      const cv::Vec3b bgr = panel.at<cv::Vec3b>(r, c);
      image.rgb.emplace_back(linear[bgr[2]], linear[bgr[1]], linear[bgr[0]]);
    }
  }
  return image;
}

namespace {

// The pattern averaged over a disk of radius `footprint_m` around the hit in
// texture space: the centre and two rings of six (a fixed, deterministic
// pattern). A camera pixel or laser footprint integrates the surface it
// covers; point-sampling mortar joints finer than the scan spacing would
// instead alias into moiré rings.
Sample filtered(const Scene& scene, const Hit& hit, double footprint_m) {
  constexpr double kSharp = 0.002;  // below 2 mm one sample resolves every pattern
  if (footprint_m < kSharp) return evaluate(scene, hit);
  Sample sum = evaluate(scene, hit);
  Hit offset = hit;
  for (int ring = 1; ring <= 2; ++ring) {
    const double radius = footprint_m * ring / 2.0;
    for (int k = 0; k < 6; ++k) {
      const double angle = std::numbers::pi / 3.0 * (k + 0.5 * ring);
      offset.uv_m = hit.uv_m + radius * Vector2d(std::cos(angle), std::sin(angle));
      const Sample s = evaluate(scene, offset);
      sum.albedo += s.albedo;
      sum.reflectance += s.reflectance;
    }
  }
  return {sum.albedo / 13.0f, sum.reflectance / 13.0f};
}

}  // namespace

SurfaceAppearance surface_appearance(const Scene& scene, const Hit& hit, double footprint_m) {
  const Sample s = filtered(scene, hit, footprint_m);
  return {s.albedo.cwiseMax(0.0f).cwiseMin(1.0f), std::clamp(s.reflectance, 0.0f, 1.0f)};
}

Eigen::Vector3f surface_albedo(const Scene& scene, const Hit& hit, double footprint_m) {
  return surface_appearance(scene, hit, footprint_m).albedo;
}

float surface_reflectance(const Scene& scene, const Hit& hit, double footprint_m) {
  return surface_appearance(scene, hit, footprint_m).reflectance;
}

}  // namespace scanbench::acquisition::sim
