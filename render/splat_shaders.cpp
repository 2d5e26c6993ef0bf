#include "render/splat_shaders.hpp"

#include "render/object_palette.hpp"

namespace scanbench::render::shaders {

// The vertex stage is a reader of the points (their attributes and
// load_point(), which fills the p_ variables), then the common part: per
// point its centre, normal, major axis and radii in eye space for the
// fragment stage, its colour by the colour mode, and a sprite wide enough
// for the ellipse (the screen extent of the sphere of its major radius). A
// point whose normal faces away from the eye is moved outside the clip
// volume (backface culling per point), as is a hidden or clipped one.
const char* const kSplatVertexCommon = R"glsl(
uniform mat4 u_view;
uniform mat4 u_projection;
uniform vec3 u_eye;
uniform float u_focal;
uniform float u_scale;
uniform int u_points;
uniform int u_backface;
uniform int u_color_mode;
uniform int u_lighting;
uniform vec2 u_height_range;
uniform int u_clip_box;
uniform vec3 u_clip_min;
uniform vec3 u_clip_max;
uniform vec4 u_section;  // normal, offset
uniform float u_section_half_width;  // 0: no slice

out vec3 v_color;
flat out vec3 v_center;
flat out vec3 v_normal;
flat out vec3 v_major;
flat out vec2 v_radii;

// What load_point() gives of the point.
vec3 p_position;    // model frame [m]
vec3 p_normal;      // unit, or zero: unknown
vec3 p_major;       // unit, or zero: round
vec2 p_radii;       // [m] across, along the major axis
vec3 p_color;       // shown colour, linear 0…1 of sRGB values
float p_intensity;  // 0…1
uint p_node;        // owning object, 0: none
float p_min_radius; // the least radius that keeps its surface closed [m]
bool p_hidden;

vec3 ramp(float t) {  // blue, cyan, green, yellow, red
  t = clamp(t, 0.0, 1.0);
  return clamp(vec3(1.5 - abs(4.0 * t - 3.0), 1.5 - abs(4.0 * t - 2.0), 1.5 - abs(4.0 * t - 1.0)),
               0.0, 1.0);
}

)glsl";

// A level-of-detail node's points as the store keeps them (lod_point.hpp),
// 40 bytes each: the position from the node's corner in 0.1 mm quanta, the
// octahedral normal and axis, half-float radii, the recorded colour shown
// through its scan's correction and its object's edit (modeling/
// color_pipeline.hpp, here per point on the device, so that an edit is a
// table update), and the object's visibility from the same table.
const char* const kLodPointReader = R"glsl(#version 450 core
layout(location = 0) in uvec3 a_offset;
layout(location = 1) in uint a_object;
layout(location = 2) in uint a_scan;
layout(location = 3) in uint a_flags;
layout(location = 4) in float a_intensity;
layout(location = 5) in ivec2 a_normal;
layout(location = 6) in ivec2 a_major;
layout(location = 7) in vec2 a_radii;
layout(location = 8) in vec4 a_rgb;

uniform vec3 u_node_corner;  // [m from the origin]
uniform uint u_half_edge;    // [quanta] half the node's edge
uniform uint u_missing;      // bit k (x 4, y 2, z 1): octant k's points are not all drawn
uniform float u_cell;        // [m] the cell of the deepest level drawn

// Four per object id (lod_renderer.cpp): (shown, edited, in the tree,
// brightness), (transfer scale, contrast), (transfer offset, gamma),
// (cos hue, sin hue, saturation, 0). Id 0, no object, first.
layout(std430, binding = 0) readonly buffer ObjectStates { vec4 objects[]; };
// Four per scan of the store: the correction's rows (matrix | offset) in
// linear RGB, then (corrected, 0, 0, 0).
layout(std430, binding = 1) readonly buffer ScanCorrections { vec4 scans[]; };

const float kQuantum = 1e-4;
const mat3 kRgbToXyz = mat3(0.4124564, 0.2126729, 0.0193339,  // columns
                            0.3575761, 0.7151522, 0.1191920,
                            0.1804375, 0.0721750, 0.9503041);
const vec3 kWhite = vec3(0.9504700, 1.0000001, 1.0888300);  // kRgbToXyz's row sums
const float kDelta = 6.0 / 29.0;

vec3 decode_unit(ivec2 code) {
  vec2 p = vec2(code) / 32767.0;
  vec3 v = vec3(p, 1.0 - abs(p.x) - abs(p.y));
  if (v.z < 0.0) {
    vec2 signs = vec2(p.x >= 0.0 ? 1.0 : -1.0, p.y >= 0.0 ? 1.0 : -1.0);
    v.xy = (1.0 - abs(p.yx)) * signs;
  }
  return normalize(v);
}

