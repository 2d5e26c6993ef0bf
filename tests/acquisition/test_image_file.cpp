// Our image encoders (image_file.cpp), read back by our decoder, whose
// channel order the triplet fixtures of an independent writer pin down:
// every pixel type the product writes comes back bit for bit (random
// channels, so a swapped red and blue would show).
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <string>

#include "acquisition/formats/image_decoder.hpp"
#include "acquisition/formats/image_file.hpp"
#include "core/errors.hpp"
#include "support/test_support.hpp"

namespace scanbench::acquisition {
namespace {

using test::ScratchDir;

struct Encoded {
  const char* extension;
  int type;
};

class ImageFileRoundTrip : public ::testing::TestWithParam<Encoded> {};

TEST_P(ImageFileRoundTrip, DecodesToTheSamePixels) {
  const Encoded& e = GetParam();
  cv::Mat image(7, 11, e.type);
  cv::randu(image, 0, e.type == CV_32FC1 || e.type == CV_32FC3 ? 1e4 : 255);
  ScratchDir dir;
  const std::filesystem::path path = dir / (std::string("image") + e.extension);
  write_image_file(path, image);
  const DecodedImage back = decode_image(path, image.rows, image.cols);
  ASSERT_TRUE(back.problem.empty()) << back.problem;
  ASSERT_EQ(back.pixels.type(), image.type());
  EXPECT_EQ(cv::norm(back.pixels, image, cv::NORM_INF), 0.0);
}

INSTANTIATE_TEST_SUITE_P(EveryWrittenType, ImageFileRoundTrip,
                         ::testing::Values(Encoded{".png", CV_8UC1}, Encoded{".png", CV_8UC3},
                                           Encoded{".png", CV_8UC4}, Encoded{".png", CV_16UC1},
                                           Encoded{".png", CV_16UC3}, Encoded{".tiff", CV_32FC1},
                                           Encoded{".tiff", CV_32FC3}, Encoded{".tif", CV_16UC1},
                                           Encoded{".TIFF", CV_8UC3}));

TEST(ImageFile, RefusesFormatsItDoesNotWriteByName) {
  const cv::Mat image(2, 2, CV_8UC1, cv::Scalar(3));
  ScratchDir dir;
  for (const char* name : {"image.jpg", "image.exr", "image"}) {
    try {
      write_image_file(dir / name, image);
      FAIL() << name << " was written";
    } catch (const core::RuntimeFailure& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
    EXPECT_FALSE(std::filesystem::exists(dir / name)) << name;
  }
  const cv::Mat floats(2, 2, CV_32FC1, cv::Scalar(1.5));
  EXPECT_THROW(write_image_file(dir / "floats.png", floats), core::RuntimeFailure);
}

}  // namespace
}  // namespace scanbench::acquisition
