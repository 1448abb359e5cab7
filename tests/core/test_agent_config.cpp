// The configuration a run records (coop/agent_config.h, io/effective_config.h;
// docs/run_format.md: agent_<id>/config_used.yaml): the file plus the command-line overrides,
// written as YAML that --config reads back to the same options.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include "cvslam/coop/agent_config.h"
#include "cvslam/coop/cc_team_filter.h"
#include "cvslam/io/build_info.h"
#include "cvslam/io/effective_config.h"
#include "cvslam/io/options_description.h"
#include "cvslam/io/run_reader.h"
#include "cvslam/io/run_writer.h"
#include "euroc_test_folder.h"

namespace cvslam {
namespace {

std::string shippedConfig() {
  return std::string(CVSLAM_SOURCE_DIR) + "/config/agent.yaml";
}

/// cvslam_run's reading of the tool sections: cvslam_agent's `agent:` is not its own.
void skipAgent(const ConfigNode& root) {
  root.skip("agent");
}

TEST(EffectiveConfig, OverridesAreValidatedAndRecordedAtTheirKeyPath) {
  auto cfg = EffectiveConfig::fromText("filter: {type: ekf, gamma: 2}\n", "test.yaml");
  ASSERT_TRUE(cfg.ok()) << cfg.status().message();
  FilterOptions filter;
  ASSERT_TRUE(filter.load(cfg->node().child("filter")).ok());
  ASSERT_TRUE(cfg->override(filter, {"filter"}, "type", "nhinf", "--filter").ok());
  EXPECT_EQ(filter.type, FilterType::kNhinf);
  EXPECT_EQ(filter.gamma, 2.0);  // the file's value stays
  // A section the file does not have is created.
  vision::DetectorOptions detector;
  ASSERT_TRUE(cfg->override(detector, {"frontend", "detector"}, "type", "orb", "--detector").ok());
  auto back = ConfigNode::fromString(cfg->yaml(), "back");
  ASSERT_TRUE(back.ok()) << cfg->yaml();
  std::string type, detector_type;
  double gamma = 0.0;
  back->child("filter").get("type", type);
  back->child("filter").get("gamma", gamma);
  back->child("frontend").child("detector").get("type", detector_type);
  EXPECT_EQ(type, "nhinf");
  EXPECT_EQ(gamma, 2.0);
  EXPECT_EQ(detector_type, "orb");

  // A bad value is refused with the option's name and is not recorded.
  Status bad = cfg->override(filter, {"filter"}, "type", "kalman", "--filter");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.message().rfind("--filter: type: must be one of", 0), 0u) << bad.message();
  EXPECT_EQ(cfg->yaml().find("kalman"), std::string::npos);
}

TEST(AgentConfig, ConfigUsedLoadsBackToTheSameOptions) {
  test::TempFolder tmp;
  AgentConfigArgs args;
  args.config = shippedConfig();
  args.filter = "nhinf";
  args.map = "full";
  args.passes = 3;
  args.detector = "orb";
  args.ci = "fast";
  args.one_way = true;
  auto first = AgentConfig::load(args, "", skipAgent);
  ASSERT_TRUE(first.ok()) << first.status().message();
  EXPECT_EQ(first->filterName(), "nhinf");
  EXPECT_EQ(first->mapName(), "full");
  EXPECT_EQ(first->slam.slam.observation_passes, 3);
  EXPECT_EQ(first->frontend.front_end.detector.type, vision::DetectorType::kOrb);
  EXPECT_EQ(first->coop.ci_method, coop::CiMethod::kFast);
  EXPECT_FALSE(first->coop.both_ways);
  // Vocabularies are named absolutely, so the file works from the run folder.
  EXPECT_TRUE(std::filesystem::path(first->frontend.vocabulary_orb).is_absolute());
  EXPECT_TRUE(std::filesystem::exists(first->frontend.vocabulary_orb));

  const std::string used = tmp / "config_used.yaml";
  ASSERT_TRUE(first->effective.write(used).ok());
  AgentConfigArgs again;
  again.config = used;
  auto second = AgentConfig::load(again, shippedConfig(), skipAgent);
  ASSERT_TRUE(second.ok()) << second.status().message();
  EXPECT_EQ(second->effective.path(), used);
  // Every option: the filter's own printout, and every section as YAML (the same text).
  EXPECT_EQ(second->slam.filter.print(), first->slam.filter.print());
  EXPECT_EQ(second->effective.yaml(), first->effective.yaml());
  EXPECT_EQ(second->mapName(), "full");
  EXPECT_EQ(second->slam.slam.observation_passes, 3);
  EXPECT_EQ(second->slam.slam.pixel_sigma, first->slam.slam.pixel_sigma);
  EXPECT_EQ(second->slam.map.k, first->slam.map.k);
  EXPECT_EQ(second->slam.ins.estimate_imu_bias, first->slam.ins.estimate_imu_bias);
  EXPECT_EQ(second->frontend.front_end.detector.type, vision::DetectorType::kOrb);
  EXPECT_EQ(second->frontend.vocabulary, first->frontend.vocabulary);
  EXPECT_EQ(second->frontend.vocabulary_orb, first->frontend.vocabulary_orb);
  EXPECT_EQ(second->coop.ci_method, coop::CiMethod::kFast);
  EXPECT_FALSE(second->coop.both_ways);
  EXPECT_EQ(second->coop.coop_sigma, first->coop.coop_sigma);
}

TEST(AgentConfig, DefaultFileToolSectionsAndErrors) {
  test::TempFolder tmp;
  // No --config: the default file when it exists; the tool's own section is its to read.
  int read_agent = 0;
  auto c = AgentConfig::load({}, shippedConfig(), [&](const ConfigNode& root) {
    root.skip("agent");
    ++read_agent;
  });
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_EQ(c->effective.path(), shippedConfig());
  EXPECT_EQ(read_agent, 1);
  // Nobody reads `agent:`: an unknown section.
  EXPECT_FALSE(AgentConfig::load({}, shippedConfig(), {}).ok());
  // No file at all: built-in defaults, and config_used.yaml holds the overrides only.
  AgentConfigArgs args;
  args.filter = "nhinf";
  auto d = AgentConfig::load(args, (tmp / "missing.yaml"), {});
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_EQ(d->effective.path(), "");
  EXPECT_EQ(d->filterName(), "nhinf");
  EXPECT_NE(d->effective.yaml().find("nhinf"), std::string::npos);
  // A bad override names its option.
  args.map = "octree";
  auto e =
      AgentConfig::load(args, shippedConfig(), [](const ConfigNode& root) { root.skip("agent"); });
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.status().message().rfind("--map: kind:", 0), 0u) << e.status().message();
}