vec3 srgb_to_linear(vec3 c) {
  return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}

vec3 linear_to_srgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, greaterThan(c, vec3(0.0031308)));
}

float lab_f(float t) {
  return t > kDelta * kDelta * kDelta ? pow(t, 1.0 / 3.0) : t / (3.0 * kDelta * kDelta) + 4.0 / 29.0;
}

float lab_f_inverse(float f) {
  return f > kDelta ? f * f * f : 3.0 * kDelta * kDelta * (f - 4.0 / 29.0);
}

vec3 linear_to_lab(vec3 rgb) {
  vec3 xyz = (kRgbToXyz * rgb) / kWhite;
  float fx = lab_f(xyz.x), fy = lab_f(xyz.y), fz = lab_f(xyz.z);
  return vec3(116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz));
}

vec3 lab_to_linear(vec3 lab) {
  float fy = (lab.x + 16.0) / 116.0;
  vec3 f = vec3(fy + lab.y / 500.0, fy, fy - lab.z / 200.0);
  vec3 xyz = vec3(lab_f_inverse(f.x), lab_f_inverse(f.y), lab_f_inverse(f.z));
  return inverse(kRgbToXyz) * (xyz * kWhite);
}

// The object's edit (modeling::apply): transfer, gamma, contrast and
// brightness on L*, hue and saturation on a*b*.
vec3 apply_edit(uint id, vec3 lab) {
  vec4 s0 = objects[4u * id], s1 = objects[4u * id + 1u], s2 = objects[4u * id + 2u],
       s3 = objects[4u * id + 3u];
  lab = s1.xyz * lab + s2.xyz;
  float lightness = clamp(lab.x, 0.0, 100.0);
  if (s2.w != 1.0) lightness = 100.0 * pow(lightness / 100.0, 1.0 / s2.w);
  lightness = 50.0 + s1.w * (lightness - 50.0) + s0.w;
  float a = s3.z * (s3.x * lab.y - s3.y * lab.z);
  float b = s3.z * (s3.y * lab.y + s3.x * lab.z);
  return vec3(clamp(lightness, 0.0, 100.0), a, b);
}

vec3 shown_color(vec3 recorded, uint scan, uint id, bool edited) {
  bool corrected = scan < uint(scans.length()) / 4u && scans[4u * scan + 3u].x > 0.5;
  if (!corrected && !edited) return recorded;
  vec3 linear = srgb_to_linear(recorded);
  if (corrected) {
    vec4 r0 = scans[4u * scan], r1 = scans[4u * scan + 1u], r2 = scans[4u * scan + 2u];
    linear = max(vec3(dot(r0.xyz, linear) + r0.w, dot(r1.xyz, linear) + r1.w,
                      dot(r2.xyz, linear) + r2.w), vec3(0.0));
  }
  if (!edited) return linear_to_srgb(linear);
  return linear_to_srgb(lab_to_linear(apply_edit(id, linear_to_lab(linear))));
}

void load_point() {
  p_position = u_node_corner + vec3(a_offset) * kQuantum;
  p_normal = (a_flags & 1u) != 0u ? decode_unit(a_normal) : vec3(0.0);
  p_major = (a_flags & 2u) != 0u ? vec3(0.0) : decode_unit(a_major);
  p_radii = a_radii;
  p_intensity = a_intensity;
  // An id not in the tree owns nothing: no object's.
  uint id = a_object < uint(objects.length()) / 4u && objects[4u * a_object].z > 0.5 ? a_object
                                                                                      : 0u;
  vec4 state = objects[4u * id];
  p_hidden = state.x < 0.5;
  p_node = id;
  p_color = (a_flags & 4u) != 0u ? shown_color(a_rgb.rgb, a_scan, id, state.y > 0.5)
                                 : vec3(a_intensity);
  uvec3 upper = uvec3(greaterThanEqual(a_offset, uvec3(u_half_edge)));
  uint octant = upper.x * 4u + upper.y * 2u + upper.z;
  p_min_radius = ((u_missing >> octant) & 1u) != 0u ? u_cell : 0.0;
}
)glsl";

