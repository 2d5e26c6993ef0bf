// LZF decoding on hand-built streams with exact answers.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "acquisition/formats/lzf.hpp"

namespace scanbench::acquisition {
namespace {

using Bytes = std::vector<std::uint8_t>;

std::optional<std::string> decode(const Bytes& in, Bytes& out) {
  return lzf_decompress(in, out);
}

TEST(Lzf, LiteralRunCopiesBytes) {
  Bytes out(3);
  EXPECT_EQ(decode({2, 'a', 'b', 'c'}, out), std::nullopt);
  EXPECT_EQ(out, (Bytes{'a', 'b', 'c'}));
}

TEST(Lzf, BackReferenceMayOverlapWhatItWrites) {
  // "ab", then length 1 + 2 = 3 from 2 back: "aba"; total "ababa".
  Bytes out(5);
  EXPECT_EQ(decode({1, 'a', 'b', 1 << 5, 1}, out), std::nullopt);
  EXPECT_EQ(out, (Bytes{'a', 'b', 'a', 'b', 'a'}));
}

TEST(Lzf, LengthSevenTakesAnExtraLengthByte) {
  // "x", then 7 + 3 + 2 = 12 copies of the byte 1 back.
  Bytes out(13);
  EXPECT_EQ(decode({0, 'x', 7 << 5, 3, 0}, out), std::nullopt);
  EXPECT_EQ(out, Bytes(13, 'x'));
}

TEST(Lzf, DamageIsReportedNotFollowed) {
  Bytes out(4);
  EXPECT_THAT(*decode({5, 'a'}, out), ::testing::HasSubstr("past the end of the data"));
  EXPECT_THAT(*decode({0, 'a', 1 << 5, 9}, out), ::testing::HasSubstr("before the start"));
  EXPECT_THAT(*decode({0, 'a', 7 << 5}, out), ::testing::HasSubstr("cut off"));
  EXPECT_THAT(*decode({0, 'a', 1 << 5, 0, 1 << 5, 0}, out),
              ::testing::HasSubstr("past the declared size"));
  EXPECT_THAT(*decode({0, 'a'}, out), ::testing::HasSubstr("decodes to 1 bytes"));
}

}  // namespace
}  // namespace scanbench::acquisition