// The shipped configuration adds the stereo model's second-order term at feature level and the
// image front end overrides it off; the ground station's joint filter takes the agents' choice
// (docs/filter.md "The first second", docs/ground_station.md "Second-order term").
TEST(AgentConfig, TheSecondOrderTermIsOnForFeaturesAndOffForImages) {
  auto c = AgentConfig::load({}, shippedConfig(), skipAgent);
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_TRUE(c->slam.slam.second_order_noise);
  EXPECT_TRUE(c->slam.slam.second_order_mean);  // and its mean
  ASSERT_TRUE(c->frontend.second_order_noise.has_value());
  EXPECT_FALSE(*c->frontend.second_order_noise);
  ASSERT_TRUE(c->frontend.second_order_mean.has_value());
  EXPECT_FALSE(*c->frontend.second_order_mean);
  coop::CcTeamFilterOptions gs;
  gs.useAgentOptions(c->slam);
  EXPECT_TRUE(gs.slam.slam.second_order_noise);
  EXPECT_TRUE(gs.slam.slam.second_order_mean);
  AgentConfigArgs args;
  args.set = {"frontend.second_order_noise=true"};
  auto d = AgentConfig::load(args, shippedConfig(), skipAgent);
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_TRUE(*d->frontend.second_order_noise);
  // The in-process ground station models image keypoints as the agents' image path does:
  // every override, the mean's too.
  args.set = {"frontend.second_order_mean=true", "frontend.pixel_sigma=0.4"};
  auto e = AgentConfig::load(args, shippedConfig(), skipAgent);
  ASSERT_TRUE(e.ok()) << e.status().message();
  coop::CcTeamFilterOptions images;
  images.useAgentImageModel(e->frontend.resolve(e->slam.slam));
  EXPECT_FALSE(images.image_second_order_noise);
  EXPECT_TRUE(images.image_second_order_mean);
  EXPECT_EQ(images.image_pixel_sigma, 0.4);
}