// After the palette (render/object_palette.hpp).
const char* const kSplatVertexBody = R"glsl(
void main() {
  load_point();
  bool has_normal = dot(p_normal, p_normal) > 0.25;
  bool clipped = u_clip_box == 1 && (any(lessThan(p_position, u_clip_min)) ||
                                     any(greaterThan(p_position, u_clip_max)));
  clipped = clipped || (u_section_half_width > 0.0 &&
                        abs(dot(u_section.xyz, p_position) - u_section.w) > u_section_half_width);
  if (p_hidden || clipped ||
      (u_backface == 1 && has_normal && dot(p_normal, u_eye - p_position) < 0.0)) {
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
    gl_PointSize = 1.0;
    return;
  }
  vec4 eye_position = u_view * vec4(p_position, 1.0);
  vec2 radii = max(p_radii * u_scale, vec2(p_min_radius));
  float depth = max(-eye_position.z, 1e-3);
  gl_Position = u_projection * eye_position;
  // A sphere of radius r at distance L spans r f L / depth² pixels either
  // side of its centre: 1 / cos θ more than on the axis.
  float reach = radii.y * u_focal * length(eye_position.xyz) / (depth * depth);
  gl_PointSize = u_points == 1 ? 1.0 : clamp(2.0 * reach + 2.0, 1.0, 255.0);
  v_center = eye_position.xyz;
  v_normal = has_normal ? normalize(mat3(u_view) * p_normal) : vec3(0.0);
  v_major = dot(p_major, p_major) > 0.25 ? normalize(mat3(u_view) * p_major) : vec3(0.0);
  v_radii = radii;
  vec3 color = p_color;
  if (u_color_mode == 1) color = vec3(p_intensity);
  if (u_color_mode == 2) color = ramp((p_position.z - u_height_range.x) /
                                      max(u_height_range.y - u_height_range.x, 1e-3));
  if (u_color_mode == 3) color = has_normal ? 0.5 + 0.5 * p_normal : vec3(0.5);
  if (u_color_mode == 4) color = object_color(p_node);
  if (u_lighting == 1 && has_normal) {
    color *= 0.35 + 0.65 * abs(dot(v_normal, normalize(-v_center)));
  }
  v_color = color;
}
)glsl";

std::string splat_vertex() {
  // The reader's #version line first; its load_point() after the p_
  // variables it fills.
  const std::string reader(kLodPointReader);
  const std::size_t first_line = reader.find('\n') + 1;
  return reader.substr(0, first_line) + kSplatVertexCommon + reader.substr(first_line) +
         object_color_glsl() + kSplatVertexBody;
}

// The fragment's view ray meets the splat's plane (its normal, or facing the
// eye) at q; outside the ellipse (radii along the major axis and across it;
// a disk of their geometric mean when facing the eye) it is discarded,
// inside it weighs by the kernel of its elliptical distance and takes q's
// depth (reversed Z).
const char* const kSplatFragment = R"glsl(#version 450 core
in vec3 v_color;
flat in vec3 v_center;
flat in vec3 v_normal;
flat in vec3 v_major;
flat in vec2 v_radii;

uniform mat4 u_projection;
uniform vec2 u_viewport;         // the banded view's size [pixels]
uniform vec2 u_viewport_origin;  // its corner in the target (the guard band, negative)
uniform int u_pass;
uniform int u_kernel;
uniform int u_oriented;
uniform float u_depth_offset;

layout(location = 0) out vec4 out_color;

float kernel_weight(float d2) {
  if (u_kernel == 1) return exp(-2.0 * d2);                   // Gaussian, σ = r / 2
  if (u_kernel == 2) return cos(1.5707963 * sqrt(d2)) + 1e-3;  // cosine
  return 1.0;                                                 // flat disk
}

void main() {
  if (u_pass == 3) {
    gl_FragDepth = gl_FragCoord.z;  // every path must write it, once one does
    out_color = vec4(v_color, 1.0);
    return;
  }
  vec2 ndc = (gl_FragCoord.xy - u_viewport_origin) / u_viewport * 2.0 - 1.0;
  vec3 ray = vec3(ndc.x / u_projection[0][0], ndc.y / u_projection[1][1], -1.0);
  vec3 facing = normalize(-v_center);
  bool oriented = u_oriented == 1 && dot(v_normal, v_normal) > 0.25;
  vec3 n = oriented ? v_normal : facing;
  float along = dot(ray, n);
  if (abs(along) < 0.05 * length(ray)) {  // seen edge on: face the eye instead
    oriented = false;
    n = facing;
    along = dot(ray, n);
  }
  vec3 q = ray * (dot(v_center, n) / along);
  vec3 offset = q - v_center;
  float d2;
  if (oriented && dot(v_major, v_major) > 0.25) {
    vec2 e = vec2(dot(offset, cross(n, v_major)), dot(offset, v_major)) / v_radii;
    d2 = dot(e, e);
  } else {
    d2 = dot(offset, offset) / (oriented ? v_radii.x * v_radii.x : v_radii.x * v_radii.y);
  }
  if (d2 > 1.0) discard;
  float z = q.z;
  if (u_pass == 0) z -= u_depth_offset * v_radii.y;
  gl_FragDepth = (u_projection[2][2] * z + u_projection[3][2]) / -z;
  float w = kernel_weight(d2);
  out_color = u_pass == 1 ? vec4(v_color * w, w) : vec4(v_color, 1.0);
}
)glsl";

