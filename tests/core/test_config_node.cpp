#include "cvslam/io/config_node.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "cvslam/io/options_description.h"

namespace cvslam {
namespace {

enum class Kind { kA, kB };

struct DemoOptions {
  double gamma = 1.0;
  int k = 20;
  bool flag = false;
  std::string name = "x";
  Kind kind = Kind::kA;
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  Eigen::Matrix2d m = Eigen::Matrix2d::Identity();

  Status load(const ConfigNode& node) {
    node.get("gamma", gamma);
    node.check(gamma > 0.0, "gamma", "must be > 0 (got " + std::to_string(gamma) + ")");
    node.get("k", k);
    node.get("flag", flag);
    node.get("name", name);
    node.getEnum("kind", kind, {{"a", Kind::kA}, {"b", Kind::kB}});
    node.get("v", v);
    node.get("m", m);
    return node.status();
  }
};

TEST(ConfigNode, MissingKeysKeepDefaults) {
  auto cfg = ConfigNode::fromString("{}", "t.yaml");
  ASSERT_TRUE(cfg.ok());
  DemoOptions o;
  EXPECT_TRUE(o.load(*cfg).ok());
  EXPECT_EQ(o.k, 20);
  EXPECT_EQ(o.kind, Kind::kA);
  EXPECT_TRUE(cfg->finish().ok());
}

TEST(ConfigNode, ReadsEveryType) {
  auto cfg = ConfigNode::fromString(
      "filter: {gamma: 2.5, k: 7, flag: true, name: hello, kind: b, v: [1, 2, 3], m: [1, 2, 3, "
      "4]}",
      "t.yaml");
  ASSERT_TRUE(cfg.ok());
  DemoOptions o;
  ASSERT_TRUE(o.load(cfg->child("filter")).ok()) << cfg->status().message();
  EXPECT_DOUBLE_EQ(o.gamma, 2.5);
  EXPECT_EQ(o.k, 7);
  EXPECT_TRUE(o.flag);
  EXPECT_EQ(o.name, "hello");
  EXPECT_EQ(o.kind, Kind::kB);
  EXPECT_EQ(o.v, Eigen::Vector3d(1, 2, 3));
  EXPECT_DOUBLE_EQ(o.m(0, 1), 2.0);  // row-major in the file
  EXPECT_DOUBLE_EQ(o.m(1, 0), 3.0);
  EXPECT_TRUE(cfg->finish().ok());
}

TEST(ConfigNode, ErrorNamesFileKeyAndReason) {
  auto cfg = ConfigNode::fromString("filter: {gamma: -2}", "agent.yaml");
  ASSERT_TRUE(cfg.ok());
  DemoOptions o;
  Status s = o.load(cfg->child("filter"));
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message().rfind("agent.yaml: filter.gamma: must be > 0", 0), 0u) << s.message();
}

TEST(ConfigNode, WrongTypesAreErrors) {
  for (const char* yaml : {"k: 1.5", "k: abc", "flag: maybe", "v: [1, 2]", "v: 3", "gamma: .nan",
                           "kind: c", "name: [1, 2]"}) {
    auto cfg = ConfigNode::fromString(yaml, "t.yaml");
    ASSERT_TRUE(cfg.ok());
    DemoOptions o;
    EXPECT_FALSE(o.load(*cfg).ok()) << yaml;
  }
}

TEST(ConfigNode, UnknownKeysAreReportedByFinish) {
  auto cfg = ConfigNode::fromString("filter: {gamma: 1, k_nearst: 3}", "t.yaml");
  ASSERT_TRUE(cfg.ok());
  DemoOptions o;
  EXPECT_TRUE(o.load(cfg->child("filter")).ok());
  Status s = cfg->finish();
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message(), "t.yaml: filter.k_nearst: unknown key");
}

TEST(ConfigNode, RequireAndSequences) {
  auto cfg = ConfigNode::fromString("agents: [{id: 1}, {id: 2}, 3]", "t.yaml");
  ASSERT_TRUE(cfg.ok());
  auto agents = cfg->sequence("agents");
  ASSERT_EQ(agents.size(), 2u);
  int id = 0;
  agents[1].require("id", id);
  EXPECT_EQ(id, 2);
  EXPECT_FALSE(cfg->status().ok());  // the third element is not a map
  auto cfg2 = ConfigNode::fromString("a: 1", "t.yaml");
  int missing = 0;
  cfg2->require("b", missing);
  EXPECT_EQ(cfg2->status().message(), "t.yaml: b: required key is missing");
}