// Detected keypoints are assumed tighter than the feature-level simulator's pixel noise, and the
// ground station assumes for them what the agents do (docs/front_end.md "Pixel σ of
// keypoints"): the two files must not drift apart.
TEST(AgentConfig, ImagesAssumeTheSameTighterPixelSigmaAtAgentsAndGroundStation) {
  auto c = AgentConfig::load({}, shippedConfig(), skipAgent);
  ASSERT_TRUE(c.ok()) << c.status().message();
  ASSERT_TRUE(c->frontend.pixel_sigma.has_value());
  EXPECT_LT(*c->frontend.pixel_sigma, c->slam.slam.pixel_sigma);
  auto gs = coop::CcTeamFilterOptions::loadFile(std::string(CVSLAM_SOURCE_DIR) +
                                                "/config/ground_station.yaml");
  ASSERT_TRUE(gs.ok()) << gs.status().message();
  EXPECT_EQ(gs->image_pixel_sigma, *c->frontend.pixel_sigma);
  EXPECT_EQ(gs->slam.slam.pixel_sigma, c->slam.slam.pixel_sigma);
  AgentConfigArgs args;
  args.set = {"frontend.pixel_sigma=0"};
  EXPECT_FALSE(AgentConfig::load(args, shippedConfig(), skipAgent).ok());
}

// --set SECTION.KEY=VALUE: any key of the file, the rest as the file has it; recorded in
// config_used.yaml; unknown keys, bad values and malformed assignments are refused.
TEST(AgentConfig, SetChangesOneKeyAndIsCheckedAsTheFileWouldBe) {
  auto base = AgentConfig::load({}, shippedConfig(), skipAgent);
  ASSERT_TRUE(base.ok()) << base.status().message();
  AgentConfigArgs args;
  args.set = {"map.kind=full", "map.max_landmarks=500", "frontend.detector.type=orb"};
  auto c = AgentConfig::load(args, shippedConfig(), skipAgent);
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_EQ(c->mapName(), "full");
  EXPECT_EQ(c->slam.map.max_landmarks, 500);
  EXPECT_NE(c->slam.map.max_landmarks, base->slam.map.max_landmarks);
  EXPECT_EQ(c->frontend.front_end.detector.type, vision::DetectorType::kOrb);
  EXPECT_EQ(c->slam.map.k, base->slam.map.k);  // the file's other keys stay
  EXPECT_EQ(c->slam.slam.pixel_sigma, base->slam.slam.pixel_sigma);
  auto back = ConfigNode::fromString(c->effective.yaml(), "back");
  ASSERT_TRUE(back.ok());
  int recorded = 0;
  back->child("map").get("max_landmarks", recorded);
  EXPECT_EQ(recorded, 500);

  const auto error = [&](std::vector<std::string> set) {
    AgentConfigArgs bad;
    bad.set = std::move(set);
    auto e = AgentConfig::load(bad, shippedConfig(), skipAgent);
    return e.ok() ? std::string() : e.status().message();
  };
  for (const char* malformed : {"map.kind", "kind=full", "map..kind=full", ".kind=full", "map.k="})
    EXPECT_NE(error({malformed}).find("--set: expected SECTION.KEY=VALUE"), std::string::npos)
        << malformed;
  EXPECT_NE(error({"map.max_landmarks=-1"}).find("max_landmarks"), std::string::npos);
  EXPECT_NE(error({"map.max_landmarks=-1"}).find("with --set"), std::string::npos);
  EXPECT_NE(error({"map.kindd=full"}).find("kindd"), std::string::npos);
  EXPECT_NE(error({"nosuchsection.key=1"}).find("nosuchsection"), std::string::npos);
}