// A triangle covering the screen.
const char* const kResolveVertex = R"glsl(#version 450 core
void main() {
  vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
)glsl";

// Weighted colour divided by weight; the background where nothing landed;
// with eye-dome lighting, each pixel darkened by how far its neighbours
// stand in front of it (log of eye distance).
//
// Hole filling (u_fill_reach > 0): a pixel nothing landed on looks along the
// 8 compass directions for the first covered pixel within the reach. Only
// when all 8 find one is it a hole in a surface (a pixel at a silhouette
// sees background on one side at least); it then takes the mean of the
// finds on the nearest surface (eye distance within 5 % of the nearest),
// each weighed by 1 / its distance, so a gap in a wall never takes the
// colour of what stands behind it.
const char* const kResolveFragment = R"glsl(#version 450 core
uniform sampler2D u_accumulated;
uniform sampler2D u_depth;
uniform vec3 u_background;
uniform int u_eye_dome;
uniform int u_fill_reach;
uniform vec2 u_depth_ab;  // eye distance = b / (depth + a)

layout(location = 0) out vec4 out_color;

float eye_distance(ivec2 p) {
  float d = texelFetch(u_depth, p, 0).r;
  return u_depth_ab.y / (d + u_depth_ab.x);
}

float log_distance(ivec2 p) {
  return log2(eye_distance(p));
}

const ivec2 kCompass[8] = ivec2[8](ivec2(1, 0), ivec2(1, 1), ivec2(0, 1), ivec2(-1, 1),
                                   ivec2(-1, 0), ivec2(-1, -1), ivec2(0, -1), ivec2(1, -1));

// The colour a hole at p takes, or alpha 0 when p is not a hole.
vec4 fill_hole(ivec2 p) {
  ivec2 size = textureSize(u_accumulated, 0);
  vec3 colors[8];
  float distances[8];
  float steps[8];
  float nearest = 1e30;
  for (int k = 0; k < 8; ++k) {
    steps[k] = 0.0;
    for (int s = 1; s <= u_fill_reach; ++s) {
      ivec2 q = p + s * kCompass[k];
      if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) break;
      vec4 found = texelFetch(u_accumulated, q, 0);
      if (found.a > 0.0) {
        colors[k] = found.rgb / found.a;
        distances[k] = eye_distance(q);
        steps[k] = float(s) * length(vec2(kCompass[k]));
        nearest = min(nearest, distances[k]);
        break;
      }
    }
    if (steps[k] == 0.0) return vec4(0.0);
  }
  vec4 sum = vec4(0.0);
  for (int k = 0; k < 8; ++k) {
    if (distances[k] <= 1.05 * nearest) sum += vec4(colors[k], 1.0) / steps[k];
  }
  return vec4(sum.rgb / sum.a, 1.0);
}

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec4 sum = texelFetch(u_accumulated, p, 0);
  if (sum.a <= 0.0) {
    vec4 filled = u_fill_reach > 0 ? fill_hole(p) : vec4(0.0);
    out_color = filled.a > 0.0 ? filled : vec4(u_background, 0.0);
    return;
  }
  vec3 color = sum.rgb / sum.a;
  if (u_eye_dome == 1) {
    ivec2 size = textureSize(u_depth, 0);
    float here = log_distance(p);
    float response = 0.0;
    for (int k = 0; k < 8; ++k) {
      float angle = 0.7853982 * float(k);
      ivec2 q = clamp(p + ivec2(round(2.0 * vec2(cos(angle), sin(angle)))), ivec2(0), size - 1);
      response += max(0.0, here - log_distance(q));
    }
    color *= exp(-1.5 * response);
  }
  out_color = vec4(color, 1.0);
}
)glsl";

}  // namespace scanbench::render::shaders
