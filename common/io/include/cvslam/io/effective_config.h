#pragma once
// The configuration a program actually runs with: a YAML file (config/agent.yaml or --config)
// plus the command-line overrides applied to it (--filter, --map, ...), kept as YAML so that
// it can be written into the run folder (agent_<id>/config_used.yaml, docs/run_format.md) and
// given back with --config: a figure is then reproduced from its folder alone.
//
// An override goes through the options struct's own loader, so it gets the file's validation
// and its error names the command-line option ("--filter: type: must be one of ekf, nhinf
// (got 'x')"), and it is recorded at its key path in the YAML.
//
//   auto cfg = EffectiveConfig::load("config/agent.yaml");
//   options.load(cfg->node());
//   cfg->override(options.filter, {"filter"}, "type", "nhinf", "--filter");
//   cfg->write(run_dir + "/agent_1/config_used.yaml");
//
// A configuration may name a profile (`profile: invariant_ekf`): a file of the keys a user
// does not set, merged beneath it (applyProfiles).

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/io/config_node.h"

namespace cvslam {

class EffectiveConfig {
 public:
  /// Reads `path`; an empty path gives an empty configuration (every option at its default).
  static Expected<EffectiveConfig> load(const std::string& path);
  /// Parses YAML text; `source` names it in messages and is the path() it was read from.
  static Expected<EffectiveConfig> fromText(const std::string& yaml, const std::string& source);

  /// The file as read, to load the options structs from (errors name the file).
  const ConfigNode& node() const { return node_; }
  /// The file read ("" when none).
  const std::string& path() const { return path_; }
  /// The folder relative file names of the configuration are resolved against ("." if none).
  std::string dir() const;

  /// Applies `key: value` of the section at `section` (e.g. {"frontend", "detector"}) to
  /// `target` through target.load(), errors naming `option`, and records it in the YAML.
  template <typename T>
  Status override(T& target, const std::vector<std::string>& section, const std::string& key,
                  const std::string& value, const std::string& option);
  /// Records `key: value` at `section` in the YAML only (the caller set the option itself).
  void set(const std::vector<std::string>& section, const std::string& key,
           const std::string& value);
  /// Applies `SECTION.KEY=VALUE` assignments (e.g. "map.max_landmarks=500", "frontend.detector.
  /// type=orb") to the configuration before any options struct reads node(), so an unknown key or
  /// a bad value is reported as the file's own would be; messages name the file "with `option`".
  Status assign(const std::vector<std::string>& assignments, const std::string& option);

  /// Merges the profiles the configuration names beneath it: while its root has `profile:
  /// NAME`, the file NAME.yaml in the first of `dirs` that holds one goes under the
  /// configuration, whose own keys win (a profile may name another, which goes under it in
  /// turn). The key is consumed: yaml() holds every key of every profile, so that a run's
  /// config_used.yaml is given back with --config without the profiles.
  Status applyProfiles(const std::vector<std::string>& dirs);
  /// The profiles applyProfiles merged, the configuration's own first.
  const std::vector<std::string>& profiles() const { return profiles_; }

  /// The configuration with every override, as YAML that ConfigNode (and --config) reads.
  std::string yaml() const;
  /// Writes yaml() to `path`, after a comment line saying what it is.
  Status write(const std::string& path) const;

 private:
  EffectiveConfig(ConfigNode node, YAML::Node tree, std::string path)
      : node_(std::move(node)), tree_(std::move(tree)), path_(std::move(path)) {}

  ConfigNode node_;
  YAML::Node tree_;  // the file's content plus the overrides
  std::string path_;
  std::vector<std::string> profiles_;
};

template <typename T>
Status EffectiveConfig::override(T& target, const std::vector<std::string>& section,
                                 const std::string& key, const std::string& value,
                                 const std::string& option) {
  YAML::Node one(YAML::NodeType::Map);
  one[key] = value;
  YAML::Emitter text;
  text << one;
  auto cfg = ConfigNode::fromString(text.c_str(), option);
  if (!cfg.ok()) return cfg.status();
  target.load(*cfg);
  if (Status s = cfg->status(); !s.ok()) return s;
  set(section, key, value);
  return Status::Ok();
}

}  // namespace cvslam
