// Layers read and written by rows (layer_rows.hpp).
#include "modeling/store/layer_rows.hpp"

#include <sqlite3.h>
#include <zstd.h>

#include <algorithm>
#include <cassert>
#include <cstring>
#include <new>

#include "core/errors.hpp"
#include "core/spill_file.hpp"
#include "modeling/store/sqlite_statement.hpp"
#include "modeling/store/zstd_blob.hpp"

namespace scanbench::store {
namespace {

// Compressed bytes moved between SQLite, zstd and the temporary file at once.
constexpr std::size_t kPieceBytes = std::size_t{1} << 20;
// The longest zstd frame header (ZSTD_FRAMEHEADERSIZE_MAX, which zstd.h
// declares for static linking only).
constexpr std::uint64_t kFrameHeaderMaxBytes = 18;

[[noreturn]] void damaged(const BlobContext& context, const std::string& problem) {
  core::FilePosition position;
  position.detail = context.location;
  throw core::InputError(context.file, position, "damaged channel data: " + problem);
}

}  // namespace

// ---- Reading -----------------------------------------------------------------------------

struct LayerRowReader::Stream {
  sqlite3* db = nullptr;
  sqlite3_blob* blob = nullptr;
  ZSTD_DCtx* zstd = nullptr;
  std::uint64_t blob_bytes = 0;
  std::uint64_t offset = 0;  // of the blob, read into `input` so far
  std::vector<std::byte> input;
  ZSTD_inBuffer in{nullptr, 0, 0};
  BlobContext context;
  bool frame_ended = false;

  ~Stream() {
    ZSTD_freeDCtx(zstd);
    sqlite3_blob_close(blob);
  }

  // Refills `input` from the blob once zstd has taken all of it; false at
  // the blob's end.
  bool refill() {
    if (in.pos < in.size) return true;
    if (offset == blob_bytes) return false;
    const auto n = static_cast<int>(std::min<std::uint64_t>(kPieceBytes, blob_bytes - offset));
    const int code = sqlite3_blob_read(blob, input.data(), n, static_cast<int>(offset));
    // A damaged page is damage (InputError), a failing disk a RuntimeFailure.
    if (code != SQLITE_OK) sqlite::throw_error(db, code, context.file, context.location);
    offset += static_cast<std::uint64_t>(n);
    in = {input.data(), static_cast<std::size_t>(n), 0};
    return true;
  }

  void decode(std::span<std::byte> out) {
    ZSTD_outBuffer target{out.data(), out.size(), 0};
    while (target.pos < target.size) {
      if (frame_ended) damaged(context, "the frame ends before the layer's last row");
      if (!refill()) damaged(context, "the frame is cut short");
      const std::size_t code = ZSTD_decompressStream(zstd, &target, &in);
      if (ZSTD_isError(code)) damaged(context, ZSTD_getErrorName(code));
      frame_ended = code == 0;
    }
  }

  // After the last row: the frame's end (its checksum checked), and nothing after it.
  void finish() {
    std::byte spare{};
    while (!frame_ended) {
      ZSTD_outBuffer target{&spare, 1, 0};
      if (!refill()) damaged(context, "the frame is cut short");
      const std::size_t code = ZSTD_decompressStream(zstd, &target, &in);
      if (ZSTD_isError(code)) damaged(context, ZSTD_getErrorName(code));
      if (target.pos != 0) damaged(context, "the frame holds more than the layer's rows");
      frame_ended = code == 0;
    }
    if (in.pos < in.size || offset < blob_bytes) damaged(context, "bytes follow the frame");
  }
};

LayerRowReader::LayerRowReader(std::unique_ptr<Stream> stream, int rows, int columns,
                               ElementType type)
    : stream_(std::move(stream)), rows_(rows), columns_(columns), type_(type) {}
LayerRowReader::LayerRowReader(LayerRowReader&&) noexcept = default;
LayerRowReader& LayerRowReader::operator=(LayerRowReader&&) noexcept = default;
LayerRowReader::~LayerRowReader() = default;

void LayerRowReader::read(std::span<std::byte> out) {
  const std::size_t row_bytes = static_cast<std::size_t>(columns_) * element_size(type_);
  assert((row_bytes == 0 ? out.empty() : out.size() % row_bytes == 0) && "whole rows");
  // Rows of no pixels are all read at once.
  const int rows = row_bytes == 0 ? rows_ - next_row_ : static_cast<int>(out.size() / row_bytes);
  assert(rows <= rows_ - next_row_ && "no more rows than remain");
  stream_->decode(out);
  next_row_ += rows;
  if (next_row_ == rows_) stream_->finish();
}

LayerRowReader LayerRowReader::open_blob(sqlite3* db, std::int64_t rowid, const char* column,
                                         int rows, int columns, ElementType type,
                                         const BlobContext& context) {
  auto stream = std::make_unique<Stream>();
  stream->db = db;
  stream->context = context;
  const int code = sqlite3_blob_open(db, "main", "scan_layers", column, rowid, 0, &stream->blob);
  if (code != SQLITE_OK) sqlite::throw_error(db, code, context.file, context.location);
  stream->blob_bytes = static_cast<std::uint64_t>(sqlite3_blob_bytes(stream->blob));
  // The frame's header first: it must record the layer's size.
  std::vector<std::uint8_t> header(std::min(kFrameHeaderMaxBytes, stream->blob_bytes));
  if (const int read =
          sqlite3_blob_read(stream->blob, header.data(), static_cast<int>(header.size()), 0);
      read != SQLITE_OK) {
    sqlite::throw_error(db, read, context.file, context.location);
  }
  check_blob_size(
      header,
      static_cast<std::size_t>(rows) * static_cast<std::size_t>(columns) * element_size(type),
      context);
  stream->zstd = ZSTD_createDCtx();
  if (stream->zstd == nullptr) throw std::bad_alloc();
  stream->input.resize(kPieceBytes);
  return LayerRowReader(std::move(stream), rows, columns, type);
}

void LayerRowReader::read_rest() {
  const int band = band_rows(kPieceBytes / element_size(type_), columns_);
  std::vector<std::byte> values;
  do {
    const int n = std::min(band, rows_ - next_row_);
    values.resize(static_cast<std::size_t>(n) * static_cast<std::size_t>(columns_) *
                  element_size(type_));
    read(std::span(values));
  } while (next_row_ < rows_);
}

void check_stored_frame(sqlite3* db, std::int64_t rowid, const char* column, int rows, int columns,
                        ElementType type, const BlobContext& context) {
  LayerRowReader::open_blob(db, rowid, column, rows, columns, type, context).read_rest();
}

// ---- Writing -----------------------------------------------------------------------------

struct LayerRowWriter::Sink {
  ZSTD_CCtx* zstd = nullptr;
  std::vector<std::byte> output;  // zstd's output, kPieceBytes
  core::SpillFile spill;
  std::vector<core::SpillFile::Extent> spilled;   // the frame's pieces in `spill`, in order
  std::vector<std::vector<std::byte>> in_memory;  // or here, once the file failed
  std::uint64_t bytes = 0;

