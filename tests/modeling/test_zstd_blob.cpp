#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "core/errors.hpp"
#include "modeling/store/zstd_blob.hpp"

namespace scanbench::store {
namespace {

using core::InputError;
using ::testing::HasSubstr;

const BlobContext kContext{"site.sbproj", "scan 3, channel range_m"};

// Bit patterns, so that -0.0 and NaN payloads count too.
bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

TEST(BlobCodec, FloatsRoundTripBitForBit) {
  const std::vector<float> values = {0.0f,
                                     -0.0f,
                                     1.5f,
                                     -3.25e-7f,
                                     std::numeric_limits<float>::quiet_NaN(),
                                     std::numeric_limits<float>::infinity(),
                                     std::numeric_limits<float>::denorm_min(),
                                     12345.678f};
  const auto blob = compress_floats(values);
  EXPECT_TRUE(same_bits(decompress_floats(blob, values.size(), kContext), values));
}

TEST(BlobCodec, BytesRoundTrip) {
  std::vector<std::uint8_t> values(1000);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = static_cast<std::uint8_t>(i * 7);
  const auto blob = compress_bytes(values, 19);
  EXPECT_EQ(decompress_bytes(blob, values.size(), kContext), values);
}

TEST(BlobCodec, VectorsRoundTripAsPackedFloats) {
  const std::vector<Eigen::Vector3f> values = {{1, 2, 3}, {-0.0f, 0.5f, -7}, {0, 0, 0}};
  const auto blob = compress_vectors(values);
  EXPECT_EQ(decompress_vectors(blob, values.size(), kContext), values);
  // The layout is x, y, z floats per element, which other tools may rely on.
  const auto raw = decompress(blob, 9 * sizeof(float), kContext);
  float floats[9];
  std::memcpy(floats, raw.data(), sizeof(floats));
  EXPECT_EQ(floats[3], -0.0f);
  EXPECT_TRUE(std::signbit(floats[3]));
  EXPECT_EQ(floats[5], -7.0f);
}

TEST(BlobCodec, EmptyArrayRoundTrips) {
  const auto blob = compress_floats(std::vector<float>{});
  EXPECT_FALSE(blob.empty());  // still a frame, which records size 0
  EXPECT_TRUE(decompress_floats(blob, 0, kContext).empty());
}

TEST(BlobCodec, RepetitiveDataShrinks) {
  const std::vector<float> values(100000, 7.5f);
  EXPECT_LT(compress_floats(values).size(), values.size() * sizeof(float) / 100);
}

TEST(BlobCodec, WrongExpectedSizeIsAnInputErrorNamingTheChannel) {
  const auto blob = compress_floats(std::vector<float>(10, 1.0f));
  try {
    decompress_floats(blob, 11, kContext);
    FAIL() << "expected core::InputError";
  } catch (const core::InputError& error) {
    EXPECT_EQ(error.file(), "site.sbproj");
    EXPECT_EQ(error.position().detail, "scan 3, channel range_m");
    EXPECT_THAT(error.what(), HasSubstr("holds 40 bytes, expected 44"));
  }
}

TEST(BlobCodec, TruncatedBlobIsAnInputError) {
  std::vector<float> values(1000);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = std::sin(static_cast<float>(i));
  auto blob = compress_floats(values);
  blob.resize(blob.size() / 2);
  EXPECT_THROW(decompress_floats(blob, values.size(), kContext), core::InputError);
}

TEST(BlobCodec, FlippedBitsAreCaughtNeverDecodedWrong) {
  std::vector<float> values(1000);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = std::sin(static_cast<float>(i));
  const auto blob = compress_floats(values);
  // Headers, compressed body and the checksum at the end. A few header bits
  // are reserved and ignored by zstd, so a flip may decode to the original;
  // it must never decode to anything else.
  int caught = 0;
  for (std::size_t i = 0; i < blob.size(); ++i) {
    for (const std::uint8_t bit : {0x01, 0x10, 0x80}) {
      auto damaged = blob;
      damaged[i] ^= bit;
      try {
        EXPECT_TRUE(same_bits(decompress_floats(damaged, values.size(), kContext), values))
            << "byte " << i << " bit " << int{bit};
      } catch (const core::InputError&) {
        ++caught;
      }
    }
  }
  EXPECT_GT(caught, static_cast<int>(3 * blob.size()) * 9 / 10);
}

TEST(BlobCodec, GarbageAndEmptyBlobsAreInputErrors) {
  const std::vector<std::uint8_t> garbage = {'n', 'o', 't', ' ', 'z', 's', 't', 'd'};
  EXPECT_THROW(decompress_bytes(garbage, 8, kContext), core::InputError);
  EXPECT_THROW(decompress_bytes({}, 0, kContext), core::InputError);
}

TEST(BlobCodec, TrailingBytesAreAnInputError) {
  auto blob = compress_bytes(std::vector<std::uint8_t>(64, 1));
  const auto second = compress_bytes(std::vector<std::uint8_t>(64, 2));
  blob.insert(blob.end(), second.begin(), second.end());
  EXPECT_THROW(decompress_bytes(blob, 64, kContext), core::InputError);
}

TEST(BlobCodec, ImpossibleCountIsAnInputErrorNotAnAllocation) {
  const auto blob = compress_floats(std::vector<float>(4, 1.0f));
  EXPECT_THROW(decompress_floats(blob, std::numeric_limits<std::size_t>::max() / 2, kContext),
               core::InputError);
}

}  // namespace
}  // namespace scanbench::store
