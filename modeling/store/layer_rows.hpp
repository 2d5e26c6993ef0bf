// A layer read or written a band of rows at a time (docs/scale.md, "Big
// scans"): a stage that works on a scan band by band holds a band of each
// layer, never the layer whole, whatever the scan's size. The stored form
// is the one of layer_store.hpp (one zstd frame), so a layer written by
// rows reads whole, and the other way round.
//
// Reading streams the frame out of its row in the project (SQLite's
// incremental blob reads, through zstd's window of at most a few MB): a
// reader holds its buffers, never the compressed layer. Writing compresses
// the rows as they come into an unnamed temporary file (core::SpillFile;
// kept in memory where that file cannot be made or fills up), and
// Project::put_layer copies it into the project in pieces.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "modeling/store/layer_store.hpp"

struct sqlite3;

namespace scanbench::core {
class SpillFile;
}

namespace scanbench::store {

class Project;
struct BlobContext;

// The rows of one layer version, in order. Made by Project::open_layer_rows,
// which checks what load_layer checks before anything is decoded (its row's
// checksum, codec, element type and count, and the frame's recorded size).
// The frame's own checksum is checked when its last row is read. Must not
// outlive its project, and the layer's row must not change meanwhile (a
// stage's own writes go to new rows).
class LayerRowReader {
 public:
  LayerRowReader(LayerRowReader&&) noexcept;
  LayerRowReader& operator=(LayerRowReader&&) noexcept;
  ~LayerRowReader();

  int rows() const { return rows_; }
  int columns() const { return columns_; }
  ElementType type() const { return type_; }
  // Rows read so far.
  int rows_read() const { return next_row_; }

  // Decodes the next out.size() / (columns · element size) rows into `out`,
  // which must hold whole rows, no more than remain (asserted). Throws
  // core::InputError naming the project, scan and layer when the data is
  // damaged: a frame that ends early or late, fails its checksum, or is
  // followed by other bytes.
  void read(std::span<std::byte> out);
  template <typename T>
  void read(std::span<T> out) {
    read(std::as_writable_bytes(out));
  }
  // The next `rows` rows in a new array. Throws as read().
  template <typename T>
  std::vector<T> read_rows(int rows) {
    std::vector<T> values(static_cast<std::size_t>(rows) * static_cast<std::size_t>(columns_));
    read(std::span(values));
    return values;
  }

  // Decodes the rows left, a band at a time, and drops them: checks the
  // rest of the frame (once at least: a layer of no pixels has one too).
  // Throws as read().
  void read_rest();

 private:
  friend class Project;
  friend void check_stored_frame(sqlite3* db, std::int64_t rowid, const char* column, int rows,
                                 int columns, ElementType type, const BlobContext& context);
  struct Stream;
  LayerRowReader(std::unique_ptr<Stream> stream, int rows, int columns, ElementType type);
  // The frame in `column` ("data" or "frame") of scan_layers row `rowid`,
  // whose fields the caller verified.
  static LayerRowReader open_blob(sqlite3* db, std::int64_t rowid, const char* column, int rows,
                                  int columns, ElementType type, const BlobContext& context);

  std::unique_ptr<Stream> stream_;
  int rows_ = 0;
  int columns_ = 0;
  ElementType type_ = ElementType::kU8;
  int next_row_ = 0;
};

// For `check`: decodes the frame in `column` ("data" or "frame") of
// scan_layers row `rowid`, a layer of rows × columns elements of `type`,
// a band at a time, as a reader does; throws core::InputError naming
// `context` where it is damaged.
void check_stored_frame(sqlite3* db, std::int64_t rowid, const char* column, int rows, int columns,
                        ElementType type, const BlobContext& context);

// A layer of rows × columns elements compressed as its rows come, for
// Project::put_layer. Memory: zstd's window and a buffer of a few MB.
class LayerRowWriter {
 public:
  LayerRowWriter(std::string name, ElementType type, int rows, int columns);
  LayerRowWriter(LayerRowWriter&&) noexcept;
  LayerRowWriter& operator=(LayerRowWriter&&) noexcept;
  ~LayerRowWriter();

  const std::string& name() const { return name_; }
  ElementType type() const { return type_; }
  int rows() const { return rows_; }
  int columns() const { return columns_; }
  int rows_written() const { return rows_written_; }
  bool complete() const { return rows_written_ == rows_; }

  // Appends whole rows (asserted, and no more than remain); the last row
  // ends the frame. Throws std::bad_alloc when zstd cannot allocate.
  void write(std::span<const std::byte> values);
  template <typename T>
  void write(std::span<const T> values) {
    write(std::as_bytes(values));
  }

  // The compressed frame's size [bytes]; asserts complete().
  std::uint64_t compressed_bytes() const;
  // Hands the frame to `sink` in pieces, in order; asserts complete().
  // Throws core::RuntimeFailure when the temporary file cannot be read.
  template <typename Sink>
  void for_each_piece(Sink&& sink) const {
    std::vector<std::byte> piece;
    for (std::size_t k = 0; k < piece_count(); ++k) sink(read_piece(k, piece));
  }

 private:
  struct Sink;
  std::size_t piece_count() const;
  std::span<const std::byte> read_piece(std::size_t k, std::vector<std::byte>& buffer) const;
  void emit(std::span<const std::byte> compressed);

  std::string name_;
  ElementType type_ = ElementType::kU8;
  int rows_ = 0;
  int columns_ = 0;
  int rows_written_ = 0;
  std::unique_ptr<Sink> sink_;
};

// The next `rows` rows of `reader`; none without one (a layer the scan
// does not have). Throws as LayerRowReader::read.
template <typename T>
std::optional<std::vector<T>> read_rows(std::optional<LayerRowReader>& reader, int rows) {
  if (!reader) return std::nullopt;
  return reader->read_rows<T>(rows);
}

// Rows of a band that holds about `pixels` pixels of a grid `columns`
// wide: a multiple of `multiple` (at least one multiple).
int band_rows(std::size_t pixels, int columns, int multiple = 1);

}  // namespace scanbench::store