TEST(AgentConfig, TheInvariantChartRefusesTheAdditiveChartsYawFixes) {
  // First estimates and the observability constraint pin the yaw direction of the additive
  // chart; with the invariant chart they would break it (docs/filter.md), so asking for both
  // is an error that names the keys, in the slam: section and in the front end's overrides.
  test::TempFolder tmp;
  const auto load = [&](const std::string& yaml) {
    const std::string path = tmp / "agent.yaml";
    std::ofstream(path) << yaml;
    AgentConfigArgs args;
    args.config = path;
    return AgentConfig::load(args, "", {});
  };
  const std::string invariant =
      "slam: {error_chart: right_invariant, first_estimate_jacobians: false, "
      "observability_constrained: false}\n";
  auto ok = load(invariant);
  ASSERT_TRUE(ok.ok()) << ok.status().message();
  EXPECT_EQ(ok->slam.slam.error_chart, ErrorChart::kRightInvariant);
  auto with_oc = load(
      "slam: {error_chart: right_invariant, first_estimate_jacobians: false, "
      "observability_constrained: true}\n");
  ASSERT_FALSE(with_oc.ok());
  EXPECT_NE(with_oc.status().message().find("error_chart"), std::string::npos)
      << with_oc.status().message();
  auto with_fej = load(invariant + "frontend: {first_estimate_jacobians: true}\n");
  ASSERT_FALSE(with_fej.ok());
  EXPECT_NE(with_fej.status().message().find("error_chart"), std::string::npos)
      << with_fej.status().message();
}

TEST(AgentConfig, RunJsonRecordsWhatRepeatsTheRun) {
  test::TempFolder tmp;
  RunInfo info;
  info.mode = "dc";
  info.scenario = "config/scenarios/coop_pair.yaml";
  info.seed = 7;
  info.duration_s = 10.5;
  info.sensing = "images";
  info.world = "hall";
  info.pixel_noise = "non_centred";
  info.agents = {1, 3};
  info.config = "config/agent.yaml";
  info.program = "cvslam_run";
  ASSERT_TRUE(writeRunInfo(tmp / "run", info).ok());
  auto back = readRunInfo(tmp / "run");
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->mode, "dc");
  EXPECT_EQ(back->scenario, info.scenario);
  EXPECT_EQ(back->seed, info.seed);
  EXPECT_EQ(back->duration_s, info.duration_s);
  EXPECT_EQ(back->sensing, "images");
  EXPECT_EQ(back->world, "hall");
  EXPECT_EQ(back->pixel_noise, "non_centred");
  EXPECT_EQ(back->agents, info.agents);
  EXPECT_EQ(back->config, info.config);
  EXPECT_EQ(back->program, "cvslam_run");
  // The code the run came from: this build's commit (a git checkout: hex digits, maybe
  // "-dirty"; "unknown" outside one).
  EXPECT_EQ(back->commit, buildCommit());
  EXPECT_FALSE(back->commit.empty());
  // Unset facts stay absent.
  ASSERT_TRUE(writeRunInfo(tmp / "bare", RunInfo{}).ok());
  auto bare = readRunInfo(tmp / "bare");
  ASSERT_TRUE(bare.ok());
  EXPECT_FALSE(bare->seed.has_value());
  EXPECT_FALSE(bare->duration_s.has_value());
  EXPECT_TRUE(bare->agents.empty());
}

