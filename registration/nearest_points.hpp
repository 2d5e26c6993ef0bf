// Exact nearest-neighbour search over a set of fixed-length vectors: 3-D
// points, 33-D feature histograms. A thin view for nanoflann's k-d tree,
// which reads the vectors where they are.
#pragma once

#include <array>
#include <cstddef>
#include <nanoflann.hpp>
#include <type_traits>
#include <vector>

namespace scanbench::registration {

// nanoflann's view of `rows`: row i's component d is rows[i][d].
template <typename Row>
struct RowsView {
  const std::vector<Row>& rows;
  std::size_t kdtree_get_point_count() const { return rows.size(); }
  float kdtree_get_pt(std::size_t i, std::size_t d) const { return rows[i][d]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;  // nanoflann computes it
  }
};

// A k-d tree over rows of Dim floats, squared Euclidean distances. The
// rows must outlive the tree and stay unchanged.
template <typename Row, int Dim>
class NearestRows {
 public:
  explicit NearestRows(const std::vector<Row>& rows)
      : view_{rows}, tree_(Dim, view_, nanoflann::KDTreeSingleIndexAdaptorParams(16)) {}
  NearestRows(std::vector<Row>&&) = delete;  // the tree reads the rows where they are
  NearestRows(const NearestRows&) = delete;
  NearestRows& operator=(const NearestRows&) = delete;

  // The k nearest rows to `query` (Dim floats), nearest first, into
  // `indices` and `squared_distances` (resized to the count found, which is
  // less than k only when the tree holds fewer rows). Thread-safe.
  void nearest(const float* query, std::size_t k, std::vector<std::size_t>& indices,
               std::vector<float>& squared_distances) const {
    indices.resize(k);
    squared_distances.resize(k);
    const std::size_t found = tree_.knnSearch(query, k, indices.data(), squared_distances.data());
    indices.resize(found);
    squared_distances.resize(found);
  }

  // Every row within `radius` of `query` as (index, squared distance), in
  // no particular order. Thread-safe.
  void within(const float* query, float radius,
              std::vector<std::pair<std::size_t, float>>& found) const {
    found.clear();
    tree_.radiusSearch(query, radius * radius, found, nanoflann::SearchParams(32, 0.0f, false));
  }

 private:
  // Past a few dimensions, the metric that stops summing once a distance
  // exceeds the worst kept one.
  using Metric = std::conditional_t<(Dim > 4), nanoflann::L2_Adaptor<float, RowsView<Row>>,
                                    nanoflann::L2_Simple_Adaptor<float, RowsView<Row>>>;
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<Metric, RowsView<Row>, Dim, std::size_t>;
  RowsView<Row> view_;
  Tree tree_;
};

}  // namespace scanbench::registration
