#include <gtest/gtest.h>

#include "core/text.hpp"

namespace scanbench::core {
namespace {

TEST(AsciiLower, ChangesOnlyAsciiCapitals) {
  EXPECT_EQ(ascii_lower("NormalX .PLY"), "normalx .ply");
  EXPECT_EQ(ascii_lower("scalar_Intensity"), "scalar_intensity");
  // UTF-8 bytes (here É, 0xC3 0x89) are left as they are.
  EXPECT_EQ(ascii_lower("\xC3\x89T\xC3\x89"), "\xC3\x89t\xC3\x89");
  EXPECT_EQ(ascii_lower(""), "");
}

}  // namespace
}  // namespace scanbench::core