TEST(ConfigNode, BadFilesGiveClearErrors) {
  auto missing = ConfigNode::loadFile("/nonexistent/cvslam.yaml");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("cannot open"), std::string::npos);
  auto bad = ConfigNode::fromString("a: [1, 2", "bad.yaml");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().message().rfind("bad.yaml: invalid YAML", 0), 0u);
  auto scalar = ConfigNode::fromString("42", "s.yaml");
  ASSERT_FALSE(scalar.ok());
  const std::string path = ::testing::TempDir() + "/cvslam_config_test.yaml";
  std::ofstream(path) << "# comment only\n";
  auto empty = ConfigNode::loadFile(path);
  ASSERT_TRUE(empty.ok());
  EXPECT_TRUE(empty->finish().ok());
  std::remove(path.c_str());
}

TEST(OptionsDescription, PrintsEveryKeyTheLoaderReadsAsYamlThatLoadsBack) {
  DemoOptions o;
  o.gamma = 0.1;  // not exactly representable: the text must still give the same double
  o.k = -3;
  o.flag = true;
  o.name = "with: colon";
  o.kind = Kind::kB;
  o.v = Eigen::Vector3d(1.5, -2, 1e-12);
  o.m << 1, 2, 3, 4;
  const std::string text = describeOptions(o);
  for (const char* key : {"gamma:", "k: -3", "flag: true", "kind: b", "v:", "m:"})
    EXPECT_NE(text.find(key), std::string::npos) << key << " missing from\n" << text;

  auto back = ConfigNode::fromString(text, "described");
  ASSERT_TRUE(back.ok()) << back.status().message() << "\n" << text;
  DemoOptions read;
  ASSERT_TRUE(read.load(*back).ok()) << back->status().message();
  EXPECT_TRUE(back->finish().ok()) << back->finish().message();
  EXPECT_EQ(read.gamma, o.gamma);
  EXPECT_EQ(read.k, o.k);
  EXPECT_EQ(read.name, o.name);
  EXPECT_EQ(read.kind, o.kind);
  EXPECT_EQ(read.v, o.v);
  EXPECT_EQ(read.m, o.m);
  EXPECT_TRUE(sameOptions(read, o));
}

TEST(OptionsDescription, EqualityIsEveryValueExactly) {
  DemoOptions a, b;
  EXPECT_TRUE(sameOptions(a, b));
  b.gamma = std::nextafter(a.gamma, 2.0);  // one ulp
  EXPECT_FALSE(sameOptions(a, b));
  b = a;
  b.m(1, 0) = 5.0;
  EXPECT_FALSE(sameOptions(a, b));
  b = a;
  b.kind = Kind::kB;
  EXPECT_FALSE(sameOptions(a, b));
}

TEST(OptionsDescription, SectionsAndListsNest) {
  auto cfg = ConfigNode::fromString("outer: {inner: {k: 4}, items: [{k: 1}, {k: 2}]}", "t.yaml");
  ASSERT_TRUE(cfg.ok());
  DemoOptions inner;
  inner.load(cfg->child("outer").child("inner"));
  for (const ConfigNode& item : cfg->child("outer").sequence("items")) {
    DemoOptions o;
    o.load(item);
  }
  const std::string text = formatOptionValues(cfg->values());
  auto back = ConfigNode::fromString(text, "described");
  ASSERT_TRUE(back.ok()) << text;
  int k_inner = 0;
  back->child("outer").child("inner").get("k", k_inner);
  EXPECT_EQ(k_inner, 4);
  const std::vector<ConfigNode> items = back->child("outer").sequence("items");
  ASSERT_EQ(items.size(), 2u) << text;
  int k1 = 0;
  items[1].get("k", k1);
  EXPECT_EQ(k1, 2);
  const std::vector<ConfigNode::Value> sectioned = inSection(optionValues(inner), "top");
  ASSERT_FALSE(sectioned.empty());
  EXPECT_EQ(sectioned.front().path, "top.gamma");
}

}  // namespace
}  // namespace cvslam
