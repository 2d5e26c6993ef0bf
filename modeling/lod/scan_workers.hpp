// Work on a project's scans shared out to workers, as the level-of-detail
// build and update read them: each worker takes the next item as soon as it
// is free, and reads through a project connection of its own.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <numeric>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "core/errors.hpp"
#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "modeling/store/project.hpp"

namespace scanbench::lod {

// Calls body(k) for k in [0, count) on `workers` workers (core::worker_count),
// each taking the next k as soon as it is free: one long item does not hold
// the others back, as batches would. A cancel throws before an item
// starts. Progress reports `stage` (an item's `label`) after the items the
// calling thread runs, and at the end: on the calling thread, as Progress
// wants.
template <typename Body>
void for_each_item(std::size_t count, int workers, core::Progress& progress, std::string_view stage,
                   const std::function<std::string(std::size_t)>& label, Body&& body) {
  const std::thread::id caller = std::this_thread::get_id();
  std::atomic<std::size_t> finished{0};
  tbb::task_arena arena = core::worker_arena(workers);
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, count, 1),
        [&](const tbb::blocked_range<std::size_t>& range) {
          for (std::size_t k = range.begin(); k < range.end(); ++k) {
            progress.throw_if_cancelled("lod");
            body(k);
            const std::size_t n = finished.fetch_add(1) + 1;
            if (std::this_thread::get_id() == caller) progress.update({stage, n, count, label(k)});
          }
        },
        tbb::simple_partitioner());
  });
  if (count > 0) progress.update({stage, count, count, label(count - 1)});
}

// Calls body(k, connection) for each scan k of `which` (indices in
// `scans`) on the workers (for_each_item). A project's connection serves
// one thread: each scan is read through a connection of its own, at the
// revision `project` read. Throws core::RuntimeFailure when the project
// changed since.
template <typename Body>
void for_each_scan(const store::Project& project, std::int64_t revision,
                   const std::vector<store::StoredScanSummary>& scans,
                   const std::vector<std::size_t>& which, int workers, core::Progress& progress,
                   std::string_view stage, Body&& body) {
  for_each_item(
      which.size(), workers, progress, stage,
      [&](std::size_t k) { return scans[which[k]].summary.name; },
      [&](std::size_t k) {
        const store::Project own = store::Project::open_read_only(project.path());
        const store::Project::ReadSnapshot snapshot = own.read_snapshot();
        if (own.revision() != revision) {
          core::FilePosition position;
          position.detail = "reading the project for the level-of-detail store";
          throw core::RuntimeFailure(project.path().string(), position,
                                     "the project changed meanwhile: run `scanbench lod` again");
        }
        body(which[k], own);
      });
}

// Every index of `scans`.
inline std::vector<std::size_t> every_scan(const std::vector<store::StoredScanSummary>& scans) {
  std::vector<std::size_t> all(scans.size());
  std::iota(all.begin(), all.end(), std::size_t{0});
  return all;
}

}  // namespace scanbench::lod
