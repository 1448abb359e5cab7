// config/mosaic.yaml loads, and bad options fail with a message naming the key.
#include <gtest/gtest.h>

#include "cvslam/io/config_node.h"
#include "cvslam/mosaic/mosaic_config.h"

namespace cvslam::mosaic {
namespace {

TEST(MosaicConfig, ShippedFileLoadsWithItsValues) {
  const auto c = MosaicConfig::loadFile(std::string(CVSLAM_SOURCE_DIR) + "/config/mosaic.yaml");
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_DOUBLE_EQ(c->mosaic.gsd, 0.02);
  EXPECT_EQ(c->super_resolution.scale, 2);
  EXPECT_EQ(c->mosaic.adjustment.model, CorrectionModel::kSimilarity);
}

Status loadText(const std::string& yaml) {
  auto node = ConfigNode::fromString(yaml, "test.yaml");
  if (!node.ok()) return node.status();
  MosaicConfig c;
  return c.load(*node);
}

TEST(MosaicConfig, InvalidValuesAndUnknownKeysFail) {
  const Status gsd = loadText("mosaic: {gsd: 0}\n");
  ASSERT_FALSE(gsd.ok());
  EXPECT_NE(gsd.message().find("mosaic.gsd"), std::string::npos) << gsd.message();
  const Status band = loadText("super_resolution: {bandwidth: 1.5}\n");
  ASSERT_FALSE(band.ok());
  EXPECT_NE(band.message().find("bandwidth"), std::string::npos) << band.message();
  const Status model = loadText("mosaic: {adjustment: {model: spline}}\n");
  EXPECT_FALSE(model.ok());
  const Status typo = loadText("photometric: {enabeld: true}\n");
  ASSERT_FALSE(typo.ok());
  EXPECT_NE(typo.message().find("enabeld"), std::string::npos) << typo.message();
  EXPECT_TRUE(loadText("mosaic: {gsd: 0.04}\n").ok());
}

}  // namespace
}  // namespace cvslam::mosaic
