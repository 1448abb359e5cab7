#include "cvslam/coop/agent_config.h"

#include <cmath>
#include <filesystem>

#include "cvslam/io/cli.h"
#include "cvslam/io/options_description.h"

namespace cvslam {
namespace {

/// A vocabulary name relative to the configuration's folder, made absolute (same file).
std::string resolved(const std::string& name, const std::string& dir) {
  if (name.empty() || std::filesystem::path(name).is_absolute()) return name;
  return std::filesystem::absolute(std::filesystem::path(dir) / name).lexically_normal().string();
}

}  // namespace

void AgentConfigArgs::addTo(CLI::App& app) {
  app.add_option("--config", config);
  app.add_option("--profile", profile);
  app.add_option("--set", set)->expected(1)->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  app.add_option("--filter", filter);
  app.add_option("--map", map);
  app.add_option("--attitude", attitude);
  app.add_option("--detector", detector);
  app.add_option("--ci", ci);
  app.add_option("--passes", passes)
      ->check(cli::numberValidator("N", "an integer ≥ 1", [](double x) {
        return x >= 1.0 && x == std::floor(x) && x <= 1e6;
      }));
  CLI::Option* both = app.add_flag("--both-ways", both_ways);
  CLI::Option* one = app.add_flag("--one-way", one_way);
  both->excludes(one);
}

Expected<AgentConfig> AgentConfig::load(
    const AgentConfigArgs& args, const std::string& default_config,
    const std::function<void(const ConfigNode&)>& tool_sections) {
  std::string path = args.config;
  if (path.empty() && !default_config.empty() && std::filesystem::exists(default_config)) {
    path = default_config;
  }
  Expected<EffectiveConfig> file = EffectiveConfig::load(path);
  if (!file.ok()) return file.status();
  if (Status s = file->assign(args.set, "--set"); !s.ok()) return s;
  if (!args.profile.empty()) file->set({}, "profile", args.profile);
  // Profiles beside the file, then the shipped ones (a file of the user's own elsewhere).
  std::vector<std::string> profile_dirs = {file->dir() + "/profiles"};
  if (!default_config.empty())
    profile_dirs.push_back(
        (std::filesystem::path(default_config).parent_path() / "profiles").string());
  if (Status s = file->applyProfiles(profile_dirs); !s.ok()) return s;
  AgentConfig c{{}, {}, {}, std::move(*file)};
  const ConfigNode& root = c.effective.node();
  c.slam.load(root);
  c.frontend.load(root.child("frontend"));
  // The slam options as the front end's overrides leave them, for images.
  if (Status s = c.frontend.resolve(c.slam.slam).checkChart(); !s.ok())
    return Status::Error("frontend: error_chart: " + s.message());
  c.coop.load(root.child("coop"));
  if (tool_sections) tool_sections(root);
  root.skip("lcm");  // read by the LCM tools (lcm-spy), not by an agent
  if (Status s = root.finish(); !s.ok()) return s;

  EffectiveConfig& e = c.effective;
  if (!args.filter.empty())
    if (Status s = e.override(c.slam.filter, {"filter"}, "type", args.filter, "--filter"); !s.ok())
      return s;
  if (!args.map.empty())
    if (Status s = e.override(c.slam.map, {"map"}, "kind", args.map, "--map"); !s.ok()) return s;
  if (!args.attitude.empty()) {
    if (Status s = e.override(c.slam.ins, {"ins"}, "attitude", args.attitude, "--attitude");
        !s.ok())
      return s;
  }
  if (args.passes > 0) {
    const std::string n = std::to_string(args.passes);
    if (Status s = e.override(c.slam.slam, {"slam"}, "observation_passes", n, "--passes"); !s.ok())
      return s;
  }
  if (!args.detector.empty()) {
    if (Status s = e.override(c.frontend.front_end.detector, {"frontend", "detector"}, "type",
                              args.detector, "--detector");
        !s.ok())
      return s;
  }
  if (!args.ci.empty())
    if (Status s = e.override(c.coop, {"coop"}, "ci_method", args.ci, "--ci"); !s.ok()) return s;
  if (args.both_ways || args.one_way) {
    const std::string v = args.both_ways ? "true" : "false";
    if (Status s = e.override(c.coop, {"coop"}, "both_ways", v, "--both-ways/--one-way"); !s.ok())
      return s;
  }
  if (auto p = c.slam.filter.policy(); !p.ok()) return p.status();

  const std::string dir = e.dir();
  for (auto [key, name] : {std::pair{"vocabulary", &c.frontend.vocabulary},
                           std::pair{"vocabulary_orb", &c.frontend.vocabulary_orb}}) {
    const std::string absolute = resolved(*name, dir);
    if (absolute != *name) e.set({"frontend"}, key, absolute);
    *name = absolute;
  }
  return c;
}

std::vector<ConfigNode::Value> AgentConfig::values() const {
  std::vector<ConfigNode::Value> all = optionValues(slam);
  for (auto part :
       {inSection(optionValues(frontend), "frontend"), inSection(optionValues(coop), "coop")})
    all.insert(all.end(), part.begin(), part.end());
  return all;
}

std::string AgentConfig::filterName() const {
  return slam.filter.type == FilterType::kEkf ? "ekf" : "nhinf";
}

std::string AgentConfig::mapName() const {
  return slam.map.kind == MapKind::kFull ? "full" : "knearest";
}

}  // namespace cvslam
