// The scans a streamed stage holds at once. A stage plans the order in which
// it will use the project's scans, then takes them one `get` at a time; the
// cache loads each scan with its geometry and prepared view when it is
// needed, drops it as soon as the plan no longer needs it, and, when the
// scans in hand would exceed the memory limit, gives up the one whose next
// use is farthest away (Belady's rule, optimal for a known order). Peak
// memory is then set by how many scans the stage needs together, not by how
// many the project holds. Internal to modeling/.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "acquisition/geometry/scan_geometry.hpp"
#include "acquisition/scan.hpp"
#include "core/progress.hpp"
#include "core/spill_file.hpp"
#include "modeling/store/project.hpp"
#include "registration/prepared_scan.hpp"
#include "registration/scan_stream.hpp"

namespace scanbench::modeling {

// One scan as a stage works on it. Neither copied nor moved: `prepared`
// points into `scan` and `geometry`. Given out as a shared_ptr: the cache
// must know which scans the stage still holds.
struct LoadedScan {
  std::int64_t id = 0;
  acquisition::Scan scan;
  acquisition::ScanGeometry geometry;
  registration::PreparedScan prepared;
  std::size_t bytes = 0;  // the heap memory of all three

  LoadedScan() = default;
  LoadedScan(const LoadedScan&) = delete;
  LoadedScan& operator=(const LoadedScan&) = delete;
};

// What of a scan a stage reads.
enum class ScanForm {
  kWhole,
  // What registration reads: the whole scan but its intensity and colour,
  // which are not read from the project.
  kGeometric,
  // What the merge compares (registration/merge.hpp): ranges, footprints,
  // normals and the prepared in_model, usable and sample areas, about 26
  // bytes a pixel instead of about 51. The scan's valid, intensity and
  // colour, the geometry's confidence and flags are dropped, and so are
  // the prepared points of a spherical grid (the merge recomputes them
  // from the ranges, registration/merge.hpp); intensity, colour and those
  // points are not even read or computed.
  kMerge,
};

// How a stage's cache holds its scans, within the memory limit.
struct ScanCacheSettings {
  ScanForm form = ScanForm::kWhole;
  // Park a scan's arrays in a temporary file (core::SpillFile) when it is
  // let go before the plan is done with it, and read them back from there
  // when the plan brings it back, rather than load it from the project
  // again: a read instead of decompressing and preparing. Where the file
  // cannot take them, from the project. The file gives a scan's space
  // back once the plan is done with it, so it holds only the scans whose
  // uses are not over (down a street, a band of neighbours, not the
  // campaign).
  bool spill = false;
  // Scans kept for a later use of the plan, beyond those the stage holds,
  // at most (Belady's rule picks them). With a spill, a few suffice: peak
  // memory is then that of the scans a stage needs together and these,
  // however many scans come back.
  std::size_t max_kept = std::numeric_limits<std::size_t>::max();
};

// The memory a stage may fill with loaded scans [bytes]: `requested` when
// given, else three quarters of what the process can still be given
// (core::available_memory_bytes), else 4 GB when that cannot be told.
std::uint64_t memory_limit_or_default(std::optional<std::uint64_t> requested);

// The project's scans (project.scans()), after checking that there is one
// and that each has its geometry, so that a stage refuses before it works
// rather than at the scan that lacks it. Throws core::InputError ("run
// scanbench geometry first").
std::vector<store::StoredScanSummary> scans_with_geometry(const store::Project& project);

class ScanCache {
 public:
  // Scans of `project` (which must outlive the cache) prepared on `threads`
  // workers; each get checks `progress` for cancellation of `stage`.
  ScanCache(const store::Project& project, std::uint64_t memory_limit_bytes, int threads,
            std::string stage, core::Progress& progress, ScanCacheSettings settings = {});

  // The scan ids in the order the following get() calls will ask for them
  // (an id may repeat). Replaces the previous plan: scans in hand that it
  // does not name are let go.
  void plan(std::vector<std::int64_t> order);

