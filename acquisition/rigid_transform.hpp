// Reading and validating rigid transforms that come from files (PTX headers,
// triplet sidecars, PCD viewpoints).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <string>

namespace scanbench::acquisition {

// Tolerance on ‖RᵀR − I‖ (max abs entry) and |det R − 1| for a matrix to count
// as a rotation. Text files carry 6–8 significant digits, so 1e-4 accepts every
// honest file and refuses scaled or sheared ones.
inline constexpr double kRigidTolerance = 1e-4;

// Empty string when `m` is a finite rigid transform (rotation block within
// kRigidTolerance of orthonormal with det +1, last row 0 0 0 1); otherwise a
// description of what is wrong, for an InputError message.
std::string rigid_transform_problem(const Eigen::Matrix4d& m);

// Builds the isometry from a matrix that passed rigid_transform_problem. The
// rotation is re-orthonormalised so that composing many poses does not drift.
Eigen::Isometry3d to_isometry(const Eigen::Matrix4d& m);

// Row-major 16 numbers <-> matrix, the layout of "T_world_scan" in JSON.
Eigen::Matrix4d matrix_from_row_major(const std::array<double, 16>& values);
std::array<double, 16> row_major(const Eigen::Isometry3d& pose);

}  // namespace scanbench::acquisition
