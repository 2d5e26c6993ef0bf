// Leica PTX (ASCII) export; the format is described in ptx_reader.hpp.
#pragma once

#include <filesystem>
#include <span>

#include "acquisition/formats/output_file.hpp"
#include "acquisition/scan.hpp"

namespace scanbench::acquisition {

// Writes `scans` into one PTX file, in order. Points are written in the scan
// frame with the pose in the header, numbers in their shortest exact decimal
// form, so read_ptx(write_ptx(s)) reproduces range, intensity, colour,
// validity and pose bit for bit (the angle model is refitted from the points
// and agrees to about 1e-12 rad). Invalid pixels are written as "0 0 0".
// Scans without intensity get intensity 0 (PTX requires the field). Output is
// all-or-nothing (output_file.hpp); throws std::runtime_error naming `path` on
// write errors. Asserts every scan passes check_consistency().
void write_ptx(const std::filesystem::path& path, std::span<const Scan> scans);

// The same file written one scan at a time, so that an export holds one
// scan in memory.
class PtxWriter {
 public:
  explicit PtxWriter(const std::filesystem::path& path) : file_(path) {}
  void add(const Scan& scan);
  void commit() { file_.commit(); }

 private:
  OutputFile file_;
};

}  // namespace scanbench::acquisition
