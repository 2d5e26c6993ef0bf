// A scan's colour correction in linear RGB (color_harmonization.hpp solves
// it; the project stores it and the model shows colours through it):
// rgb' = matrix · rgb + offset.
#pragma once

#include <Eigen/Core>

namespace scanbench::registration {

struct ColorCorrection {
  Eigen::Matrix3d matrix = Eigen::Matrix3d::Identity();
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  Eigen::Vector3d apply(const Eigen::Vector3d& rgb) const { return matrix * rgb + offset; }
  bool identity() const {
    return matrix == Eigen::Matrix3d::Identity() && offset == Eigen::Vector3d::Zero();
  }
  bool operator==(const ColorCorrection&) const = default;
};

}  // namespace scanbench::registration