  ~Sink() {
    for (const core::SpillFile::Extent& extent : spilled) spill.release(extent);
    ZSTD_freeCCtx(zstd);
  }
};

LayerRowWriter::LayerRowWriter(std::string name, ElementType type, int rows, int columns)
    : name_(std::move(name)),
      type_(type),
      rows_(rows),
      columns_(columns),
      sink_(std::make_unique<Sink>()) {
  assert(rows >= 0 && columns >= 0);
  sink_->zstd = ZSTD_createCCtx();
  if (sink_->zstd == nullptr) throw std::bad_alloc();
  ZSTD_CCtx_setParameter(sink_->zstd, ZSTD_c_compressionLevel, kDefaultCompressionLevel);
  ZSTD_CCtx_setParameter(sink_->zstd, ZSTD_c_checksumFlag, 1);  // as compress() writes it
  ZSTD_CCtx_setPledgedSrcSize(sink_->zstd, static_cast<unsigned long long>(rows) *
                                               static_cast<unsigned long long>(columns) *
                                               element_size(type));
  sink_->output.resize(kPieceBytes);
  if (rows == 0) write({});  // an empty layer is one empty frame
}

LayerRowWriter::LayerRowWriter(LayerRowWriter&&) noexcept = default;
LayerRowWriter& LayerRowWriter::operator=(LayerRowWriter&&) noexcept = default;
LayerRowWriter::~LayerRowWriter() = default;

void LayerRowWriter::emit(std::span<const std::byte> compressed) {
  if (compressed.empty()) return;
  sink_->bytes += compressed.size();
  if (sink_->in_memory.empty()) {
    if (const auto extent = sink_->spill.put(compressed.data(), compressed.size())) {
      sink_->spilled.push_back(*extent);
      return;
    }
  }
  sink_->in_memory.emplace_back(compressed.begin(), compressed.end());
}

void LayerRowWriter::write(std::span<const std::byte> values) {
  const std::size_t row_bytes = static_cast<std::size_t>(columns_) * element_size(type_);
  assert((row_bytes == 0 ? values.empty() : values.size() % row_bytes == 0) && "whole rows");
  const int rows = row_bytes == 0 ? rows_ : static_cast<int>(values.size() / row_bytes);
  assert(rows <= rows_ - rows_written_ && "no more rows than the layer has");
  rows_written_ += rows;
  ZSTD_inBuffer in{values.data(), values.size(), 0};
  const ZSTD_EndDirective mode = rows_written_ == rows_ ? ZSTD_e_end : ZSTD_e_continue;
  for (;;) {
    ZSTD_outBuffer out{sink_->output.data(), sink_->output.size(), 0};
    const std::size_t left = ZSTD_compressStream2(sink_->zstd, &out, &in, mode);
    // The input is plain bytes, and as long as pledged (asserted above):
    // what is left to fail is memory for zstd's tables.
    if (ZSTD_isError(left)) throw std::bad_alloc();
    emit(std::span(sink_->output).first(out.pos));
    const bool done = mode == ZSTD_e_end ? left == 0 : in.pos == in.size;
    if (done) break;
  }
}

std::uint64_t LayerRowWriter::compressed_bytes() const {
  assert(complete() && "every row written");
  return sink_->bytes;
}

std::size_t LayerRowWriter::piece_count() const {
  return sink_->spilled.size() + sink_->in_memory.size();
}

std::span<const std::byte> LayerRowWriter::read_piece(std::size_t k,
                                                      std::vector<std::byte>& buffer) const {
  assert(complete() && "every row written");
  if (k >= sink_->spilled.size()) return sink_->in_memory[k - sink_->spilled.size()];
  const core::SpillFile::Extent& extent = sink_->spilled[k];
  buffer.resize(extent.bytes);
  sink_->spill.get(extent, buffer.data());
  return buffer;
}

int band_rows(std::size_t pixels, int columns, int multiple) {
  assert(multiple >= 1);
  const std::size_t per_row = static_cast<std::size_t>(std::max(columns, 1));
  const std::size_t multiples =
      std::max<std::size_t>(1, pixels / per_row / static_cast<std::size_t>(multiple));
  return static_cast<int>(std::min<std::size_t>(multiples * multiple, 1u << 30));
}

}  // namespace scanbench::store
