// Labels carried between registered scans of the simulated campus: the
// truth's object ids of one scan, transferred to another, name the objects
// that scan's truth names.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "registration/label_transfer.hpp"
#include "registration/simulated_campus.hpp"

namespace scanbench::registration {
namespace {

// Scan `from`'s truth ids on its model pixels (0 elsewhere).
std::vector<std::uint32_t> truth_labels(const test::SimulatedCampus& site, int from) {
  const auto k = static_cast<std::size_t>(from);
  std::vector<std::uint32_t> labels(site.prepared[k].in_model.size(), 0);
  for (std::size_t i = 0; i < labels.size(); ++i) {
    if (site.prepared[k].in_model[i]) labels[i] = site.truth[k].object_id[i];
  }
  return labels;
}

struct Agreement {
  std::size_t labelled = 0;  // target pixels given a label
  std::size_t right = 0;     // ... the target's truth id
  std::size_t beside = 0;    // ... another, but one a neighbouring pixel has
  std::size_t in_model = 0;  // target model pixels
};

// True when a pixel next to q (8-neighbourhood) has truth id `id`.
bool next_to(const acquisition::Scan& scan, const std::vector<acquisition::sim::ObjectId>& ids,
             std::size_t q, std::uint32_t id) {
  const int row = static_cast<int>(q / static_cast<std::size_t>(scan.columns));
  const int col = static_cast<int>(q % static_cast<std::size_t>(scan.columns));
  for (int dr = -1; dr <= 1; ++dr) {
    for (int dc = -1; dc <= 1; ++dc) {
      const int r = row + dr, c = (col + dc + scan.columns) % scan.columns;
      if (r >= 0 && r < scan.rows && ids[scan.index(r, c)] == id) return true;
    }
  }
  return false;
}

Agreement transfer_truth(int from, int to, const LabelTransferSettings& settings = {}) {
  const test::SimulatedCampus& site = test::campus(3);
  const std::vector<std::uint32_t> out = transfer_labels(
      site.prepared[static_cast<std::size_t>(from)], truth_labels(site, from),
      site.prepared[static_cast<std::size_t>(to)], site.true_relative(from, to), settings);
  Agreement a;
  const auto& target = site.prepared[static_cast<std::size_t>(to)];
  for (std::size_t q = 0; q < out.size(); ++q) {
    a.in_model += target.in_model[q];
    if (out[q] == 0) continue;
    ++a.labelled;
    const auto& ids = site.truth[static_cast<std::size_t>(to)].object_id;
    if (out[q] == ids[q]) {
      ++a.right;
    } else {
      a.beside += next_to(site.scans[static_cast<std::size_t>(to)], ids, q, out[q]);
    }
  }
  return a;
}

TEST(TransferLabels, TheTruthOfOneScanNamesTheObjectsAnotherScanSaw) {
  for (const auto& [from, to] : {std::pair{0, 1}, std::pair{1, 0}, std::pair{0, 2}}) {
    const Agreement a = transfer_truth(from, to);
    // The scans share much of the campus, and a label lands on its own
    // object (98.0 to 99.1 % measured) or a pixel away from it (99.2 to
    // 99.8 % with GCC; 98.95 % in the clang sanitizer build, whose simulated
    // scans differ from GCC's in a few pixels in a thousand): an object's
    // edge is where the truth's beam centres fall, and the same-surface test
    // allows a footprint.
    EXPECT_GT(a.labelled, a.in_model / 5) << from << " → " << to;
    EXPECT_GT(static_cast<double>(a.right) / static_cast<double>(a.labelled), 0.97)
        << from << " → " << to << ": " << a.right << " of " << a.labelled;
    EXPECT_GT(static_cast<double>(a.right + a.beside) / static_cast<double>(a.labelled), 0.985)
        << from << " → " << to << ": " << a.labelled - a.right - a.beside << " astray";
  }
}

TEST(TransferLabels, NoLabelNoTransferAndTheThreadCountChangesNothing) {
  const test::SimulatedCampus& site = test::campus(3);
  const std::vector<std::uint32_t> none(site.prepared[0].in_model.size(), 0);
  const std::vector<std::uint32_t> out =
      transfer_labels(site.prepared[0], none, site.prepared[1], site.true_relative(0, 1), {});
  EXPECT_EQ(std::count(out.begin(), out.end(), 0u), static_cast<std::ptrdiff_t>(out.size()));
  LabelTransferSettings one;
  one.threads = 1;
  LabelTransferSettings two;
  two.threads = 2;
  const std::vector<std::uint32_t> labels = truth_labels(site, 0);
  EXPECT_EQ(
      transfer_labels(site.prepared[0], labels, site.prepared[1], site.true_relative(0, 1), one),
      transfer_labels(site.prepared[0], labels, site.prepared[1], site.true_relative(0, 1), two));
}

}  // namespace
}  // namespace scanbench::registration
