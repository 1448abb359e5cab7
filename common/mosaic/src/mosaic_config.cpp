#include "cvslam/mosaic/mosaic_config.h"

#include "cvslam/io/config_node.h"

namespace cvslam::mosaic {

Status MosaicConfig::load(const ConfigNode& node) {
  mosaic.load(node.child("mosaic"));
  registration.load(node.child("registration"));
  photometric.load(node.child("photometric"));
  super_resolution.load(node.child("super_resolution"));
  evaluation.load(node.child("evaluation"));
  if (Status s = node.status(); !s.ok()) return s;
  return node.finish();
}

Expected<MosaicConfig> MosaicConfig::loadFile(const std::string& path) {
  auto node = ConfigNode::loadFile(path);
  if (!node.ok()) return node.status();
  MosaicConfig c;
  if (Status s = c.load(*node); !s.ok()) return s;
  return c;
}

}  // namespace cvslam::mosaic