TEST(AgentConfig, ItsDescriptionLoadsBackToTheSameOptions) {
  // The shipped file, one override and a --set: what cvslam_agent --verbose prints is a
  // complete configuration that --config reads back to exactly the same options.
  AgentConfigArgs args;
  args.config = shippedConfig();
  args.filter = "nhinf";
  args.set = {"map.max_landmarks=123"};
  auto config = AgentConfig::load(args, "", skipAgent);
  ASSERT_TRUE(config.ok()) << config.status().message();
  const std::string text = formatOptionValues(config->values());
  EXPECT_NE(text.find("max_landmarks: 123"), std::string::npos) << text;

  test::TempFolder tmp;
  const std::string path = tmp.path() + "/described.yaml";
  std::ofstream(path) << text;
  AgentConfigArgs again;
  again.config = path;
  auto back = AgentConfig::load(again, "", skipAgent);
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_TRUE(sameOptions(back->slam, config->slam));
  EXPECT_TRUE(sameOptions(back->frontend, config->frontend));
  EXPECT_TRUE(sameOptions(back->coop, config->coop));
  EXPECT_EQ(back->filterName(), "nhinf");
  // ...and differs where the options differ.
  AgentConfigArgs other = again;
  other.set = {"coop.both_ways=false"};
  auto changed = AgentConfig::load(other, "", skipAgent);
  ASSERT_TRUE(changed.ok()) << changed.status().message();
  EXPECT_TRUE(sameOptions(changed->slam, config->slam));
  EXPECT_FALSE(sameOptions(changed->coop, config->coop));
}

TEST(AgentConfig, TheShippedFileHoldsWhatAUserSetsAndItsProfileTheRest) {
  // config/agent.yaml: at most 60 keys; the algorithm's switches come from its profile.
  auto file = EffectiveConfig::load(shippedConfig());
  ASSERT_TRUE(file.ok()) << file.status().message();
  const YAML::Node tree = YAML::Load(file->yaml());
  std::function<int(const YAML::Node&)> leaves = [&](const YAML::Node& n) {
    if (!n.IsMap()) return 1;
    int count = 0;
    for (const auto& entry : n) count += leaves(entry.second);
    return count;
  };
  EXPECT_LE(leaves(tree) - 1, 60);  // `profile:` itself is not a setting
  EXPECT_EQ(tree["profile"].as<std::string>(), "invariant_ekf");
  EXPECT_FALSE(tree["slam"]["error_chart"]);

  AgentConfigArgs args;
  args.config = shippedConfig();
  auto shipped = AgentConfig::load(args, "", skipAgent);
  ASSERT_TRUE(shipped.ok()) << shipped.status().message();
  EXPECT_EQ(shipped->effective.profiles(), std::vector<std::string>{"invariant_ekf"});
  EXPECT_EQ(shipped->slam.slam.error_chart, ErrorChart::kRightInvariant);
  EXPECT_EQ(shipped->slam.slam.held_landmarks, 100);
  EXPECT_EQ(shipped->frontend.front_end.detector.fast_sift.describe_budget, 150);
  // The record holds every key, without the profile: it loads back alone.
  const std::string used = shipped->effective.yaml();
  EXPECT_EQ(used.find("profile:"), std::string::npos) << used;
  test::TempFolder tmp;
  std::ofstream(tmp / "used.yaml") << used;
  AgentConfigArgs again;
  again.config = tmp / "used.yaml";
  auto back = AgentConfig::load(again, "", skipAgent);
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_TRUE(back->effective.profiles().empty());
  EXPECT_TRUE(sameOptions(back->slam, shipped->slam));
  EXPECT_TRUE(sameOptions(back->frontend, shipped->frontend));
  EXPECT_TRUE(sameOptions(back->coop, shipped->coop));

  // Every key of the profile is a key of the configuration: set in the file, it wins.
  args.set = {"slam.held_landmarks=7", "frontend.loop_detection.min_inliers=9"};
  auto set = AgentConfig::load(args, "", skipAgent);
  ASSERT_TRUE(set.ok()) << set.status().message();
  EXPECT_EQ(set->slam.slam.held_landmarks, 7);
  EXPECT_EQ(set->frontend.loop_detection.min_inliers, 9);
}

