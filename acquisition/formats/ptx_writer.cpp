#include "acquisition/formats/ptx_writer.hpp"

#include <cassert>

#include "acquisition/formats/number_format.hpp"

namespace scanbench::acquisition {
namespace {

void append_vector(std::string& out, std::initializer_list<double> values) {
  bool first = true;
  for (const double v : values) {
    if (!first) out += ' ';
    append_number(out, v);
    first = false;
  }
  out += '\n';
}

void write_header(std::string& out, const Scan& scan) {
  out += std::to_string(scan.columns) + '\n' + std::to_string(scan.rows) + '\n';
  const Eigen::Vector3d& p = scan.scanner.position_world;
  append_vector(out, {p.x(), p.y(), p.z()});
  const Eigen::Matrix3d r = scan.T_world_scan.linear();
  for (int axis = 0; axis < 3; ++axis) append_vector(out, {r(0, axis), r(1, axis), r(2, axis)});
  const Eigen::Matrix4d m = scan.T_world_scan.matrix();
  for (int column = 0; column < 4; ++column) {
    append_vector(out, {m(0, column), m(1, column), m(2, column), m(3, column)});
  }
}

void append_point(std::string& out, const Scan& scan, int row, int col) {
  const std::size_t i = scan.index(row, col);
  if (scan.valid[i]) {
    const Eigen::Vector3d p =
        static_cast<double>(scan.range_m[i]) * direction_precise(scan, row, col);
    append_number(out, p.x());
    out += ' ';
    append_number(out, p.y());
    out += ' ';
    append_number(out, p.z());
  } else {
    out += "0 0 0";
  }
  out += ' ';
  append_number(out, scan.has_intensity() ? scan.intensity[i] : 0.0f);
  if (scan.has_color()) {
    for (int c = 0; c < 3; ++c) {
      out += ' ';
      out += std::to_string(scan.rgb[3 * i + c]);
    }
  }
  out += '\n';
}

}  // namespace

void PtxWriter::add(const Scan& scan) {
  assert(check_consistency(scan).empty() && "write_ptx needs a consistent scan");
  write_header(file_.buffer(), scan);
  for (int col = 0; col < scan.columns; ++col) {
    for (int row = 0; row < scan.rows; ++row) {
      append_point(file_.buffer(), scan, row, col);
      file_.flush_if_full();
    }
  }
}

void write_ptx(const std::filesystem::path& path, std::span<const Scan> scans) {
  PtxWriter writer(path);
  for (const Scan& scan : scans) writer.add(scan);
  writer.commit();
}

}  // namespace scanbench::acquisition