  // The next scan of the plan, which must be `id` (asserted), loaded if it
  // is not in hand. The caller holds it as long as it uses it; the cache
  // never drops a scan that is held. Throws core::MemoryShortage, before
  // loading, when the scans held plus this one would exceed the limit (the
  // stage needs more at once than it may have), core::InputError when the
  // scan has no geometry ("run scanbench geometry first") or is damaged,
  // core::Cancelled when cancelled.
  std::shared_ptr<const LoadedScan> get(std::int64_t id);

  // Scans loaded from the project, and read back from the spill.
  std::size_t loads() const { return loads_; }
  std::size_t spill_reads() const { return spill_reads_; }
  // The most memory the scans in hand (held or kept) took at once [bytes].
  std::uint64_t peak_bytes() const { return peak_bytes_; }

 private:
  struct Entry {
    std::shared_ptr<const LoadedScan> scan;
    std::size_t next_use = 0;  // position in the plan; kNever when none
  };
  // A scan in the spill: what its arrays leave of it, and where each array
  // went (in the order of visit_arrays in scan_cache.cpp).
  struct Parked {
    acquisition::Scan scan;
    acquisition::RangeNoise range_noise;
    std::vector<core::SpillFile::Extent> arrays;
  };

  std::uint64_t bytes_in_hand() const;
  void refuse_beyond_limit(std::uint64_t bytes, std::int64_t id) const;
  std::pair<std::map<std::int64_t, Entry>::iterator, std::size_t> farthest_unheld();
  void make_room(std::uint64_t bytes);
  void keep_at_most(std::size_t count);
  std::shared_ptr<const LoadedScan> load(std::int64_t id);
  std::shared_ptr<LoadedScan> load_from_project(std::int64_t id) const;
  std::shared_ptr<LoadedScan> read_back(const Parked& parked, std::int64_t id) const;
  void park(const LoadedScan& loaded);
  void unpark(std::int64_t id);
  void drop(std::map<std::int64_t, Entry>::iterator kept);

  const store::Project& project_;
  std::vector<std::int64_t> plan_;
  std::vector<std::size_t> next_use_;  // per plan position: the next one with the same id
  std::size_t position_ = 0;
  std::uint64_t limit_;
  int threads_;
  std::string stage_;
  core::Progress& progress_;
  ScanCacheSettings settings_;
  std::unique_ptr<core::SpillFile> spill_;  // with settings_.spill only
  std::map<std::int64_t, Parked> parked_;
  std::map<std::int64_t, Entry> kept_;
  // Scans given out, kept or not: memory is theirs until the last holder
  // lets go.
  std::vector<std::weak_ptr<const LoadedScan>> given_;
  std::map<std::int64_t, std::size_t> pixels_;  // per scan, from the summaries
  double bytes_per_pixel_ = 0.0;                // the most seen so far
  std::size_t loads_ = 0;
  std::size_t spill_reads_ = 0;
  std::uint64_t peak_bytes_ = 0;
};

// The project's scans as a registration::ScanStream: position k is the
// scan ids[k], loaded through a ScanCache in ScanForm::kGeometric.
class CachedScans final : public registration::ScanStream {
 public:
  CachedScans(const store::Project& project, std::vector<std::int64_t> ids,
              std::uint64_t memory_limit_bytes, int threads, std::string stage,
              core::Progress& progress)
      : ids_(std::move(ids)),
        cache_(project, memory_limit_bytes, threads, std::move(stage), progress,
               {.form = ScanForm::kGeometric}) {}

  std::size_t size() const override { return ids_.size(); }
  void plan(std::vector<int> order) override;
  std::shared_ptr<const registration::PreparedScan> get(int k) override;
  const ScanCache& cache() const { return cache_; }

 private:
  std::vector<std::int64_t> ids_;
  ScanCache cache_;
};

}  // namespace scanbench::modeling
