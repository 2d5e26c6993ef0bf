// LodRenderer's selections in the 3D view (lod_renderer.hpp, lasso.hpp):
// the lasso, which sees which points are in front through a depth raster
// of their splats, and the brush.
#include <algorithm>
#include <cmath>
#include <tuple>
#include <vector>

#include "modeling/lod/lod_store.hpp"
#include "render/lasso.hpp"
#include "render/lod_renderer.hpp"

namespace scanbench::render {

namespace {

// A point a selection takes, until the selection is gathered.
struct Taken {
  std::int64_t scan = 0;
  std::uint32_t pixel = 0;
  Eigen::Vector3f position;
};

LodSelection gather(std::vector<Taken>& taken, std::size_t sample) {
  LodSelection out;
  out.points = taken.size();
  if (sample > 0) {
    const std::size_t step = std::max<std::size_t>(1, (taken.size() + sample - 1) / sample);
    for (std::size_t i = 0; i < taken.size(); i += step) out.sample.push_back(taken[i].position);
  }
  std::sort(taken.begin(), taken.end(), [](const Taken& a, const Taken& b) {
    return std::tie(a.scan, a.pixel) < std::tie(b.scan, b.pixel);
  });
  for (const Taken& t : taken) {
    std::vector<std::uint32_t>& pixels = out.pixels[t.scan];
    if (pixels.empty() || pixels.back() != t.pixel) pixels.push_back(t.pixel);
  }
  return out;
}

// The widest splat a lasso's visibility test draws [pixels]: a nearer
// surface's splats reach this far into the lasso from outside it.
constexpr float kMaxOccluderRadiusPx = 16.0f;

}  // namespace

LodSelection LodRenderer::select(const RenderView& view, const Lasso& lasso,
                                 const RenderSettings& settings, const LodSelectOptions& options) {
  const Clipping& clipping = settings.culling.clipping;
  std::vector<Taken> taken;
  if (lasso.empty() || hierarchy_.nodes.empty() || hierarchy_.nodes.front().key.depth != 0)
    return {};
  // Seeing which points are in front needs the splats that may cover the
  // lasso: those centred up to the widest splat beyond its bounds.
  const bool through = std::isinf(options.depth_m);
  const float margin = through ? 0.0f : kMaxOccluderRadiusPx;
  const Eigen::AlignedBox2f reach_box(lasso.bounds().min().array() - margin,
                                      lasso.bounds().max().array() + margin);
  const Eigen::AlignedBox2f picture(
      Eigen::Vector2f::Zero(),
      Eigen::Vector2f(static_cast<float>(view.width), static_cast<float>(view.height)));
  const Eigen::AlignedBox2f raster_box = reach_box.intersection(picture);
  DepthRaster raster(static_cast<int>(std::floor(raster_box.min().x())),
                     static_cast<int>(std::floor(raster_box.min().y())),
                     static_cast<int>(std::ceil(raster_box.max().x())),
                     static_cast<int>(std::ceil(raster_box.max().y())));
  struct Candidate {
    Taken point;
    Eigen::Vector2f at;
    float depth = 0.0f;
    float tolerance = 0.0f;
  };
  std::vector<Candidate> candidates;
  const float scale = settings.splat_scale;
  const bool cull_back = !through && settings.culling.backface;
  std::vector<std::size_t> stack = {0};
  while (!stack.empty()) {
    const std::size_t k = stack.back();
    stack.pop_back();
    const Eigen::AlignedBox3f& reach = hierarchy_.reach[k];
    if (reach.isEmpty() || clipping.excludes(reach)) continue;
    // A box reaching behind the eye may cover any of the picture.
    if (const auto on_picture = project_box(view, reach);
        on_picture && !on_picture->intersects(reach_box))
      continue;
    for (const std::int32_t child : hierarchy_.children[k]) {
      if (child >= 0) stack.push_back(static_cast<std::size_t>(child));
    }
    for_each_shown_point(
        k, clipping,
        [&](const lod::LodPoint& q, std::int64_t object, const Eigen::Vector3f& position) {
          const std::optional<Eigen::Vector2f> at = project_to_picture(view, position);
          if (!at || !reach_box.contains(*at)) return;
          const bool enclosed = lasso.encloses(*at) && (!options.open_only || object == 0);
          if (through) {
            if (enclosed) taken.push_back({scan_ids_.at(q.scan), q.pixel, position});
            return;
          }
          // A point the view does not draw hides nothing; it is taken only
          // from behind the nearest surface.
          const bool drawn = !cull_back || !(q.flags & lod::LodPoint::kHasNormal) ||
                             lod::decode_unit(q.normal).dot(view.eye - position) >= 0.0f;
          const float depth = view_depth(view, position);
          const float radius_m = scale * lod::from_half(q.radii[0]);
          if (drawn)
            raster.splat(*at, depth,
                         std::min(kMaxOccluderRadiusPx, radius_m * view.focal_px / depth));
          if (enclosed && (drawn || options.depth_m > 0.0f))
            candidates.push_back({{scan_ids_.at(q.scan), q.pixel, position},
                                  *at,
                                  depth,
                                  2.0f * radius_m + 0.005f * depth + options.depth_m});
        });
  }
  for (const Candidate& c : candidates) {
    if (raster.in_front(c.at, c.depth, c.tolerance)) taken.push_back(c.point);
  }
  return gather(taken, options.sample);
}

LodSelection LodRenderer::select_sphere(const Eigen::Vector3f& centre, float radius_m,
                                        const RenderSettings& settings,
                                        const LodSelectOptions& options) {
  const Clipping& clipping = settings.culling.clipping;
  std::vector<Taken> taken;
  if (radius_m <= 0.0f || hierarchy_.nodes.empty() || hierarchy_.nodes.front().key.depth != 0)
    return {};
  const Eigen::AlignedBox3f ball(centre.array() - radius_m, centre.array() + radius_m);
  const float r2 = radius_m * radius_m;
  std::vector<std::size_t> stack = {0};
  while (!stack.empty()) {
    const std::size_t k = stack.back();
    stack.pop_back();
    const Eigen::AlignedBox3f& reach = hierarchy_.reach[k];
    if (reach.isEmpty() || clipping.excludes(reach) || !reach.intersects(ball)) continue;
    for (const std::int32_t child : hierarchy_.children[k]) {
      if (child >= 0) stack.push_back(static_cast<std::size_t>(child));
    }
    for_each_shown_point(
        k, clipping,
        [&](const lod::LodPoint& q, std::int64_t object, const Eigen::Vector3f& position) {
          if ((position - centre).squaredNorm() > r2 || (options.open_only && object != 0)) return;
          taken.push_back({scan_ids_.at(q.scan), q.pixel, position});
        });
  }
  return gather(taken, options.sample);
}

}  // namespace scanbench::render
