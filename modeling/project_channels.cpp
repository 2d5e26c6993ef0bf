#include "modeling/project_channels.hpp"

#include "core/errors.hpp"
#include "modeling/blob_codec.hpp"
#include "modeling/sqlite_statement.hpp"

namespace scanbench::modeling {

namespace {

struct ChannelsFound {
  bool range_m = false;
  bool valid = false;
  bool intensity = false;
  bool rgb = false;
  bool directions = false;
};

[[noreturn]] void damaged(const BlobContext& context, const std::string& problem) {
  core::FilePosition position;
  position.detail = context.location;
  throw core::InputError(context.file, position, "project is damaged: " + problem);
}

void check_count(std::size_t stored, std::size_t expected, const BlobContext& context) {
  if (stored != expected) {
    damaged(context, "channel has " + std::to_string(stored) + " elements, expected " +
                         std::to_string(expected));
  }
}

// Decodes one stored channel into `scan` and notes it in `found`.
void decode_channel(const std::string& channel, std::size_t count,
                    std::span<const std::uint8_t> blob, const BlobContext& context,
                    acquisition::Scan& scan, ChannelsFound& found) {
  const std::size_t n = scan.pixel_count();
  if (channel == "range_m") {
    check_count(count, n, context);
    scan.range_m = decompress_floats(blob, n, context);
    found.range_m = true;
  } else if (channel == "valid") {
    check_count(count, n, context);
    scan.valid = decompress_bytes(blob, n, context);
    found.valid = true;
  } else if (channel == "intensity") {
    check_count(count, n, context);
    scan.intensity = decompress_floats(blob, n, context);
    found.intensity = true;
  } else if (channel == "rgb") {
    check_count(count, 3 * n, context);
    scan.rgb = decompress_bytes(blob, 3 * n, context);
    found.rgb = true;
  } else if (channel == "directions" && !scan.is_spherical()) {
    check_count(count, n, context);
    std::get<acquisition::PerPixelDirections>(scan.angles).directions =
        decompress_vectors(blob, n, context);
    found.directions = true;
  } else {
    damaged(context, "unexpected channel");
  }
}

void check_complete(const ChannelsFound& found, bool has_intensity, bool has_color,
                    const acquisition::Scan& scan, const BlobContext& context) {
  if (!found.range_m) damaged(context, "channel range_m is missing");
  if (!found.valid) damaged(context, "channel valid is missing");
  if (found.intensity != has_intensity) damaged(context, "intensity channel disagrees with flag");
  if (found.rgb != has_color) damaged(context, "rgb channel disagrees with flag");
  if (!scan.is_spherical() && !found.directions) {
    damaged(context, "channel directions is missing");
  }
}

void insert_channel(sqlite3* db, const std::string& file, std::int64_t id, const char* channel,
                    std::size_t element_count, const std::vector<std::uint8_t>& blob) {
  sqlite::Statement insert(db,
                           "INSERT INTO scan_channels (scan_id, channel, element_count, codec, "
                           "data) VALUES (?1, ?2, ?3, 'zstd', ?4)",
                           file);
  insert.bind_int(1, id).bind_text(2, channel);
  insert.bind_int(3, static_cast<std::int64_t>(element_count)).bind_blob(4, blob);
  insert.run();
}

}  // namespace

void insert_channels(sqlite3* db, const std::string& file, std::int64_t id,
                     const acquisition::Scan& scan) {
  insert_channel(db, file, id, "range_m", scan.range_m.size(), compress_floats(scan.range_m));
  insert_channel(db, file, id, "valid", scan.valid.size(), compress_bytes(scan.valid));
  if (scan.has_intensity()) {
    insert_channel(db, file, id, "intensity", scan.intensity.size(),
                   compress_floats(scan.intensity));
  }
  if (scan.has_color()) {
    insert_channel(db, file, id, "rgb", scan.rgb.size(), compress_bytes(scan.rgb));
  }
  if (const auto* per_pixel = std::get_if<acquisition::PerPixelDirections>(&scan.angles)) {
    insert_channel(db, file, id, "directions", per_pixel->directions.size(),
                   compress_vectors(per_pixel->directions));
  }
}

void read_channels(sqlite3* db, const std::string& file, std::int64_t id, bool has_intensity,
                   bool has_color, acquisition::Scan& scan) {
  sqlite::Statement select(
      db, "SELECT channel, element_count, codec, data FROM scan_channels WHERE scan_id = ?1", file);
  select.bind_int(1, id);
  ChannelsFound found;
  while (select.step()) {
    const std::string channel = select.column_text(0);
    const BlobContext context{file, "scan " + std::to_string(id) + ", channel " + channel};
    if (select.column_text(2) != "zstd") damaged(context, "unknown codec");
    const std::int64_t count = select.column_int(1);
    if (count < 0) damaged(context, "negative element count");
    decode_channel(channel, static_cast<std::size_t>(count), select.column_blob(3), context, scan,
                   found);
  }
  check_complete(found, has_intensity, has_color, scan,
                 BlobContext{file, "scan " + std::to_string(id)});
}

}  // namespace scanbench::modeling