TEST(AgentConfig, AProfileSetsTheFiltersVariantInOneWord) {
  AgentConfigArgs args;
  args.config = shippedConfig();
  args.profile = "thesis_ekf";
  auto thesis = AgentConfig::load(args, "", skipAgent);
  ASSERT_TRUE(thesis.ok()) << thesis.status().message();
  EXPECT_EQ(thesis->effective.profiles(),
            (std::vector<std::string>{"thesis_ekf", "invariant_ekf"}));
  EXPECT_EQ(thesis->slam.slam.error_chart, ErrorChart::kAdditive);
  EXPECT_EQ(thesis->slam.ins.attitude, vehicle::Attitude::kEuler);
  EXPECT_EQ(thesis->slam.slam.held_landmarks, 0);
  EXPECT_FALSE(thesis->coop.both_ways);
  // What the profile leaves open is the shipped profile's, and the file's keys stay.
  EXPECT_EQ(thesis->slam.slam.loop_closure_passes, 3);
  EXPECT_EQ(thesis->slam.map.k, 20);
  args.profile = "ideal_ekf";
  auto ideal = AgentConfig::load(args, "", skipAgent);
  ASSERT_TRUE(ideal.ok()) << ideal.status().message();
  EXPECT_EQ(ideal->slam.slam.error_chart, ErrorChart::kAdditive);
  EXPECT_TRUE(ideal->slam.slam.second_order_mean);
}

TEST(AgentConfig, MisspeltKeysAndProfilesAreRefusedInOneLine) {
  test::TempFolder tmp;
  auto load = [&](const std::string& text) {
    std::ofstream(tmp / "c.yaml") << text;
    AgentConfigArgs args;
    args.config = tmp / "c.yaml";
    return AgentConfig::load(args, shippedConfig(), skipAgent);
  };
  // A key of the profile, misspelt in the user's file.
  auto typo = load("profile: invariant_ekf\nslam: {held_landmark: 5}\n");
  ASSERT_FALSE(typo.ok());
  EXPECT_NE(typo.status().message().find("held_landmark"), std::string::npos);
  EXPECT_EQ(typo.status().message().find('\n'), std::string::npos) << typo.status().message();
  // An unknown profile names the known ones (the shipped folder, beside the default file).
  auto unknown = load("profile: invarant_ekf\n");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.status().message().find("unknown profile 'invarant_ekf'"), std::string::npos)
      << unknown.status().message();
  EXPECT_NE(unknown.status().message().find("thesis_ekf"), std::string::npos);
  // A profile beside the user's file is found first; one that names itself is refused.
  std::filesystem::create_directories(tmp / "profiles");
  std::ofstream(tmp / "profiles/loop.yaml") << "profile: loop\n";
  auto cycle = load("profile: loop\n");
  ASSERT_FALSE(cycle.ok());
  EXPECT_NE(cycle.status().message().find("names itself"), std::string::npos)
      << cycle.status().message();
  std::ofstream(tmp / "profiles/mine.yaml") << "profile: invariant_ekf\nmap: {k: 12}\n";
  auto mine = load("profile: mine\n");
  ASSERT_TRUE(mine.ok()) << mine.status().message();
  EXPECT_EQ(mine->slam.map.k, 12);
  EXPECT_EQ(mine->slam.slam.held_landmarks, 100);
}

}  // namespace
}  // namespace cvslam
